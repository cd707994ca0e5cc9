// SPDX-License-Identifier: GPL-3.0-or-later
#include "TestSupport.h"
#include "experiment/Session.h"
#include "experiment/TrialFlow.h"

#include <gtest/gtest.h>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
/// Records what the session asks the player to do; reports seed = planned + 1 and a GRF file.
class FakePlayer : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus& s, std::uint64_t plannedSeed) override {
        EXPECT_FALSE(playing) << "start() while playing";
        playing = true;
        log.push_back("start " + s.id);
        return {plannedSeed + 1, "grf/" + std::to_string(log.size()) + ".csv"};
    }
    void stop() override {
        if (playing) log.push_back("stop");
        playing = false;
    }
    bool playing = false;
    std::vector<std::string> log;
};

const char* kProtocol = R"(
[protocol]
id = "sess"
version = 1
title = "Session test"
[design]
type = "within"
[[stimuli]]
id = "WD"
surface = "wood"
[[stimuli]]
id = "GL"
surface = "gravel"
[[stimuli]]
id = "MT"
surface = "metal"
[[stimuli]]
id = "PR"
surface = "carpet"
practice_only = true
[ordering]
repetitions = 2
no_immediate_repeat = true
practice = ["PR"]
break_every = 3
[questions.surface]
options = ["wood", "gravel", "metal", "carpet"]
[[questions.scales]]
id = "quality"
prompt = "Quality"
min = 1
max = 7
)";

TrialAnswer answerFor(const TrialRecord& t) {
    TrialAnswer a;
    a.answer = t.stimulus.surface;
    a.ratings["quality"] = 4;
    return a;
}
} // namespace

TEST(ExperimentSession, RunsBriefingPracticeTrialsBreaksEnd) {
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("s.db"), parseProtocol(kProtocol, "s.toml"),
                                          {"S", "lab", 3, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    FakePlayer player;
    double now = 100.0;
    Session session(store, "P1", player, {"E", "a", "s", "t"}, [&] { return now; });
    EXPECT_EQ(session.phase(), SessionPhase::Briefing);
    EXPECT_FALSE(session.resumed());
    EXPECT_THROW(session.play(), std::logic_error);
    session.finishBriefing();
    std::vector<std::string> phases;
    while (session.phase() != SessionPhase::Finished) {
        phases.push_back(toString(session.phase()));
        if (session.phase() == SessionPhase::Break) {
            session.finishBreak();
            continue;
        }
        const TrialRecord t = session.current();
        EXPECT_THROW(session.answer(answerFor(t)), std::logic_error); // not played yet
        session.play();
        EXPECT_TRUE(player.playing);
        now += 2.0;
        TrialAnswer bad;
        bad.ratings["quality"] = 4; // the surface answer is missing
        TrialFlow flow(store, session);
        EXPECT_EQ(flow.submit(bad).refusal, Refusal::Incomplete);
        EXPECT_TRUE(player.playing) << "an invalid answer keeps the stimulus running";
        session.answer(answerFor(t));
        EXPECT_FALSE(player.playing);
    }
    EXPECT_EQ(phases, (std::vector<std::string>{"practice", "trial", "trial", "trial", "break",
                                                "trial", "trial", "trial"}));
    const auto trials = store.trials("P1");
    for (const auto& t : trials) {
        EXPECT_TRUE(t.answered);
        EXPECT_EQ(*t.renderSeed, t.plannedSeed + 1); // the player's seed is stored
        EXPECT_TRUE(t.grfRecording.has_value());
        EXPECT_DOUBLE_EQ(*t.responseTimeS, 2.0);
        EXPECT_EQ(t.sessionNumber, 1);
    }
    EXPECT_EQ(store.participant("P1").status, ParticipantStatus::Completed);
    EXPECT_EQ(player.log.front(), "start PR");
    EXPECT_THROW(Session(store, "P1", player, {}), StoreError); // nothing left to run
}

TEST(ExperimentSession, InterruptedSessionResumesAtFirstUnansweredTrial) {
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("s.db"), parseProtocol(kProtocol, "s.toml"),
                                          {"S", "lab", 3, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    FakePlayer player;
    {
        Session session(store, "P1", player, {"E", "a", "s", "t"});
        session.finishBriefing();
        for (int i = 0; i < 3; ++i) {
            session.play();
            session.answer(answerFor(session.current()));
        }
        // Trial 3 started but not answered when the lab's power fails.
        session.play();
        session.interrupt();
        EXPECT_FALSE(player.playing);
    }
    Session resumed(store, "P1", player, {"E", "a", "s", "t"});
    EXPECT_TRUE(resumed.resumed());
    EXPECT_EQ(resumed.sessionNumber(), 2);
    EXPECT_EQ(resumed.phase(), SessionPhase::Trial);
    EXPECT_EQ(resumed.current().index, 3);
    resumed.play();
    resumed.answer(answerFor(resumed.current()));
    EXPECT_EQ(store.trial("P1", 3).sessionNumber, 2);
    bool restarted = false;
    for (const auto& e : store.events()) restarted = restarted || e.kind == "trial_restarted";
    EXPECT_TRUE(restarted);
}
