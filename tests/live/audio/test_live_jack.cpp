// SPDX-License-Identifier: GPL-3.0-or-later
// The full live path through a real sound server: a JACK server with the dummy driver
// (`jackd --no-realtime -d dummy -r 48000 -p 64 -C 4 -P 6`) under a server name of its own
// stands in for the sound card; RtAudio's JACK API opens it as the device "system" (4 in, 6
// out). Skipped (with the reason) only when jackd is not installed.
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "engine/scene/LiveEngine.h"
#include "tests/common/AllocationTrap.h"
#include "tests/common/ScratchDir.h"
#include "tests/live/audio/JackDummyServer.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace eng = underfoot::engine;
using namespace std::chrono_literals;

namespace {

constexpr int kPeriod = 64;

using underfoot::test::findProgram;

int run(const std::vector<std::string>& args, std::string* output = nullptr) {
    return underfoot::test::runProgram(args, output);
}

class JackServer : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        server_ = new underfoot::test::JackDummyServer(
            "underfoot_test", underfoot::test::scratchDir("live_jack") / "jackd.log", kPeriod);
        serverName_ = server_->name();
        ready_ = server_->ready();
    }
    static void TearDownTestSuite() {
        delete server_;
        server_ = nullptr;
    }
    void SetUp() override {
        if (!server_->installed()) GTEST_SKIP() << "jackd is not installed (Debian package jackd2)";
        ASSERT_TRUE(ready_) << "jackd (server " << serverName_
                            << ") did not come up within 10 s; see its log in the scratch dir";
    }

    static eng::AudioSettings settings(const std::string& client) {
        eng::AudioSettings s;
        s.api = "jack";
        s.device = "system";
        s.sampleRateHz = 48000;
        s.blockSize = kPeriod;
        s.channels.headphonesLeft = 0;
        s.channels.headphonesRight = 1;
        s.channels.haptic[0] = {2, 3};
        s.channels.haptic[1] = {4, 5};
        s.channels.microphones = {0, 1, 2, 3};
        s.clientName = client;
        s.portConnection = eng::AudioSettings::PortConnection::Manual;
        return s;
    }

    static void openSystem(eng::LiveEngine& engine, const std::string& client) {
        underfoot::test::openJackDevice(engine, settings(client));
    }

    static underfoot::test::JackDummyServer* server_;
    static std::string serverName_;
    static bool ready_;
};

underfoot::test::JackDummyServer* JackServer::server_ = nullptr;
std::string JackServer::serverName_;
bool JackServer::ready_ = false;

/// Waits until the engine has processed `frames` more frames (the dummy driver drops cycles
/// when the machine is loaded, so wall time is not audio time); false after `timeout`.
bool waitFrames(const eng::LiveEngine& e, std::uint64_t frames,
                std::chrono::seconds timeout = std::chrono::seconds(30)) {
    const auto start = e.meters().frames;
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (e.meters().frames < start + frames) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(20ms);
    }
    return true;
}

std::unique_ptr<eng::LiveScene> heaviestScene(const eng::LiveEngine& e, std::uint64_t seed) {
    eng::LiveSceneDescription d;
    d.surface = "creaking_wood";
    d.impulseResponse = "hall";
    d.modality = eng::OutputModality::AudioHaptic;
    d.seed = seed;
    return eng::LiveScene::create(std::move(d), e.processSpec(), e.settings().channels);
}

} // namespace

TEST_F(JackServer, ListsTheDummyDriverAsADevice) {
    const auto devices = eng::listAudioDevices("jack");
    bool found = false;
    for (const auto& d : devices)
        if (d.name == "system") {
            found = true;
            EXPECT_EQ(d.api, "jack");
            EXPECT_EQ(d.inputChannels, 4);
            EXPECT_EQ(d.outputChannels, 6);
            EXPECT_NE(std::find(d.sampleRatesHz.begin(), d.sampleRatesHz.end(), 48000),
                      d.sampleRatesHz.end());
        }
    EXPECT_TRUE(found) << "no JACK device named system";
}

TEST_F(JackServer, UnknownDeviceAndTooManyChannelsAreClearErrors) {
    eng::LiveEngine engine;
    auto s = settings("uf_err");
    s.device = "no_such_card";
    try {
        engine.open(s);
        FAIL() << "opened an unknown device";
    } catch (const eng::AudioSettingsError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("\"no_such_card\" not found"), std::string::npos) << msg;
        EXPECT_NE(msg.find("\"system\" (4 in, 6 out)"), std::string::npos) << msg;
    }
    s = settings("uf_err");
    s.channels.haptic[1].toe = 7; // the dummy card has 6 outputs
    try {
        engine.open(s);
        FAIL() << "opened 8 outputs on a 6-output device";
    } catch (const eng::AudioSettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("has 6 output channels"), std::string::npos)
            << e.what();
    }
}

TEST_F(JackServer, RunsTheHeaviestSceneAndPublishesMeters) {
    eng::LiveEngine engine;
    openSystem(engine, "uf_run");
    EXPECT_EQ(engine.openedApi(), "jack");
    EXPECT_EQ(engine.settings().blockSize, kPeriod);
    EXPECT_EQ(engine.outputChannels(), 6);
    EXPECT_EQ(engine.inputChannels(), 4);
    engine.start();
    ASSERT_TRUE(engine.submit(heaviestScene(engine, 7)));
    EXPECT_TRUE(waitFrames(engine, 48000u * 3)) << "3 s of audio within 30 s";
    const auto m = engine.meters();
    engine.stop();
    EXPECT_GE(m.frames, 48000u * 3);
    EXPECT_GT(m.outputPeak[0] + m.outputPeak[1], 0.0f) << "headphones silent?";
    EXPECT_GT(m.averageLoadPercent, 0.0);
    EXPECT_GT(m.maxBlockSeconds, 0.0);
    std::printf(
        "[ jack     ] heaviest scene, 3 s of audio: %llu blocks, %llu xruns, load avg %.1f %% "
        "max %.1f %%, worst block %.3f ms\n",
        static_cast<unsigned long long>(m.blocks), static_cast<unsigned long long>(m.xruns),
        m.averageLoadPercent, m.maxLoadPercent, m.maxBlockSeconds * 1e3);
    engine.close();
}

TEST_F(JackServer, LoopbackLatencyIsOneBlock) {
    eng::LiveEngine engine;
    openSystem(engine, "uf_loop");
    engine.start();
    // Our first output into our first input.
    std::string out;
    ASSERT_EQ(run({findProgram("jack_connect"), "uf_loop:outport 0", "uf_loop:inport 0"}, &out), 0)
        << out;
    std::this_thread::sleep_for(200ms);
    std::vector<long long> measured;
    for (int k = 0; k < 5; ++k) {
        ASSERT_TRUE(engine.probeLatency(0, 0));
        long long v = -1;
        for (int i = 0; i < 200 && v < 0; ++i) {
            std::this_thread::sleep_for(10ms);
            v = engine.meters().probeLatencyFrames;
        }
        measured.push_back(v);
    }
    engine.close();
    std::printf("[ jack     ] loopback output 1 -> input 1 latency (frames):");
    for (auto v : measured) std::printf(" %lld", v);
    std::printf("  (period %d)\n", kPeriod);
    for (auto v : measured)
        EXPECT_EQ(v, kPeriod) << "JACK hands a client's output to a connected input one period "
                                 "later; anything more is latency we added";
}

namespace {
std::atomic<bool> trapArmed{false};
std::atomic<std::uint64_t> armedCallbacks{0};
void armTrap() {
    if (trapArmed.load(std::memory_order_relaxed)) armedCallbacks.fetch_add(1);
    if (trapArmed.load(std::memory_order_relaxed))
        underfoot::test::countAllocations.store(true, std::memory_order_relaxed);
}
void disarmTrap() {
    underfoot::test::countAllocations.store(false, std::memory_order_relaxed);
}
} // namespace

TEST_F(JackServer, CallbackDoesNotAllocateAcrossSwapsAndMeterReads) {
    eng::LiveEngine engine;
    openSystem(engine, "uf_alloc");
    engine.setCallbackHooks({&armTrap, &disarmTrap});
    // The hooks really arm the counter: an allocation between them is counted (checked before
    // the stream runs, so that no callback disarms it meanwhile).
    underfoot::test::allocationCount = 0;
    trapArmed = true;
    armTrap();
    auto probe = std::make_unique<int>(1);
    disarmTrap();
    volatile int sink = *probe; // keep the allocation observable
    (void)sink;
    trapArmed = false;
    ASSERT_EQ(underfoot::test::allocationCount.load(), 1) << "the trap must see an allocation";
    engine.start();
    std::vector<std::unique_ptr<eng::LiveScene>> scenes;
    for (int k = 0; k < 8; ++k) {
        if (k % 2 == 0) {
            scenes.push_back(heaviestScene(engine, static_cast<std::uint64_t>(k)));
        } else {
            eng::LiveSceneDescription d;
            d.surface = k % 4 == 1 ? "gravel" : "wood";
            d.control = k == 3 ? eng::ControlKind::Microphones : eng::ControlKind::Walker;
            d.seed = static_cast<std::uint64_t>(k);
            scenes.push_back(eng::LiveScene::create(std::move(d), engine.processSpec(),
                                                    engine.settings().channels));
        }
    }
    // Counts only while the callback runs (the hooks arm and disarm the counter); the main
    // thread meanwhile only submits pre-built scenes, reads meters and frees retired scenes.
    underfoot::test::allocationCount = 0;
    armedCallbacks = 0;
    trapArmed = true;
    const auto blocksBefore = engine.meters().blocks;
    for (auto& s : scenes) {
        ASSERT_TRUE(engine.submit(std::move(s)));
        // A quarter second of audio per scene (the crossfade is 10 ms), reading the meters
        // as a GUI does.
        const auto target = engine.meters().frames + 12000;
        const auto deadline = std::chrono::steady_clock::now() + 10s;
        while (engine.meters().frames < target && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(10ms);
    }
    engine.submit(nullptr);
    EXPECT_TRUE(engine.waitIdle(2.0));
    trapArmed = false;
    const auto m = engine.meters();
    const auto armed = armedCallbacks.load();
    engine.close();
    const long allocations = underfoot::test::allocationCount.load();
    const auto blocks = m.blocks - blocksBefore;
    std::printf("[ jack     ] %llu callbacks, 8 swaps + fade-out, %ld allocations, %llu xruns\n",
                static_cast<unsigned long long>(blocks), allocations,
                static_cast<unsigned long long>(m.xruns));
    EXPECT_GT(blocks, 1000u);
    EXPECT_GT(armed, blocks * 9 / 10) << "the callbacks ran inside the armed hooks";
    EXPECT_EQ(m.scenesSwapped, 8u);
    EXPECT_EQ(m.scenesRetired, 8u);
    EXPECT_EQ(allocations, 0);
}

TEST_F(JackServer, RecordedLiveTrialReplaysToWhatWasPlayed) {
    eng::LiveEngine engine;
    openSystem(engine, "uf_rec");
    const auto dir = underfoot::test::scratchDir("live_jack");
    const auto grfPath = (dir / "trial_grf.wav").string();
    const auto outPath = (dir / "trial_out.wav").string();
    eng::LiveSceneDescription d;
    d.surface = "metal";
    d.seed = 99;
    d.grfRecorder = eng::makeGrfRecorder(grfPath, 2, 48000);
    d.outputRecorder = std::make_shared<eng::AudioRecorder>(outPath, 2, 48000);
    auto grfRec = d.grfRecorder;
    auto outRec = d.outputRecorder;
    engine.start();
    ASSERT_TRUE(engine.submit(
        eng::LiveScene::create(std::move(d), engine.processSpec(), engine.settings().channels)));
    ASSERT_TRUE(waitFrames(engine, 48000u * 5 / 2)) << "2.5 s of audio within 30 s";
    engine.submit(nullptr);
    ASSERT_TRUE(engine.waitIdle(2.0));
    engine.close();
    grfRec->finish();
    outRec->finish();
    EXPECT_EQ(grfRec->droppedFrames(), 0u);
    ASSERT_GE(grfRec->writtenFrames(), 48000u * 5 / 2);

    // The recording holds the fade-in at the start and the fade-out at the end; the replay
    // applies the fade-in identically and is compared up to where the fade-out began
    // (the output recording's last crossfade_ms).
    const auto grf = eng::loadGrfFile(grfPath);
    const auto played = eng::readAudioFile(outPath);
    eng::RenderOptions o;
    o.blockSize = kPeriod;
    o.seed = 99;
    const auto replay = eng::renderSurface("metal", grf, o);
    ASSERT_EQ(replay.audio.frames(), played.frames());
    const int fade = 480;
    const std::size_t compare =
        played.frames() - static_cast<std::size_t>((fade + kPeriod - 1) / kPeriod * kPeriod);
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < compare; ++i)
        for (int c = 0; c < 2; ++c)
            if (eng::LiveScene::fadeGain(static_cast<std::int64_t>(i), fade) *
                    replay.audio.at(i, c) !=
                played.at(i, c))
                ++mismatches;
    EXPECT_EQ(mismatches, 0u) << "of " << compare << " frames";
}
