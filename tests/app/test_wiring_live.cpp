// SPDX-License-Identifier: GPL-3.0-or-later
// app/wiring: a protocol's stimulus becomes a live scene with exactly its nodes; the LivePlayer
// records the GRF next to the study and returns a path `underfoot replay` resolves; a recorded
// live trial with a soundscape replays (renderer + soundscape as `underfoot replay` mixes it)
// to the samples that were played.
#include "app/wiring/Players.h"
#include "app/wiring/Replay.h"
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "engine/scene/WadingNode.h"
#include "engine/wading/Gait.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"
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

eng::AudioSettings settings() {
    eng::AudioSettings s;
    s.sampleRateHz = 48000;
    s.blockSize = 64;
    s.channels.haptic[0] = {2, 3};
    s.channels.haptic[1] = {4, 5};
    s.channels.microphones = {0, 1};
    return s;
}

xp::Stimulus stimulus(const std::string& surface) {
    xp::Stimulus s;
    s.id = "t_" + surface;
    s.surface = surface;
    s.input.kind = xp::InputKind::Walker;
    s.input.walker["cadence"] = 105.0;
    return s;
}

std::unique_ptr<eng::LiveScene> sceneOf(const xp::Stimulus& st,
                                        const wir::StimulusSceneOptions& o = {}) {
    return eng::LiveScene::create(wir::describeStimulus(st, 5, o), {48000, 64},
                                  settings().channels);
}

} // namespace

TEST(Wiring, StimulusBecomesASceneWithOnlyItsNodes) {
    auto plain = stimulus("wood");
    auto s = sceneOf(plain);
    EXPECT_EQ(s->control(), eng::ControlKind::Walker);
    EXPECT_FALSE(s->hasNode(eng::SceneNode::Reverb));
    EXPECT_FALSE(s->hasNode(eng::SceneNode::Ambience));
    EXPECT_FALSE(s->hasNode(eng::SceneNode::Haptics));

    auto rich = stimulus("metal");
    rich.reverb = "small_room";
    rich.soundscape = "forest";
    rich.modalities = xp::Modalities::AudioHaptic;
    s = sceneOf(rich);
    EXPECT_TRUE(s->hasNode(eng::SceneNode::Reverb));
    EXPECT_TRUE(s->hasNode(eng::SceneNode::Ambience));
    EXPECT_TRUE(s->hasNode(eng::SceneNode::Haptics));
    EXPECT_NE(s->summary().find("soundscape forest"), std::string::npos) << s->summary();

    rich.modalities = xp::Modalities::Haptic; // earplugs: no room, no soundscape
    s = sceneOf(rich);
    EXPECT_FALSE(s->hasNode(eng::SceneNode::Reverb));
    EXPECT_FALSE(s->hasNode(eng::SceneNode::Ambience));
    EXPECT_TRUE(s->hasNode(eng::SceneNode::Haptics));

    auto mic = stimulus("gravel");
    mic.input.kind = xp::InputKind::Sensor;
    mic.input.sensor = xp::SensorKind::Microphones;
    EXPECT_EQ(sceneOf(mic)->control(), eng::ControlKind::Microphones);

    auto fsr = mic;
    fsr.input.sensor = xp::SensorKind::Fsr;
    try {
        sceneOf(fsr);
        FAIL() << "an FSR stimulus without a shoe source was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("FSR shoes"), std::string::npos) << e.what();
    }

    auto badWalker = stimulus("wood");
    badWalker.input.walker["speed"] = 1.0;
    EXPECT_THROW(sceneOf(badWalker), std::invalid_argument);
}

TEST(Wiring, LivePlayerRecordsTheGrfNextToTheStudy) {
    eng::LiveEngine engine;
    engine.openOffline(settings());
    // A stand-in for the device's callback thread.
    std::atomic<bool> running{true};
    std::thread audio([&] {
        std::vector<std::vector<float>> out(6, std::vector<float>(64));
        std::vector<float*> op;
        for (auto& c : out) op.push_back(c.data());
        while (running) {
            engine.processBlock(nullptr, op.data(), 64);
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    });
    const auto study = underfoot::test::scratchDir("wiring_live") / "study";
    wir::LivePlayerOptions o;
    o.studyFolder = study.string();
    o.recordingFolder = (study / "recordings").string();
    wir::LivePlayer player(engine, o);
    const auto start = player.start(stimulus("wood"), 77);
    EXPECT_EQ(start.renderSeed, 77u);
    ASSERT_TRUE(start.grfRecording.has_value());
    EXPECT_EQ(fs::path(*start.grfRecording).parent_path(), "recordings") << *start.grfRecording;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const auto second = player.start(stimulus("gravel"), 78); // stops the first one
    ASSERT_TRUE(second.grfRecording.has_value());
    EXPECT_NE(*second.grfRecording, *start.grfRecording);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    player.stop();
    EXPECT_EQ(player.lastDroppedFrames(), 0u);
    const auto& stats = player.lastTrialStats();
    EXPECT_GT(stats.frames, 4800u);
    EXPECT_GT(stats.averageLoadPercent, 0.0);
    EXPECT_TRUE(fs::exists(study / (*second.grfRecording + ".meters.toml")));
    running = false;
    audio.join();
    for (const auto* ref : {&*start.grfRecording, &*second.grfRecording}) {
        const auto grf = eng::loadGrfFile((study / *ref).string());
        EXPECT_EQ(grf.channels.size(), 2u);
        EXPECT_GT(grf.frames(), 4800u) << *ref;
        float peak = 0;
        for (float v : grf.channels[0]) peak = std::max(peak, v);
        EXPECT_GT(peak, 100.0f) << "the walker's left foot in " << *ref;
    }
}

TEST(Wiring, LiveTrialWithSoundscapeReplaysToThePlayedSamples) {
    eng::LiveEngine engine;
    engine.openOffline(settings());
    auto st = stimulus("dry_leaves");
    st.soundscape = "forest";
    const std::uint64_t seed = 31;
    const auto grfPath = (underfoot::test::scratchDir("wiring_live") / "leaves.wav").string();
    auto d = wir::describeStimulus(st, seed);
    d.grfRecorder = eng::makeGrfRecorder(grfPath, 2, 48000);
    auto recorder = d.grfRecorder;
    engine.submit(
        eng::LiveScene::create(std::move(d), engine.processSpec(), engine.settings().channels));
    std::vector<std::vector<float>> out(6, std::vector<float>(64)), played(2);
    std::vector<float*> op;
    for (auto& c : out) op.push_back(c.data());
    for (int b = 0; b < 2 * 48000 / 64; ++b) {
        engine.processBlock(nullptr, op.data(), 64);
        for (std::size_t c = 0; c < 2; ++c)
            played[c].insert(played[c].end(), out[c].begin(), out[c].end());
    }
    engine.close();
    recorder->finish();

    // What `underfoot replay` does (app/cli/cmd_replay.cpp), at the live block size.
    const auto grf = eng::loadGrfFile(grfPath);
    eng::RenderOptions ro;
    ro.blockSize = 64;
    ro.seed = seed;
    auto r = eng::renderSurface(st.surface, grf, ro);
    underfoot::soundscapes::SoundscapeRenderer ambience(
        underfoot::soundscapes::loadSoundscape("forest"));
    ambience.prepare({48000, 1024});
    ambience.reset(seed);
    const std::size_t n = r.audio.frames();
    ASSERT_EQ(n, played[0].size());
    std::vector<float> l(n), rr(n);
    ambience.process(l.data(), rr.data(), static_cast<int>(n));
    std::size_t mismatches = 0;
    double maxDiff = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const float g = eng::LiveScene::fadeGain(static_cast<std::int64_t>(i), 480);
        const float el = g * (r.audio.samples[2 * i] + l[i]);
        const float er = g * (r.audio.samples[2 * i + 1] + rr[i]);
        if (el != played[0][i] || er != played[1][i]) ++mismatches;
        maxDiff = std::max(
            {maxDiff, double(std::fabs(el - played[0][i])), double(std::fabs(er - played[1][i]))});
    }
    EXPECT_EQ(mismatches, 0u) << "largest difference " << maxDiff;
}

TEST(Wiring, WaterStimulusPlaysTheWadingNodeAndRecordsItsGait) {
    // surface "water": the wading node replaces control and voices; a walker input means the
    // virtual gait at the stimulus's wading cadence; gyroscopes need a receiver.
    xp::Stimulus water;
    water.id = "wade_deep";
    water.surface = "water";
    water.input.kind = xp::InputKind::Walker;
    water.wading["depth"] = std::string("deep");
    water.wading["algorithm"] = std::string("v2");
    water.wading["cadence"] = std::string("fast");
    auto scene = sceneOf(water);
    ASSERT_NE(scene->wading(), nullptr);
    EXPECT_EQ(scene->voiceCount(), 0);
    EXPECT_NE(scene->summary().find("virtual gait 118 steps/min"), std::string::npos)
        << scene->summary();
    xp::Stimulus gyro = water;
    gyro.input.kind = xp::InputKind::Sensor;
    gyro.input.sensor = xp::SensorKind::Gyro;
    EXPECT_THROW(sceneOf(gyro), std::invalid_argument);
    xp::Stimulus bad = water;
    bad.wading["depth"] = std::string("knee");
    EXPECT_THROW(sceneOf(bad), std::invalid_argument);

    eng::LiveEngine engine;
    engine.openOffline(settings());
    std::atomic<bool> running{true};
    std::atomic<float> peak{0.0f};
    std::thread audio([&] {
        std::vector<std::vector<float>> out(6, std::vector<float>(64));
        std::vector<float*> op;
        for (auto& c : out) op.push_back(c.data());
        while (running) {
            for (auto& c : out) std::fill(c.begin(), c.end(), 0.0f);
            engine.processBlock(nullptr, op.data(), 64);
            for (float v : out[0]) peak = std::max(peak.load(), std::fabs(v));
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    });
    const auto study = underfoot::test::scratchDir("wiring_live") / "water_study";
    wir::LivePlayerOptions o;
    o.studyFolder = study.string();
    o.recordingFolder = (study / "recordings").string();
    wir::LivePlayer player(engine, o);
    const auto start = player.start(water, 9);
    ASSERT_TRUE(start.grfRecording.has_value());
    EXPECT_EQ(fs::path(*start.grfRecording).extension(), ".csv") << *start.grfRecording;
    // 1.5 s of audio (the offline callback runs faster than real time).
    const auto frames0 = engine.meters().frames;
    for (int i = 0; i < 1000 && engine.meters().frames < frames0 + 72000; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    player.stop();
    running = false;
    audio.join();
    EXPECT_GT(peak.load(), 0.0f) << "the fast virtual gait splashes";
    const auto gait = eng::readGaitCsv((study / *start.grfRecording).string());
    EXPECT_GE(gait.size(), 140u);
    double swing = 0;
    for (const auto& f : gait) swing = std::max(swing, f[eng::Limb::LeftThigh]);
    EXPECT_GT(swing, 50.0) << "the recorded virtual gait swings";
    // Beside it, what reproduces the node exactly: the same frames with the samples
    // at which they took effect, and the live block size for the replay.
    const auto recording = (study / *start.grfRecording).string();
    const auto arrivals = eng::readGaitArrivals(recording + ".arrivals.csv");
    ASSERT_EQ(arrivals.frames.size(), gait.size());
    EXPECT_GE(arrivals.samples, 72000);
    for (std::size_t k = 0; k < gait.size(); ++k)
        EXPECT_NEAR(arrivals.frames[k].frame[eng::Limb::LeftThigh], gait[k][eng::Limb::LeftThigh],
                    1e-6)
            << k;
    EXPECT_TRUE(fs::exists(recording + ".meters.toml"));
}

// The `.meters.toml` side file the replay reads (parseLiveMeters, fuzzed by fuzz_live_meters):
// what LivePlayer writes gives the live rate and block size; a value the replay cannot use and
// bad syntax are a ReplayError naming the file, line and column (never the replay's defaults).
TEST(Wiring, MetersFileGivesTheLiveRateAndBlockSize) {
    const auto m = wir::parseLiveMeters("# Measured by the live engine\nscene = \"gravel\"\n"
                                        "sample_rate = 44100\nblock_size = 64\nframes = 11200\n",
                                        "grf.wav.meters.toml");
    ASSERT_TRUE(m.sampleRateHz && m.blockSize);
    EXPECT_EQ(*m.sampleRateHz, 44100.0);
    EXPECT_EQ(*m.blockSize, 64);
    // Out of range, not a number, or a float block size (1.8e91 was once cast to an integer
    // unchecked by toml++: undefined behaviour found by fuzz_live_meters,
    // regressions/live_meters/).
    for (const char* text :
         {"sample_rate = -1\n", "sample_rate = nan\n", "sample_rate = \"fast\"\n",
          "block_size = 70000\n", "block_size = 1.8e91\n", "block_size = 64.0\n"}) {
        try {
            (void)wir::parseLiveMeters(std::string("scene = \"x\"\n") + text,
                                       "grf.wav.meters.toml");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const wir::ReplayError& e) {
            EXPECT_NE(std::string(e.what()).find("grf.wav.meters.toml:2:"), std::string::npos)
                << e.what();
        }
    }
    const auto none = wir::parseLiveMeters("scene = \"gravel\"\n", "x");
    EXPECT_FALSE(none.sampleRateHz);
    EXPECT_FALSE(none.blockSize);
    try {
        (void)wir::parseLiveMeters("sample_rate = 48000\nblock_size = [\n", "grf.wav.meters.toml");
        FAIL() << "bad TOML was accepted";
    } catch (const wir::ReplayError& e) {
        EXPECT_NE(std::string(e.what()).find("grf.wav.meters.toml:"), std::string::npos)
            << e.what();
    }
}
