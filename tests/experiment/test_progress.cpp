// SPDX-License-Identifier: GPL-3.0-or-later
#include "TestSupport.h"
#include "experiment/Progress.h"
#include "experiment/Session.h"

#include <gtest/gtest.h>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

TEST(ExperimentProgress, CountsAnsweredTrialsPerParticipantAndGroups) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("p.db"), loadProtocol(shipped("eurohaptics2010.toml")), {"EH", "lab", 10, "t"});
    for (int i = 0; i < 4; ++i)
        store.registerParticipant({"P" + std::to_string(i), {}, "", "", "", {}, ""});
    SilentPlayer player;
    {
        Session s(store, "P0", player, {"E", "a", "s", "t"});
        s.finishBriefing();
        for (int i = 0; i < 5; ++i) {
            TrialAnswer a;
            a.answer = s.current().stimulus.surface;
            a.ratings = {{"realism", 4}, {"quality", 4}};
            s.play();
            s.answer(a);
        }
    }
    store.dropParticipant("P3", "left early");
    const StudyProgress p = studyProgress(store);
    ASSERT_EQ(p.participants.size(), 4u);
    EXPECT_EQ(p.participants[0].answered, 5);
    EXPECT_EQ(p.participants[0].planned, 16);
    EXPECT_EQ(p.participants[1].answered, 0);
    EXPECT_EQ(p.participants[3].status, ParticipantStatus::Dropped);
    int active = 0, dropped = 0;
    for (const auto& g : p.groups) {
        active += g.active;
        dropped += g.dropped;
        EXPECT_EQ(g.target, 10);
    }
    EXPECT_EQ(active, 3);
    EXPECT_EQ(dropped, 1);
    ASSERT_EQ(p.plan.groups.size(), 3u);
    EXPECT_EQ(p.plan.groups[0].mainTrials, 16);
    EXPECT_EQ(p.plan.balance[0].participants, 10); // the group target
}
