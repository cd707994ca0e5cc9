// SPDX-License-Identifier: GPL-3.0-or-later
// Every trial replayable: the first trial of each shipped sensor-driven footstep
// protocol (microphones: TVCG 2011 exp. 1 and 2; FSR shoes: Eurohaptics 2010) runs through the
// live path — a study, a Session, the LivePlayer on a LiveEngine whose callback body runs here at
// the live block size (64 frames at 48 kHz) with the sensor's signal fed in — and
// `underfoot replay` (renderTrialReplay) of that stored trial gives the samples that were
// played, bit for bit (after the engine's 10 ms fade-in, applied to the replay the same way).
#include "app/wiring/Adapters.h"
#include "app/wiring/Players.h"
#include "app/wiring/Replay.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/dsp/Random.h"
#include "experiment/Session.h"
#include "experiment/Store.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <thread>

namespace eng = underfoot::engine;
namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;

namespace {

constexpr int kBlock = 64;
constexpr int kBlocks = 3 * 48000 / kBlock; // 3 s of live audio

struct Played {
    std::vector<float> left, right;
};

/// The study's first trial played live, then replayed; returns the largest difference.
void liveThenReplay(const std::string& protocolFile, const std::string& name) {
    SCOPED_TRACE(name);
    const auto dir = underfoot::test::scratchDir("replay_protocols") / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string studyPath = (dir / "study.db").string();
    auto store =
        xp::StudyStore::create(studyPath, xp::loadProtocol(protocolFile), {"RP", "ci", 17, "t"});
    const auto& protocol = store.protocol();
    const xp::SensorKind sensor = protocol.stimuli.front().input.sensor;

    eng::AudioSettings settings;
    settings.sampleRateHz = 48000;
    settings.blockSize = kBlock;
    settings.channels.microphones = {0, 1};
    eng::LiveEngine engine;
    engine.openOffline(settings);

    wir::LivePlayerOptions options;
    options.studyFolder = dir.string();
    options.recordingFolder = (dir / "recordings").string();
    std::shared_ptr<eng::StepGrfPlayer> steps;
    if (sensor == xp::SensorKind::Fsr) {
        eng::StepGrfPlayerConfig config;
        config.seed = 3;
        steps = std::make_shared<eng::StepGrfPlayer>(eng::StepGrfPlayer::loadDefaultBank(48000),
                                                     config);
        options.scene.fsrSource = std::make_shared<wir::StepGrfSource>(steps);
    }
    wir::LivePlayer player(engine, options);

    // The first registered participant whose first trial is heard (audio or audio + haptics).
    std::string code;
    for (int i = 1; i <= 6 && code.empty(); ++i) {
        const std::string c = "P" + std::to_string(i);
        store.registerParticipant({c, 30, "", "", "", {}, ""});
        if (store.trials(c).front().stimulus.modalities != xp::Modalities::Haptic) code = c;
    }
    ASSERT_FALSE(code.empty());
    xp::Session session(store, code, player, {"test", "offline engine", "fed", "t", true});
    session.finishBriefing();
    session.play();

    // The sensor: footsteps every 0.55 s, alternating feet. Microphones hear a decaying noise
    // burst; the shoes report a heel strike.
    eng::Random noise(42);
    std::vector<std::vector<float>> in(2, std::vector<float>(kBlock)),
        out(2, std::vector<float>(kBlock));
    std::vector<const float*> ip{in[0].data(), in[1].data()};
    std::vector<float*> op{out[0].data(), out[1].data()};
    Played played;
    std::size_t t = 0;
    for (int b = 0; b < kBlocks; ++b) {
        for (int i = 0; i < kBlock; ++i, ++t) {
            const double phase = std::fmod(static_cast<double>(t) / 48000.0, 0.55);
            const float env = static_cast<float>(0.6 * std::exp(-phase / 0.04));
            in[0][i] = env * static_cast<float>(noise.bipolar());
            in[1][i] = 0.5f * in[0][i];
        }
        if (steps && t % 26400 < kBlock) {
            eng::StepEvent e;
            e.foot = (t / 26400) % 2 ? eng::Foot::Right : eng::Foot::Left;
            e.strength = 0.8f;
            steps->pushStep(e);
        }
        engine.processBlock(ip.data(), op.data(), kBlock);
        played.left.insert(played.left.end(), out[0].begin(), out[0].end());
        played.right.insert(played.right.end(), out[1].begin(), out[1].end());
    }
    // Stopping waits for the audio thread to hand the scene back: keep the callback running.
    std::atomic<bool> running{true};
    std::thread audio([&] {
        std::vector<std::vector<float>> o(2, std::vector<float>(kBlock));
        std::vector<float*> p{o[0].data(), o[1].data()};
        std::vector<std::vector<float>> silent(2, std::vector<float>(kBlock, 0.0f));
        std::vector<const float*> s{silent[0].data(), silent[1].data()};
        while (running) {
            engine.processBlock(s.data(), p.data(), kBlock);
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
    });
    xp::TrialAnswer answer;
    const auto& q = protocol.questions;
    answer.answer = q.surfaceOptions.front().id;
    for (const xp::Scale* s : session.askedScales()) answer.ratings[s->id] = s->min;
    if (q.asksSoundscape(session.participant().groupId))
        answer.soundscapeAnswer = q.soundscapeOptions.front().id;
    session.answer(answer);
    running = false;
    audio.join();
    engine.close();

    const auto trial = store.trial(code, 0);
    ASSERT_TRUE(trial.grfRecording.has_value());
    ASSERT_TRUE(trial.audio.has_value());
    EXPECT_EQ(trial.audio->blockSize, kBlock);

    wir::ReplayRequest request;
    request.study = studyPath;
    request.participant = code;
    request.trial = 0;
    const auto replay = wir::renderTrialReplay(request);
    EXPECT_EQ(replay.blockSize, kBlock);
    const std::size_t n = played.left.size();
    ASSERT_GE(replay.audio.frames(), n);
    double energy = 0;
    std::size_t mismatches = 0;
    double maxDiff = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const float g = eng::LiveScene::fadeGain(static_cast<std::int64_t>(i), 480);
        const float el = g * replay.audio.samples[2 * i];
        const float er = g * replay.audio.samples[2 * i + 1];
        energy += double(played.left[i]) * played.left[i];
        if (el != played.left[i] || er != played.right[i]) ++mismatches;
        maxDiff = std::max({maxDiff, double(std::fabs(el - played.left[i])),
                            double(std::fabs(er - played.right[i]))});
    }
    EXPECT_GT(energy, 1e-3) << "the fed sensor made footsteps heard";
    EXPECT_EQ(mismatches, 0u) << "largest difference " << maxDiff << " over " << n << " frames";
    std::printf("%s: %zu frames played live, replay mismatches %zu, largest difference %g\n",
                name.c_str(), n, mismatches, maxDiff);
}

} // namespace

TEST(ReplayProtocols, MicrophoneTrialsOfTvcg2011Exp1ReplayBitForBit) {
    liveThenReplay(xp::shippedProtocolDir() + "/tvcg2011_exp1.toml", "tvcg2011_exp1");
}

TEST(ReplayProtocols, MicrophoneTrialsOfTvcg2011Exp2ReplayBitForBit) {
    liveThenReplay(xp::shippedProtocolDir() + "/tvcg2011_exp2.toml", "tvcg2011_exp2");
}

TEST(ReplayProtocols, FsrTrialsOfEurohaptics2010ReplayBitForBit) {
    liveThenReplay(xp::shippedProtocolDir() + "/eurohaptics2010.toml", "eurohaptics2010");
}
