// SPDX-License-Identifier: GPL-3.0-or-later
// An online trial replays bit for bit to what the server served: participants run a shipped
// listening protocol with soundscapes (tvcg2011_exp2_clips: footsteps alone, with matching and
// with mismatching environments) through the web API (loopback HTTP, a real SQLite file, clips
// rendered by `underfoot clips`' wiring::renderClipFolder); then wiring::renderTrialReplay, what
// `underfoot replay --trial N` runs, renders answered trials again (one per stimulus). Its
// samples' SHA-256 equals the one stored with the trial and the one of the clip file the
// server sent; every file sent is the manifest's, byte for byte.
#include "WebTestSupport.h"

#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Replay.h"
#include "app/wiring/StimulusRender.h"
#include "engine/io/AudioFile.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

namespace underfoot::web::test {
namespace {

namespace xp = underfoot::experiment;

TEST(WebReplay, AnOnlineTrialReplaysToTheSamplesOfTheClipServed) {
    const xp::Protocol p = xp::loadProtocol(
        (fs::path(xp::shippedProtocolDir()) / "tvcg2011_exp2_clips.toml").string());
    TempDir dir;
    const std::string clips = dir.file("clips"), study = dir.file("online.db");
    const auto manifest = wiring::renderClipFolder(p, clips);
    std::map<std::string, std::string> fileHash; // manifest: file name -> bytes' SHA-256
    for (const auto& r : manifest) fileHash[r.file] = r.sha256;
    std::vector<xp::NewInvitation> links;
    {
        xp::StudyStore store = xp::StudyStore::create(study, p, {"WEB", "web", 4, "test"});
        links = xp::Invitations(store).create(store, 3, std::nullopt); // one per group
    }
    // What each participant's page received: (code, trial) -> the served file's bytes.
    std::map<std::pair<std::string, int>, std::string> served;
    {
        ServerOptions fast;
        fast.ratePerSecond = 1000;
        fast.burst = 1000;
        InProcessServer s(study, clips, fast, testOptions());
        for (const auto& link : links) {
            const ApiClient c(s.port, link.token);
            json fields = json::object();
            for (const auto& f : p.participantFields)
                fields[f.id] = f.options.empty() ? std::string("x") : f.options.front();
            ASSERT_EQ(c.post("/api/consent", {{"consent", true}, {"fields", fields}}).status, 200);
            json state = startParticipant(c);
            for (int n = 0; n < 200 && state.value("phase", "") != "finished"; ++n) {
                if (state.value("phase", "") == "break") {
                    state = c.post("/api/break", json::object()).body;
                    continue;
                }
                ASSERT_TRUE(state.contains("trial")) << state.dump();
                const int index = state["trial"]["index"];
                ASSERT_EQ(c.post("/api/present", {{"trial", index}}).status, 200);
                const Reply clip = c.get("/api/clip/" + std::to_string(index));
                ASSERT_EQ(clip.status, 200);
                served[{link.participantCode, index}] = clip.raw;
                const Reply r = c.post("/api/answer", validAnswer(state, "a" + std::to_string(n)));
                ASSERT_EQ(r.status, 200) << r.raw;
                state = r.body;
            }
            EXPECT_EQ(state.value("phase", ""), "finished");
        }
    }
    // Every trial's file is checked; each stimulus is replayed once (the render is the costly
    // part, and trials of one stimulus play the same clip).
    int trials = 0, replayedTrials = 0, withSoundscape = 0;
    std::set<std::string> replayedStimuli;
    xp::StudyStore store = xp::StudyStore::open(study);
    for (const auto& link : links)
        for (const auto& t : store.trials(link.participantCode)) {
            SCOPED_TRACE(link.participantCode + " trial " + std::to_string(t.index));
            ASSERT_TRUE(t.answered);
            ASSERT_TRUE(t.clip.has_value());
            const std::string& bytes = served.at({link.participantCode, t.index});
            // The file sent is the manifest's, byte for byte.
            EXPECT_EQ(xp::sha256Hex(bytes), fileHash.at(t.clip->file));
            ++trials;
            if (!replayedStimuli.insert(t.stimulus.id).second) continue;
            const std::string copy = dir.file("served.wav");
            std::ofstream(copy, std::ios::binary) << bytes;
            const std::string heard = wiring::samplesSha256(engine::readAudioFile(copy));
            wiring::ReplayRequest q;
            q.study = study;
            q.participant = link.participantCode;
            q.trial = t.index;
            const wiring::ReplayRender again = wiring::renderTrialReplay(q);
            const std::string replayed = wiring::samplesSha256(again.audio);
            EXPECT_EQ(replayed, t.clip->samplesSha256);
            EXPECT_EQ(replayed, heard);
            EXPECT_EQ(again.matchesHeard, true);
            ++replayedTrials;
            withSoundscape += t.stimulus.soundscape.has_value();
        }
    std::printf("[figures] web replay: %d online trials of %zu participants served the "
                "manifest's file; %d of them (one per stimulus) replayed to the served clip's "
                "samples, %d with a soundscape\n",
                trials, links.size(), replayedTrials, withSoundscape);
    EXPECT_GT(replayedTrials, 0);
    EXPECT_GT(withSoundscape, 0);
}

} // namespace
} // namespace underfoot::web::test
