// SPDX-License-Identifier: GPL-3.0-or-later
#include "TestSupport.h"
#include "experiment/Plan.h"
#include "experiment/Protocol.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
std::vector<ProtocolProblem> problemsOf(const std::string& text,
                                        const Catalogue& catalogue = defaultCatalogue()) {
    try {
        parseProtocol(text, "t.toml", catalogue);
    } catch (const ProtocolError& e) {
        return e.problems();
    }
    return {};
}

bool hasProblem(const std::vector<ProtocolProblem>& problems, const std::string& fragment,
                int line = 0) {
    return std::any_of(problems.begin(), problems.end(), [&](const ProtocolProblem& p) {
        return p.message.find(fragment) != std::string::npos && (line == 0 || p.line == line);
    });
}
} // namespace

TEST(ExperimentProtocol, Tvcg2011Exp1HasThirteenStimuliTwiceAndNineteenOptions) {
    const Protocol p = loadProtocol(shipped("tvcg2011_exp1.toml"));
    EXPECT_EQ(p.id, "tvcg2011_exp1");
    EXPECT_EQ(p.design, DesignKind::Within);
    ASSERT_EQ(p.stimuli.size(), 13u);
    EXPECT_EQ(p.ordering.repetitions, 2);
    ASSERT_EQ(p.questions.surfaceOptions.size(), 19u); // 18 surfaces + I don't know
    EXPECT_EQ(p.questions.surfaceOptions.back().id, "dont_know");
    EXPECT_EQ(p.questions.surfaceOptions.back().letter, 's');
    EXPECT_EQ(p.stimulus("WR")->surface, "wood_reverb");
    EXPECT_EQ(p.stimulus("WR")->reverb, "wooden_room");
    EXPECT_EQ(p.stimulus("BS")->input.sensor, SensorKind::Microphones);
    EXPECT_EQ(generatePlan(p, "all", 1, 0).size(), 26u);
    EXPECT_EQ(p.hash.size(), 64u);
}

TEST(ExperimentProtocol, Tvcg2011Exp2GroupsAndPairsFollowStudies) {
    const Protocol p = loadProtocol(shipped("tvcg2011_exp2.toml"));
    ASSERT_EQ(p.groups.size(), 3u);
    EXPECT_EQ(p.groups[0].id, "none");
    EXPECT_EQ(p.groups[1].id, "coherent");
    EXPECT_EQ(p.groups[2].id, "incoherent");
    EXPECT_EQ(p.groups[0].target, 15);
    EXPECT_EQ(p.groups[2].target, 13);
    EXPECT_EQ(generatePlan(p, "none", 1, 0).size(), 10u);
    EXPECT_EQ(generatePlan(p, "coherent", 1, 0).size(), 10u);
    EXPECT_EQ(generatePlan(p, "incoherent", 1, 0).size(), 12u);
    // Coherent pairs (Nordahl et al. 2011, exp. 2).
    const std::vector<std::pair<std::string, std::string>> coherent = {
        {"beach_sand", "beach_summer"},
        {"gravel", "farm_courtyard"},
        {"deep_snow", "ski_slope"},
        {"forest_underbrush", "forest"},
        {"dry_leaves", "park_fall"}};
    for (std::size_t i = 0; i < coherent.size(); ++i) {
        const Stimulus* s = p.stimulus(p.groups[1].stimuli[i]);
        EXPECT_EQ(s->surface, coherent[i].first);
        EXPECT_EQ(s->soundscape, coherent[i].second);
    }
    const std::vector<std::pair<std::string, std::string>> incoherent = {
        {"beach_sand", "forest"},
        {"beach_sand", "ski_slope"},
        {"deep_snow", "forest"},
        {"deep_snow", "beach_summer"},
        {"forest_underbrush", "beach_summer"},
        {"forest_underbrush", "ski_slope"}};
    for (std::size_t i = 0; i < incoherent.size(); ++i) {
        const Stimulus* s = p.stimulus(p.groups[2].stimuli[i]);
        EXPECT_EQ(s->surface, incoherent[i].first);
        EXPECT_EQ(s->soundscape, incoherent[i].second);
    }
    for (const auto& sid : p.groups[0].stimuli) EXPECT_FALSE(p.stimulus(sid)->soundscape);
    // Answer letters a..p as in Nordahl et al. 2011, exp. 2.
    const auto& o = p.questions.surfaceOptions;
    ASSERT_EQ(o.size(), 16u);
    EXPECT_EQ(o[0].letter, 'a');
    EXPECT_EQ(o[0].id, "beach_sand");
    EXPECT_EQ(o[2].label, "dirt");
    EXPECT_EQ(o[3].label, "snow");
    EXPECT_EQ(o[10].id, "carpet");
    EXPECT_EQ(o[12].id, "frozen_snow");
    EXPECT_EQ(o[15].letter, 'p');
    EXPECT_EQ(o[15].id, "dont_know");
    EXPECT_FALSE(p.questions.asksSoundscape("none"));
    EXPECT_TRUE(p.questions.asksSoundscape("coherent"));
    EXPECT_TRUE(p.questions.asksSoundscape("incoherent"));
    ASSERT_EQ(p.questions.scales.size(), 2u);
    EXPECT_EQ(p.questions.scales[0].id, "realism");
    EXPECT_EQ(p.questions.scales[0].max, 7);
}

TEST(ExperimentProtocol, Eurohaptics2010GroupsOverrideModalities) {
    const Protocol p = loadProtocol(shipped("eurohaptics2010.toml"));
    ASSERT_EQ(p.groups.size(), 3u);
    for (const auto& g : p.groups) EXPECT_EQ(g.stimuli.size(), 8u);
    const auto haptic = generatePlan(p, "haptic", 5, 1);
    ASSERT_EQ(haptic.size(), 16u);
    for (const auto& t : haptic) EXPECT_EQ(t.stimulus.modalities, Modalities::Haptic);
    for (const auto& t : generatePlan(p, "audiohaptic", 5, 2))
        EXPECT_EQ(t.stimulus.modalities, Modalities::AudioHaptic);
    EXPECT_EQ(p.stimulus("BS")->input.sensor, SensorKind::Fsr);
}

TEST(ExperimentProtocol, WadingFactorialGeneratesSixWaterConditionsAndPractice) {
    const Protocol p = loadProtocol(dataFile("wading_factorial.toml"));
    EXPECT_FALSE(p.questions.asksSurface());
    ASSERT_EQ(p.groups.size(), 1u);
    ASSERT_EQ(p.groups[0].stimuli.size(), 6u);
    int scales010 = 0, scales17 = 0;
    for (const auto& s : p.questions.scales) {
        scales010 += s.min == 0 && s.max == 10;
        scales17 += s.min == 1 && s.max == 7;
    }
    EXPECT_EQ(scales010, 4);
    EXPECT_EQ(scales17, 1);
    const Stimulus* deepFast = p.stimulus("wade_deep_fast");
    ASSERT_NE(deepFast, nullptr);
    EXPECT_EQ(deepFast->surface, "water");
    EXPECT_EQ(std::get<std::string>(deepFast->wading.at("depth")), "deep");
    EXPECT_EQ(std::get<std::string>(deepFast->wading.at("cadence")), "fast");
    EXPECT_EQ(std::get<std::string>(deepFast->wading.at("algorithm")), "v2");
    EXPECT_EQ(deepFast->factors.at("depth"), "deep");
    EXPECT_EQ(deepFast->input.kind, InputKind::Walker);
    const auto plan = generatePlan(p, "all", 3, 0);
    ASSERT_EQ(plan.size(), 13u);
    EXPECT_TRUE(plan[0].practice);
    EXPECT_EQ(plan[0].stimulus.id, "practice_normal");
    for (std::size_t i = 1; i < plan.size(); ++i) EXPECT_FALSE(plan[i].practice);
}

TEST(ExperimentProtocol, ReportsEveryProblemWithLineAndColumn) {
    const std::string text = "[protocol]\n"               // 1
                             "id = \"bad one\"\n"         // 2
                             "version = 1\n"              // 3
                             "title = \"x\"\n"            // 4
                             "[design]\n"                 // 5
                             "type = \"between\"\n"       // 6
                             "[[stimuli]]\n"              // 7
                             "id = \"A\"\n"               // 8
                             "surface = \"sand\"\n"       // 9
                             "modalitis = \"audio\"\n"    // 10
                             "[[stimuli]]\n"              // 11
                             "id = \"B\"\n"               // 12
                             "surface = \"wood\"\n"       // 13
                             "soundscape = \"moon\"\n"    // 14
                             "[[groups]]\n"               // 15
                             "id = \"g1\"\n"              // 16
                             "stimuli = []\n"             // 17
                             "[[groups]]\n"               // 18
                             "id = \"g2\"\n"              // 19
                             "stimuli = [\"B\", \"C\"]\n" // 20
                             "[questions.surface]\n"      // 21
                             "options = [\"wood\"]\n";    // 22
    const auto problems = problemsOf(text);
    EXPECT_TRUE(hasProblem(problems, "'bad one'", 2));
    EXPECT_TRUE(hasProblem(problems, "unknown surface 'sand'", 9));
    EXPECT_TRUE(hasProblem(problems, "unknown key 'modalitis'", 10));
    EXPECT_TRUE(hasProblem(problems, "unknown soundscape 'moon'", 14));
    EXPECT_TRUE(hasProblem(problems, "group 'g1' is empty", 17));
    EXPECT_TRUE(hasProblem(problems, "unknown stimulus 'C'", 20));
    EXPECT_GE(problems.size(), 6u);
    for (const auto& p : problems) {
        EXPECT_EQ(p.file, "t.toml");
        EXPECT_GT(p.line, 0) << p.message;
        EXPECT_GT(p.column, 0) << p.message;
    }
    // The message of the exception lists them all as file:line:column.
    try {
        parseProtocol(text, "t.toml");
        FAIL();
    } catch (const ProtocolError& e) {
        EXPECT_NE(std::string(e.what()).find("t.toml:9:11: unknown surface 'sand'"),
                  std::string::npos)
            << e.what();
    }
}

TEST(ExperimentProtocol, SyntaxErrorHasPosition) {
    const auto problems = problemsOf("[protocol]\nid = \"x\"\nversion = \n");
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].line, 3);
    EXPECT_NE(problems[0].message.find("syntax"), std::string::npos);
}

TEST(ExperimentProtocol, ImpossibleOrderingConstraintsAreErrorsNotRelaxed) {
    // One stimulus presented three times with no immediate repeat.
    const std::string single = "[protocol]\nid = \"s\"\nversion = 1\ntitle = \"s\"\n"
                               "[design]\ntype = \"within\"\n"
                               "[[stimuli]]\nid = \"WD\"\nsurface = \"wood\"\n"
                               "[ordering]\nrepetitions = 3\nno_immediate_repeat = true\n"
                               "[questions.surface]\noptions = [\"wood\"]\n";
    EXPECT_TRUE(hasProblem(problemsOf(single), "impossible ordering constraint", 10));
    // Fixed order of a single stimulus repeated: the seam between repetitions repeats it.
    std::string fixedSingle = single;
    fixedSingle.replace(fixedSingle.find("repetitions = 3"), 15,
                        "repetitions = 2\norder = \"fixed\"");
    EXPECT_TRUE(hasProblem(problemsOf(fixedSingle), "at the seam between repetitions"));
    // A fixed order of distinct stimuli satisfies the constraint.
    EXPECT_TRUE(problemsOf(miniProtocol("", "repetitions = 2\norder = \"fixed\"\n"
                                            "no_immediate_repeat = true\n"))
                    .empty());
    // A break that can never happen.
    EXPECT_TRUE(hasProblem(problemsOf(miniProtocol("", "repetitions = 2\nbreak_every = 6\n")),
                           "break_every = 6 leaves no break"));
    EXPECT_TRUE(problemsOf(miniProtocol("", "repetitions = 2\nbreak_every = 3\n")).empty());
}

TEST(ExperimentProtocol, ValidationUsesTheCallersCatalogue) {
    Catalogue engineList;
    engineList.surfaces = {{"wood", "wood", "WD"}, {"gravel", "gravel", "GL"}};
    const auto problems = problemsOf(miniProtocol(), engineList);
    EXPECT_TRUE(hasProblem(problems, "unknown surface 'wood_reverb'"));
    EXPECT_TRUE(hasProblem(problems, "unknown surface 'metal'"));
    EXPECT_TRUE(problemsOf(miniProtocol()).empty());
}

TEST(ExperimentProtocol, UnanswerableStimulusIsReported) {
    const std::string text = miniProtocol();
    std::string noWood = text;
    noWood.replace(noWood.find("options = [\"wood\", "), 19, "options = [");
    EXPECT_TRUE(
        hasProblem(problemsOf(noWood), "no answer option names the surface of stimulus 'WD'"));
}

TEST(ExperimentProtocol, ScalesAndOptionsAreChecked) {
    EXPECT_TRUE(hasProblem(problemsOf(miniProtocol("[[questions.scales]]\nid = \"q\"\nprompt = "
                                                   "\"q\"\nmin = 5\nmax = 5\n")),
                           "min 5 >= max 5"));
    EXPECT_TRUE(hasProblem(problemsOf(miniProtocol("[[questions.scales]]\nid = \"realism\"\n"
                                                   "prompt = \"again\"\nmin = 1\nmax = 7\n")),
                           "scale id 'realism' is used twice"));
}

TEST(ExperimentProtocol, StimulusTomlRoundTrip) {
    const Protocol p = loadProtocol(dataFile("wading_factorial.toml"));
    for (const auto& s : p.stimuli) EXPECT_EQ(stimulusFromToml(stimulusToToml(s)), s) << s.id;
    const Protocol e = loadProtocol(shipped("tvcg2011_exp2.toml"));
    for (const auto& s : e.stimuli) EXPECT_EQ(stimulusFromToml(stimulusToToml(s)), s) << s.id;
}

TEST(StoredStimulus, UnknownKeysAndWrongTypesAreRefusedWithTheirPlace) {
    auto errorOf = [](const std::string& text) {
        try {
            (void)stimulusFromToml(text);
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(errorOf("id = \"a\"\nsurface = \"wood\"\nsurfce = \"x\"\n"),
              "stored stimulus:3:1: unknown key 'surfce' in stored stimulus; expected one of: "
              "clip, factors, id, input, label, modalities, practice_only, reverb, soundscape, "
              "surface, wading (did you mean 'surface'?)");
    EXPECT_EQ(errorOf("id = \"a\"\nsurface = 3\n"),
              "stored stimulus:2:11: 'surface' in stored stimulus must be a string");
    EXPECT_EQ(errorOf("id = \"a\"\nsurface = \"wood\"\nmodalities = \"smell\"\n"),
              "stored stimulus:3:14: 'modalities' in stored stimulus is 'smell'; expected one of: "
              "audio, haptic, both, audio_haptic");
    EXPECT_EQ(errorOf("id = \"a\"\nsurface = \"wood\"\n[wading]\ndepth = nan\n"),
              "stored stimulus:4:9: 'depth' in [wading] is not a finite number");
}

TEST(ExperimentProtocol, MissingFileIsAProblemNotACrash) {
    EXPECT_THROW(loadProtocol("/nonexistent/protocol.toml"), ProtocolError);
}

TEST(ExperimentProtocol, Sha256OfKnownText) {
    // FIPS 180-2 test vector: SHA-256("abc").
    EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(ExperimentCatalogue, CorrectnessFollowsTheSurfaceWalkedOn) {
    EXPECT_TRUE(answerIsCorrect("wood", "wood_reverb"));
    EXPECT_TRUE(answerIsCorrect("wood_reverb", "wood_reverb"));
    EXPECT_TRUE(answerIsCorrect("wood", "wood"));
    EXPECT_FALSE(answerIsCorrect("creaking_wood", "wood_reverb"));
    EXPECT_FALSE(answerIsCorrect("dont_know", "wood"));
    EXPECT_FALSE(answerIsCorrect("", "wood"));
    EXPECT_EQ(baseSurface("metal_reverb"), "metal");
    EXPECT_EQ(defaultCatalogue().surfaces.size(), 18u);
    EXPECT_EQ(defaultCatalogue().soundscapes.size(), 5u);
}
