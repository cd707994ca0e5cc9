// SPDX-License-Identifier: GPL-3.0-or-later
// The three wading protocols follow the paper's designs, and every new protocol construct
// (scale anchors, per-stimulus scales, per-scale blocks, lab clips, [clips], [laps], Latin
// square counterbalancing, participant fields) is checked, with file:line:column errors.
#include "StudySupport.h"
#include "experiment/Clips.h"
#include "experiment/Plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>

using namespace underfoot::experiment;
using namespace underfoot::wading::test;

namespace {

std::vector<ProtocolProblem> problemsOf(const std::string& text) {
    try {
        parseProtocol(text, "t.toml");
    } catch (const ProtocolError& e) {
        return e.problems();
    }
    return {};
}

::testing::AssertionResult hasProblem(const std::vector<ProtocolProblem>& problems,
                                      const std::string& fragment, int line, int column = 0) {
    for (const auto& p : problems)
        if (p.message.find(fragment) != std::string::npos && p.line == line &&
            (column == 0 || p.column == column))
            return ::testing::AssertionSuccess();
    std::string all;
    for (const auto& p : problems) all += "\n  " + p.toString();
    return ::testing::AssertionFailure()
           << "no problem '" << fragment << "' at line " << line << "; got:" << all;
}

/// A small rating protocol; `extra` is appended, `ordering` replaces the [ordering] body.
std::string ratingProtocol(const std::string& extra, const std::string& ordering = "",
                           const std::string& scale = "") {
    return "[protocol]\nid = \"r\"\nversion = 1\ntitle = \"R\"\n" // 1-4
           "[design]\ntype = \"within\"\n"                        // 5-6
           "[[stimuli]]\nid = \"A\"\nsurface = \"water\"\n"       // 7-9
           "[[stimuli]]\nid = \"B\"\nsurface = \"water\"\n"       // 10-12
           "[ordering]\n" +
           ordering +                                                              // 13
           "[questions]\n"                                                         // 14
           "[[questions.scales]]\nid = \"x\"\nprompt = \"X\"\nmin = 0\nmax = 10\n" // 15-19
           + scale + extra;
}

} // namespace

TEST(WadingProtocols, ListeningTestIsTwoDepthsByThreeSpeedsRatedPerScaleBlock) {
    const Protocol p = loadProtocol(shippedProtocol("wading_listening.toml"));
    EXPECT_TRUE(p.clips.enabled);
    EXPECT_DOUBLE_EQ(p.clips.seconds, 7.0); // paper §4.1: 7-s excerpts
    EXPECT_EQ(p.ordering.blocks, BlockKind::Scale);
    ASSERT_EQ(p.groups.size(), 1u);
    ASSERT_EQ(p.groups[0].stimuli.size(), 6u);
    ASSERT_EQ(p.questions.scales.size(), 4u);
    const std::vector<std::string> ids{"depth", "speed", "effort", "naturalness"};
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(p.questions.scales[i].id, ids[i]);
        EXPECT_EQ(p.questions.scales[i].min, 0);
        EXPECT_EQ(p.questions.scales[i].max, 10);
        EXPECT_EQ(p.questions.scales[i].anchors.size(), 2u);
    }
    EXPECT_EQ(p.questions.scales[0].anchors.at(10), "1 m / 3.28 ft");
    EXPECT_EQ(p.questions.scales[0].maxLabel, "1 m / 3.28 ft");
    const Stimulus* s = p.stimulus("wade_deep_135");
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(std::get<std::string>(s->wading.at("algorithm")), "v1");
    EXPECT_EQ(s->factors.at("depth"), "deep");

    // Four blocks, one per scale, each presenting the six clips once in its own order.
    const auto plan = generatePlan(p, "all", 11, 0);
    ASSERT_EQ(plan.size(), 24u);
    std::vector<std::vector<std::string>> orders(4);
    for (const auto& t : plan) {
        ASSERT_GE(t.block, 1);
        ASSERT_LE(t.block, 4);
        orders[static_cast<std::size_t>(t.block - 1)].push_back(t.stimulus.id);
        const auto asked = askedScales(p, t.stimulus, t.block);
        ASSERT_EQ(asked.size(), 1u);
        EXPECT_EQ(asked[0]->id, ids[static_cast<std::size_t>(t.block - 1)]);
        EXPECT_EQ(t.repetition, 1);
    }
    std::set<std::vector<std::string>> distinct;
    for (auto& o : orders) {
        ASSERT_EQ(o.size(), 6u);
        distinct.insert(o);
        std::sort(o.begin(), o.end());
        EXPECT_EQ(std::unique(o.begin(), o.end()), o.end());
    }
    EXPECT_GT(distinct.size(), 1u) << "every block should draw its own random order";
}

TEST(WadingProtocols, InteractiveTestCounterbalancesThreeConditionsWithLaps) {
    const Protocol p = loadProtocol(shippedProtocol("wading_interactive.toml"));
    EXPECT_EQ(p.laps.baseline, 3);
    EXPECT_EQ(p.laps.feedback, 3);
    EXPECT_TRUE(p.laps.silent(3));
    EXPECT_FALSE(p.laps.silent(4));
    EXPECT_FALSE(p.clips.enabled);
    // Williams design for 3 conditions: 6 orders = every permutation; each condition follows
    // every other exactly twice (first-order carry-over balance).
    ASSERT_EQ(p.groups.size(), 6u);
    std::set<std::vector<std::string>> orders;
    std::map<std::pair<std::string, std::string>, int> follows;
    for (const auto& g : p.groups) {
        ASSERT_EQ(g.stimuli.size(), 3u);
        orders.insert(g.stimuli);
        for (std::size_t i = 1; i < 3; ++i) ++follows[{g.stimuli[i - 1], g.stimuli[i]}];
        const auto plan = generatePlan(p, g.id, 3, 0);
        ASSERT_EQ(plan.size(), 3u);
        for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(plan[i].stimulus.id, g.stimuli[i]);
    }
    EXPECT_EQ(orders.size(), 6u);
    EXPECT_EQ(follows.size(), 6u);
    for (const auto& [pair, n] : follows) EXPECT_EQ(n, 2) << pair.first << "->" << pair.second;
    // Seven 1-7 items for S5.0 and S0.8; three for AS (paper §5.3).
    ASSERT_EQ(p.questions.scales.size(), 7u);
    for (const auto& s : p.questions.scales) {
        EXPECT_EQ(s.min, 1);
        EXPECT_EQ(s.max, 7);
    }
    EXPECT_EQ(askedScales(p, *p.stimulus("S5"), 1).size(), 7u);
    EXPECT_EQ(askedScales(p, *p.stimulus("S08"), 1).size(), 7u);
    const auto as = askedScales(p, *p.stimulus("AS"), 1);
    ASSERT_EQ(as.size(), 3u);
    EXPECT_EQ(as[0]->id, "walking_change");
    EXPECT_EQ(as[1]->id, "comfort");
    EXPECT_EQ(as[2]->id, "speed_change");
    EXPECT_EQ(p.questions.scale("effort_change")->anchors.at(4), "no change");
}

TEST(WadingProtocols, RealismTestIsThreeSoundsByThreeCadencesRatedTwice) {
    const Protocol p = loadProtocol(shippedProtocol("wading_realism.toml"));
    ASSERT_EQ(p.groups[0].stimuli.size(), 9u);
    EXPECT_EQ(p.ordering.repetitions, 2);
    int lab = 0;
    for (const auto& s : p.stimuli) lab += s.clip ? 1 : 0;
    EXPECT_EQ(lab, 3);
    EXPECT_EQ(*p.stimulus("real_63")->clip, "real/wading_63spm.wav");
    EXPECT_EQ(p.stimulus("real_63")->factors.at("algorithm"), "real");
    EXPECT_EQ(p.stimulus("v1_118")->factors.at("cadence"), "118");
    EXPECT_DOUBLE_EQ(std::get<double>(p.stimulus("v1_118")->wading.at("cadence")), 118.0);
    ASSERT_EQ(p.participantFields.size(), 3u);
    EXPECT_EQ(p.participantFields[2].id, "listening_device");
    EXPECT_EQ(p.participantFields[2].options.size(), 4u);
    const auto plan = generatePlan(p, "all", 5, 1);
    ASSERT_EQ(plan.size(), 18u);
    for (std::size_t i = 1; i < plan.size(); ++i)
        EXPECT_NE(plan[i].stimulus.id, plan[i - 1].stimulus.id);
    // Stored stimuli keep their clip file (replay and the clip player need it).
    EXPECT_EQ(stimulusFromToml(stimulusToToml(*p.stimulus("real_27"))), *p.stimulus("real_27"));
}

TEST(WadingProtocols, MissingLabClipIsReportedAtItsProtocolLine) {
    const Protocol p = loadProtocol(shippedProtocol("wading_realism.toml"));
    const std::string dir = scratchFile("clips");
    std::filesystem::create_directories(dir + "/real");
    auto problems = checkClipFiles(p, dir);
    ASSERT_EQ(problems.size(), 3u);
    EXPECT_EQ(problems[0].line, 50); // clip = "real/wading_27spm.wav" in wading_realism.toml
    EXPECT_EQ(problems[0].column, 8);
    EXPECT_NE(problems[0].message.find("real/wading_27spm.wav"), std::string::npos);
    EXPECT_NE(problems[0].toString().find("wading_realism.toml:50:8:"), std::string::npos);
    std::ofstream(dir + "/real/wading_27spm.wav") << "";
    problems = checkClipFiles(p, dir);
    ASSERT_EQ(problems.size(), 3u);
    EXPECT_NE(problems[0].message.find("is empty"), std::string::npos);
    for (const char* name : {"wading_27spm.wav", "wading_63spm.wav", "wading_118spm.wav"})
        std::ofstream(dir + "/real/" + name) << "RIFF";
    EXPECT_TRUE(checkClipFiles(p, dir).empty());
}

TEST(WadingProtocols, ScaleAnchorsAreCheckedAgainstTheRange) {
    auto problems = problemsOf(ratingProtocol("anchors = { 0 = \"none\", 11 = \"too far\" }\n"));
    EXPECT_TRUE(
        hasProblem(problems, "anchor 11 of scale 'x' is outside its range; expected 0 to 10", 20));
    problems = problemsOf(ratingProtocol("anchors = { low = \"none\" }\n"));
    EXPECT_TRUE(hasProblem(problems, "anchor 'low' of scale 'x' is not a whole number", 20));
    problems = problemsOf(ratingProtocol("anchors = { 5 = 3 }\n"));
    EXPECT_TRUE(hasProblem(problems, "anchor 5 of scale 'x' must be a non-empty string", 20));
    const Protocol ok = parseProtocol(
        ratingProtocol("anchors = { 0 = \"none\", 5 = \"middle\", 10 = \"all\" }\n"), "t.toml");
    EXPECT_EQ(ok.questions.scales[0].anchors.size(), 3u);
    EXPECT_EQ(ok.questions.scales[0].minLabel, "none");
}

TEST(WadingProtocols, ScaleStimulusListsNameKnownStimuli) {
    auto problems = problemsOf(ratingProtocol("stimuli = [\"A\", \"Z\"]\n"));
    EXPECT_TRUE(hasProblem(problems, "scale 'x' names unknown stimulus 'Z'", 20));
    problems = problemsOf(ratingProtocol("stimuli = []\n"));
    EXPECT_TRUE(hasProblem(problems, "scale 'x' has an empty 'stimuli' list", 20));
    const Protocol ok = parseProtocol(ratingProtocol("stimuli = [\"B\"]\n"), "t.toml");
    EXPECT_TRUE(askedScales(ok, *ok.stimulus("A"), 1).empty());
    EXPECT_EQ(askedScales(ok, *ok.stimulus("B"), 1).size(), 1u);
}

TEST(WadingProtocols, ScaleBlocksNeedScalesAndNoSurfaceQuestion) {
    const std::string noScales = "[protocol]\nid = \"r\"\nversion = 1\ntitle = \"R\"\n"
                                 "[design]\ntype = \"within\"\n"
                                 "[[stimuli]]\nid = \"A\"\nsurface = \"wood\"\n"
                                 "[ordering]\nblocks = \"scale\"\n"
                                 "[questions]\n[questions.surface]\noptions = [\"wood\"]\n";
    const auto problems = problemsOf(noScales);
    EXPECT_TRUE(hasProblem(problems, "blocks = \"scale\" needs [[questions.scales]]", 10));
    EXPECT_TRUE(hasProblem(problems, "the surface question would be asked in every block", 10));
    EXPECT_TRUE(hasProblem(
        problemsOf(ratingProtocol("", "blocks = \"scales\"\n")),
        "'blocks' in [ordering] is 'scales'; expected one of: none, repetition, scale", 14));
}

TEST(WadingProtocols, LabClipsMustBeRelativeFilesWithoutWadingSettings) {
    const std::string base = "[protocol]\nid = \"r\"\nversion = 1\ntitle = \"R\"\n"
                             "[design]\ntype = \"within\"\n"
                             "[[stimuli]]\nid = \"A\"\nsurface = \"water\"\n";
    const std::string tail = "[questions]\n[[questions.scales]]\nid = \"x\"\nprompt = \"X\"\n"
                             "min = 0\nmax = 10\n";
    auto problems = problemsOf(base + "clip = \"/etc/passwd\"\n" + tail);
    EXPECT_TRUE(hasProblem(problems, "expected a file name relative to the clip folder", 10, 8));
    problems = problemsOf(base + "clip = \"../x.wav\"\n" + tail);
    EXPECT_TRUE(hasProblem(problems, "no '..'", 10, 8));
    problems = problemsOf(base + "clip = \"a.wav\"\nwading = { depth = \"deep\" }\n" + tail);
    EXPECT_TRUE(hasProblem(problems, "has both a lab-supplied 'clip' and 'wading' settings", 10));
    problems = problemsOf(base + "clip = \"a.wav\"\nfactors = { sound = [1, 2] }\n" + tail);
    EXPECT_TRUE(
        hasProblem(problems, "factor 'sound' in [[stimuli]] #1.factors must be a string", 11));
    const Protocol ok = parseProtocol(base + "clip = \"rec/a.wav\"\n" + tail, "t.toml");
    EXPECT_TRUE(ok.clips.enabled) << "a lab clip makes the protocol a listening test";
    EXPECT_EQ(clipPath(*ok.stimulus("A"), "/lab/clips"), "/lab/clips/rec/a.wav");
}

TEST(WadingProtocols, ClipsAndLapsTablesAreValidated) {
    auto problems = problemsOf(ratingProtocol("[clips]\nseconds = 0.1\nspeed = 2\n"));
    EXPECT_TRUE(hasProblem(problems,
                           "'seconds' in [clips] is 0.1; expected a finite number from "
                           "0.5 to 600",
                           21));
    EXPECT_TRUE(hasProblem(problems, "unknown key 'speed' in [clips]", 22));
    problems = problemsOf(ratingProtocol("[laps]\nbaseline = 3\nfeedback = 0\n"));
    EXPECT_TRUE(hasProblem(problems, "'feedback' in [laps] is 0; expected 1 to 100", 22));
    problems = problemsOf(ratingProtocol("[laps]\nfeedback = 3\n[clips]\nseconds = 5\n"));
    EXPECT_TRUE(hasProblem(problems,
                           "[clips] (a listening test) and [laps] (an interactive test) "
                           "exclude each other",
                           22));
}

TEST(WadingProtocols, LatinSquareNeedsAWithinDesignAndNoRandomOrder) {
    auto problems = problemsOf(ratingProtocol("", "counterbalance = \"latin_square\"\n"
                                                  "order = \"random\"\n"));
    EXPECT_TRUE(hasProblem(problems, "order = \"random\" contradicts counterbalance", 15));
    problems = problemsOf(ratingProtocol("", "counterbalance = \"williams\"\n"));
    EXPECT_TRUE(hasProblem(problems, "expected one of: none, latin_square", 14));
    const std::string between =
        "[protocol]\nid = \"r\"\nversion = 1\ntitle = \"R\"\n[design]\ntype = \"between\"\n"
        "[[stimuli]]\nid = \"A\"\nsurface = \"water\"\n[[groups]]\nid = \"g\"\n"
        "[ordering]\ncounterbalance = \"latin_square\"\n"
        "[questions]\n[[questions.scales]]\nid = \"x\"\nprompt = \"X\"\nmin = 0\nmax = 10\n";
    EXPECT_TRUE(hasProblem(problemsOf(between), "expected design type = \"within\"", 13));
    // Two conditions: a Williams design of 2 rows (AB, BA).
    const Protocol two =
        parseProtocol(ratingProtocol("", "counterbalance = \"latin_square\"\n"), "t.toml");
    ASSERT_EQ(two.groups.size(), 2u);
    EXPECT_EQ(two.groups[0].stimuli, (std::vector<std::string>{"A", "B"}));
    EXPECT_EQ(two.groups[1].stimuli, (std::vector<std::string>{"B", "A"}));
}

TEST(WadingProtocols, ParticipantFieldsAreValidated) {
    auto problems = problemsOf(ratingProtocol("[[participant_fields]]\nid = \"device\"\n"
                                              "options = [\"phone\", \"phone\"]\n"
                                              "[[participant_fields]]\nid = \"age\"\n"
                                              "[[participant_fields]]\nid = \"x\"\ncolour = 1\n"));
    EXPECT_TRUE(hasProblem(problems,
                           "option 'phone' of [[participant_fields]] #1 is empty or "
                           "listed twice",
                           22));
    EXPECT_TRUE(hasProblem(problems, "participant field 'age' is built in", 23));
    EXPECT_TRUE(hasProblem(problems, "unknown key 'colour' in [[participant_fields]] #2", 27));
}

TEST(WadingProtocols, RatingModelErrorsAreLocatedAndCheckedAgainstTheProtocol) {
    try {
        parseRatingModel("[scales.depth]\nbase = 5\nnoise_sd = -1\nwobble = 2\n[other]\n",
                         "m.toml");
        FAIL() << "expected a ProtocolError";
    } catch (const ProtocolError& e) {
        const std::string text = e.what();
        EXPECT_NE(text.find("m.toml:3:12: [scales.depth].noise_sd is -1"), std::string::npos)
            << text;
        EXPECT_NE(text.find("m.toml:4:1: unknown key 'wobble' in [scales.depth]"),
                  std::string::npos)
            << text;
        EXPECT_NE(text.find("m.toml:5:1: unknown table 'other'"), std::string::npos) << text;
        EXPECT_NE(text.find("expected one of: base, effects, fields, noise_sd, participant_sd, "
                            "stimuli"),
                  std::string::npos)
            << text;
    }
    const Protocol p = loadProtocol(shippedProtocol("wading_listening.toml"));
    const RatingModel m =
        parseRatingModel("[scales.depth]\nbase = 5\neffects.depth = { deep = 1, muddy = 2 }\n"
                         "effects.colour = { red = 1 }\n[scales.loudness]\nbase = 3\n",
                         "m.toml");
    const auto problems = checkRatingModel(m, p);
    ASSERT_EQ(problems.size(), 3u);
    EXPECT_NE(problems[0].find("factor 'colour'"), std::string::npos);
    EXPECT_NE(problems[1].find("factor 'depth' has no level 'muddy'"), std::string::npos);
    EXPECT_NE(problems[2].find("scale 'loudness' is not a scale"), std::string::npos);
    for (const char* name : {"wading_listening", "wading_interactive", "wading_realism"}) {
        const Protocol shipped = loadProtocol(shippedProtocol(std::string(name) + ".toml"));
        EXPECT_TRUE(checkRatingModel(
                        loadRatingModel(ratingModel(std::string(name) + "_ratings.toml")), shipped)
                        .empty())
            << name;
    }
}
