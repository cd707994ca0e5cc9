// SPDX-License-Identifier: GPL-3.0-or-later
// The participant-visible contract over every shipped protocol: one participant per group runs
// a whole session through TrialFlow, and no screen of its participant screen model shows the
// experimenter's notes, group names, the current stimulus's ids, clip file names, seeds or the
// correct answer (support/ParticipantScreens.h). Injected leaks prove that the search finds them.
#include "TestSupport.h"
#include "support/ParticipantScreens.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {

struct WalkFigures {
    int screens = 0;
    int searched = 0; ///< forbidden strings searched, summed over the screens
    std::vector<std::string> found;
};

/// One participant per group of `protocol` through every screen.
WalkFigures walkEveryGroup(const Protocol& protocol, const TempDir& dir, const std::string& name) {
    WalkFigures f;
    StudyStore store = StudyStore::create(dir.file(name + ".db"), protocol, {"C", "lab", 5, "t"});
    const std::size_t groups = std::max<std::size_t>(1, protocol.groups.size());
    for (std::size_t g = 0; g < groups; ++g) {
        std::map<std::string, std::string> fields;
        for (const auto& field : protocol.participantFields)
            fields[field.id] = field.options.empty() ? "x" : field.options.front();
        NewParticipant who{"P" + std::to_string(g + 1), {}, "", "", "", {}, ""};
        if (!protocol.groups.empty() && protocol.design == DesignKind::Between) {
            who.groupOverride = protocol.groups[g].id;
            who.overrideReason = "every group's screens";
        }
        store.registerParticipant(who, fields);
        std::string options; // the answer lists never change with the stimulus
        f.screens += walkParticipantScreens(
            store, who.code,
            [&](const ParticipantScreen& screen, const TrialFlow&, const TrialRecord* trial) {
                const auto forbidden = forbiddenStrings(protocol, trial);
                f.searched += static_cast<int>(forbidden.size());
                for (const auto& hit :
                     leaks(screenFreeText(screen), screenVaryingText(screen), forbidden))
                    f.found.push_back(screen.heading + ": " + hit);
                if (screen.page == ParticipantScreen::Page::Trial && !screen.sections.empty()) {
                    const std::string now = screenOptions(screen);
                    if (options.empty()) options = now;
                    if (now != options)
                        f.found.push_back(screen.heading + ": the answer lists changed");
                }
            });
    }
    return f;
}

} // namespace

TEST(ParticipantContract, NoScreenOfAnyShippedProtocolShowsWhatOnlyTheExperimenterMayRead) {
    TempDir dir;
    int protocols = 0;
    int screens = 0;
    int searched = 0;
    for (const auto& entry : std::filesystem::directory_iterator(shippedProtocolDir())) {
        if (entry.path().extension() != ".toml") continue;
        const Protocol p = loadProtocol(entry.path().string());
        const WalkFigures f = walkEveryGroup(p, dir, p.id);
        ++protocols;
        screens += f.screens;
        searched += f.searched;
        EXPECT_GT(f.screens, 3) << p.id;
        for (const auto& hit : f.found) ADD_FAILURE() << p.id << ": " << hit;
    }
    EXPECT_GE(protocols, 7);
    // The figures of docs/decisions/one-trial-core.md.
    std::printf("participant contract: %d protocols, %d screens, %d forbidden-string searches\n",
                protocols, screens, searched);
}

TEST(ParticipantContract, InjectedLeaksAreFound) {
    TempDir dir;
    const std::string base = loadProtocol(shipped("tvcg2011_exp2.toml")).sourceText;
    // The notes copied into the participant's briefing.
    {
        const Protocol p = loadProtocol(shipped("tvcg2011_exp2.toml"));
        std::string text = base;
        const std::string firstSentence = p.notes.substr(0, p.notes.find('.'));
        text.replace(text.find("briefing = \"\"\""), 14,
                     "briefing = \"\"\"" + firstSentence + ". ");
        const WalkFigures f = walkEveryGroup(parseProtocol(text, "inject.toml"), dir, "notes");
        ASSERT_FALSE(f.found.empty());
        EXPECT_NE(f.found.front().find("notes '"), std::string::npos) << f.found.front();
    }
    // A surface id in a prompt: found in the trials whose stimulus walks on it.
    {
        std::string text = base;
        const std::size_t at = text.find("prompt = \"");
        ASSERT_NE(at, std::string::npos);
        text.insert(at + 10, "deep_snow ");
        const Protocol p = parseProtocol(text, "inject.toml");
        const WalkFigures f = walkEveryGroup(p, dir, "surface");
        bool surface = false;
        for (const auto& hit : f.found)
            surface = surface || hit.find("surface id 'deep_snow'") != hit.npos;
        EXPECT_TRUE(surface);
    }
    // The search itself: whole words only for ids, substrings for sentences.
    EXPECT_TRUE(contains("you walk on gravel.", "gravel", true));
    EXPECT_FALSE(contains("gravel_reverb", "gravel", true));
    EXPECT_TRUE(contains("Group coherent: each surface", "each surf", false));
}

// The trial core's free rules (TrialFlow.h) that every front end asks.
TEST(TrialCoreRules, PartRangeLockAndPersonSession) {
    TempDir dir;
    const Protocol p = loadProtocol(shipped("wading_listening.toml"));
    StudyStore store = StudyStore::create(dir.file("w.db"), p, {"W", "lab", 2, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    std::vector<std::string> parts;
    walkParticipantScreens(store, "P1",
                           [&](const ParticipantScreen& s, const TrialFlow&, const TrialRecord*) {
                               if (!s.part.empty() && (parts.empty() || parts.back() != s.part))
                                   parts.push_back(s.part);
                           });
    ASSERT_EQ(parts.size(), p.questions.scales.size()); // one part per scale, in block order
    EXPECT_EQ(parts.front(), "Part 1 of 4: " + p.questions.scales.front().prompt);

    const Scale& depth = p.questions.scales.front();
    EXPECT_TRUE(ratingInRange(depth, depth.min));
    EXPECT_FALSE(ratingInRange(depth, depth.max + 1));
    EXPECT_EQ(ratingRangeProblem(depth, depth.max + 1),
              fmt::format("{} is outside the scale {}–{}.", depth.max + 1, depth.min, depth.max));
    EXPECT_EQ(ratingRangeProblem(depth, depth.min), "");

    Protocol locked = p;
    locked.lock = LockRule::OnAnswer;
    EXPECT_NE(lockRefusal(locked, false).find("lock = \"answer\""), std::string::npos);
    EXPECT_EQ(lockRefusal(p, false), "");
    EXPECT_NE(lockRefusal(p, true).find("lock = \"next_trial\""), std::string::npos);

    ParticipantInfo person;
    person.code = "P9";
    EXPECT_EQ(personSessionRefusal(person), "");
    person.simulated = true;
    EXPECT_NE(personSessionRefusal(person).find("simulated participant"), std::string::npos);
    EXPECT_EQ(progressText(12, 40), "12 of 40 trials answered");

    // answerProblems is the trial core's rule (the store keeps only its schema).
    const TrialRecord t = store.trials("P1").front();
    TrialAnswer a;
    a.ratings[depth.id] = depth.max + 1;
    EXPECT_FALSE(answerProblems(p, "all", a, t.stimulus, t.block).empty());
}
