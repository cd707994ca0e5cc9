// SPDX-License-Identifier: GPL-3.0-or-later
// What is stored is what was heard: for every shipped listening protocol whose clips Underfoot
// renders, the clip folder of `underfoot clips` (wiring::renderClipFolder) is played in a booth
// session (experiment::Session + ClipPlayer through TrialFlow, as `session --clips` does) and
// stood for by a simulated participant (`session --simulate --clips`); every answered trial of
// both replays (wiring::renderTrialReplay) to samples whose SHA-256 is the one stored with it.
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Replay.h"
#include "experiment/Clips.h"
#include "experiment/Simulation.h"
#include "experiment/TrialFlow.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;

namespace {

struct Figures {
    int trials = 0;
    int matched = 0;
    std::vector<std::string> mismatches;
};

/// Replays every answered trial of `code` and compares it with what was stored as heard.
void replayAll(const std::string& study, const xp::StudyStore& store, const std::string& code,
               const std::string& path, Figures& f) {
    for (const auto& t : store.trials(code)) {
        if (!t.answered) continue;
        ++f.trials;
        wir::ReplayRequest q;
        q.study = study;
        q.participant = code;
        q.trial = t.index;
        const auto r = wir::renderTrialReplay(q);
        if (r.matchesHeard && *r.matchesHeard)
            ++f.matched;
        else
            f.mismatches.push_back(path + " " + r.description);
    }
}

/// One booth session of `code` through TrialFlow and a ClipPlayer that plays nothing.
void runBooth(xp::StudyStore& store, const std::string& code, const std::string& clipDir) {
    xp::ClipPlayer player(store.protocol(), clipDir);
    xp::Session session(store, code, player, {"booth", "test", "clips " + clipDir, "t", true});
    xp::TrialFlow flow(store, session);
    while (session.phase() != xp::SessionPhase::Finished) {
        if (session.phase() == xp::SessionPhase::Briefing) {
            session.finishBriefing();
        } else if (session.phase() == xp::SessionPhase::Break) {
            session.finishBreak();
        } else {
            flow.reset();
            ASSERT_TRUE(flow.start()) << flow.start().message;
            for (const auto& sec : flow.sections()) {
                if (sec.kind == xp::SectionKind::Scale)
                    flow.setRating(sec.scale->id, sec.scale->max);
                else
                    flow.choose(sec.kind, sec.options.back().letter);
            }
            const auto r = flow.commit();
            ASSERT_TRUE(r) << r.message;
        }
    }
}

} // namespace

TEST(ReplayHeard, EveryShippedListeningProtocolReplaysToTheSamplesItsParticipantsHeard) {
    int protocols = 0;
    Figures booth, simulated;
    for (const auto& entry : fs::directory_iterator(xp::shippedProtocolDir())) {
        if (entry.path().extension() != ".toml") continue;
        const xp::Protocol p = xp::loadProtocol(entry.path().string());
        if (!p.clips.enabled) continue;
        bool labClips = false;
        for (const auto& s : p.stimuli) labClips = labClips || s.clip.has_value();
        if (labClips) continue; // the lab's recordings are not shipped (wading_realism)
        ++protocols;
        const std::string dir = underfoot::test::scratchDir("replay_heard_" + p.id).string();
        wir::renderClipFolder(p, dir + "/clips");
        const std::string study = dir + "/study.db";
        xp::StudyStore store = xp::StudyStore::create(study, p, {"R", "lab", 11, "t"});
        store.registerParticipant({"B1", {}, "", "", "", {}, ""});
        runBooth(store, "B1", dir + "/clips");
        replayAll(study, store, "B1", "booth", booth);

        xp::SimulationSettings settings;
        settings.clipDir = dir + "/clips";
        auto matrices = xp::defaultMatrices(p, entry.path().string());
        if (matrices.empty()) matrices[""] = xp::ConfusionMatrix{}; // rating-only protocols
        ASSERT_GT(xp::simulateStudy(store, matrices, 1, settings), 0);
        for (const auto& who : store.participants())
            if (who.simulated) replayAll(study, store, who.code, "simulated", simulated);
    }
    EXPECT_GE(protocols, 2); // tvcg2011_exp2_clips, wading_listening
    EXPECT_GT(booth.trials, 0);
    EXPECT_GT(simulated.trials, 0);
    EXPECT_EQ(booth.matched, booth.trials);
    EXPECT_EQ(simulated.matched, simulated.trials);
    for (const auto& m : booth.mismatches) ADD_FAILURE() << m;
    for (const auto& m : simulated.mismatches) ADD_FAILURE() << m;
    // The figures of docs/decisions/one-trial-core.md.
    std::printf("replay heard: %d protocols; booth %d of %d trials identical; simulated %d of %d\n",
                protocols, booth.matched, booth.trials, simulated.matched, simulated.trials);
}
