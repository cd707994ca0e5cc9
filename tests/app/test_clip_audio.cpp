// SPDX-License-Identifier: GPL-3.0-or-later
// app/wiring/ClipPlayer: a listening-test clip played through the live engine reaches the
// headphone channels sample for sample (after the engine's crossfade), nothing reaches the
// haptic channels, and the clip ends in silence; a rendered clip folder passes checkClips.
#include "app/wiring/ClipPlayer.h"
#include "experiment/Protocol.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eng = underfoot::engine;
namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;

TEST(ClipAudio, ClipReachesTheHeadphonesSampleForSample) {
    eng::AudioSettings s;
    s.sampleRateHz = 48000;
    s.blockSize = 64;
    s.channels.haptic[0] = {2, 3};
    s.channels.haptic[1] = {4, 5};
    eng::LiveEngine engine;
    engine.openOffline(s);

    // 0.25 s stereo clip at the engine's rate: 440 Hz at 0.5 left, 0.25 right.
    eng::AudioBuffer clip;
    clip.sampleRateHz = 48000;
    clip.channels = 2;
    const std::size_t frames = 12000;
    for (std::size_t f = 0; f < frames; ++f) {
        const float x =
            static_cast<float>(std::sin(2.0 * M_PI * 440.0 * static_cast<double>(f) / 48000.0));
        clip.samples.push_back(0.5f * x);
        clip.samples.push_back(0.25f * x);
    }
    const auto path = (underfoot::test::scratchDir("clip_audio") / "clip.wav").string();
    eng::writeAudioFile(path, clip);

    wir::ClipAudio audio(engine);
    audio.play(path);
    EXPECT_TRUE(audio.playing());
    EXPECT_EQ(audio.lastFrames(), frames);

    const int outputs = engine.outputChannels();
    ASSERT_GE(outputs, 6);
    std::vector<std::vector<float>> out(static_cast<std::size_t>(outputs), std::vector<float>(64));
    std::vector<float*> op;
    for (auto& c : out) op.push_back(c.data());
    std::vector<std::vector<float>> got(static_cast<std::size_t>(outputs));
    const int blocks = 250; // 16000 frames: the clip and a third of a second after it
    for (int b = 0; b < blocks; ++b) {
        engine.processBlock(nullptr, op.data(), 64);
        for (int c = 0; c < outputs; ++c)
            got[static_cast<std::size_t>(c)].insert(got[static_cast<std::size_t>(c)].end(),
                                                    out[static_cast<std::size_t>(c)].begin(),
                                                    out[static_cast<std::size_t>(c)].end());
    }
    const auto fadeFrames = static_cast<std::size_t>(s.crossfadeMs * 1e-3 * 48000.0) + 64;
    double maxError = 0, peakLeft = 0, peakRight = 0, haptic = 0, after = 0;
    for (std::size_t f = 0; f < got[0].size(); ++f) {
        if (f >= fadeFrames && f < frames) {
            maxError =
                std::max(maxError, static_cast<double>(std::abs(got[0][f] - clip.samples[2 * f])));
            maxError = std::max(maxError,
                                static_cast<double>(std::abs(got[1][f] - clip.samples[2 * f + 1])));
        }
        if (f < frames) {
            peakLeft = std::max(peakLeft, static_cast<double>(std::abs(got[0][f])));
            peakRight = std::max(peakRight, static_cast<double>(std::abs(got[1][f])));
        } else {
            after = std::max({after, static_cast<double>(std::abs(got[0][f])),
                              static_cast<double>(std::abs(got[1][f]))});
        }
        for (int c = 2; c < 6; ++c)
            haptic = std::max(haptic,
                              static_cast<double>(std::abs(got[static_cast<std::size_t>(c)][f])));
    }
    EXPECT_LT(maxError, 1e-6);
    EXPECT_NEAR(peakLeft, 0.5, 1e-3);
    EXPECT_NEAR(peakRight, 0.25, 1e-3);
    EXPECT_EQ(haptic, 0.0);
    EXPECT_EQ(after, 0.0);
    audio.stop();
    EXPECT_FALSE(audio.playing());

    EXPECT_THROW(audio.play(path + ".missing.wav"), eng::FileError);
}

TEST(ClipAudio, RenderedFolderPassesTheSessionCheck) {
    auto protocol =
        xp::loadProtocol(std::string(UNDERFOOT_SOURCE_DIR) + "/protocols/wading_listening.toml");
    protocol.clips.seconds = 0.3;
    const auto dir = (underfoot::test::scratchDir("clip_folder") / "clips").string();
    EXPECT_FALSE(xp::checkClips(protocol, dir).empty());
    int calls = 0, lastDone = -1;
    const auto records =
        wir::renderClipFolder(protocol, dir, 48000.0, [&](int done, int total, const std::string&) {
            ++calls;
            lastDone = done;
            EXPECT_EQ(total, 6);
            return true;
        });
    EXPECT_EQ(records.size(), 6u);
    EXPECT_EQ(calls, 7);
    EXPECT_EQ(lastDone, 6);
    EXPECT_TRUE(xp::checkClips(protocol, dir).empty());
    // Stopped at once: nothing but what was already there; no manifest change.
    const auto stopped = wir::renderClipFolder(protocol, dir + "_stopped", 48000.0,
                                               [](int, int, const std::string&) { return false; });
    EXPECT_TRUE(stopped.empty());
    EXPECT_FALSE(xp::checkClips(protocol, dir + "_stopped").empty());
}
