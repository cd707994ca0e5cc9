// SPDX-License-Identifier: GPL-3.0-or-later
// The live wading path through real components: a JACK server with the dummy driver (`jackd
// --no-realtime -d dummy -r 48000 -p 64 -C 4 -P 6`, a server name of its own) is the sound card,
// RtAudio's JACK API runs the LiveEngine, whose scene is the wading node (deep, v2) fed by an
// OscGyroReceiver on a free UDP port; liblo's lo_send to 127.0.0.1 plays the four gyroscopes at
// 100 Hz (one packet per limb per period). Standing still must be silent (malformed packets
// included); the latency is measured from the lo_send of the packet that starts a swing to the
// end of the first audio callback whose headphone output is not zero. Skipped only when jackd is
// not installed.
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/scene/LiveEngine.h"
#include "engine/scene/WadingNode.h"
#include "tests/common/AllocationTrap.h"
#include "tests/common/ScratchDir.h"
#include "tests/live/audio/JackDummyServer.h"

#include <gtest/gtest.h>
#include <lo/lo.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

namespace eng = underfoot::engine;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kPeriod = 64;
constexpr double kBlockMs = 1000.0 * kPeriod / 48000.0;

class WadingJack : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        server_ = new underfoot::test::JackDummyServer(
            "underfoot_wade", underfoot::test::scratchDir("live_wading") / "jackd.log", kPeriod);
        serverName_ = server_->name();
        ready_ = server_->ready();
    }
    static void TearDownTestSuite() {
        delete server_;
        server_ = nullptr;
    }
    void SetUp() override {
        if (!server_->installed()) GTEST_SKIP() << "jackd is not installed (Debian package jackd2)";
        ASSERT_TRUE(ready_) << "jackd (server " << serverName_ << ") did not come up within 10 s";
    }
    static eng::AudioSettings settings(const std::string& client) {
        eng::AudioSettings s;
        s.api = "jack";
        s.device = "system";
        s.sampleRateHz = 48000;
        s.blockSize = kPeriod;
        s.channels.headphonesLeft = 0;
        s.channels.headphonesRight = 1;
        s.clientName = client;
        s.portConnection = eng::AudioSettings::PortConnection::Manual;
        return s;
    }
    static underfoot::test::JackDummyServer* server_;
    static std::string serverName_;
    static bool ready_;
};

underfoot::test::JackDummyServer* WadingJack::server_ = nullptr;
std::string WadingJack::serverName_;
bool WadingJack::ready_ = false;

// --- what the callback hooks observe (audio thread; plain atomics, no allocation)
std::atomic<eng::LiveEngine*> watchedEngine{nullptr};
std::atomic<bool> armAllocations{false}, watchChange{false};
std::atomic<float> loudest{0.0f};
std::atomic<long long> firstChangeNs{-1};
std::atomic<std::uint64_t> firstChangeBlock{0};
std::atomic<long long> firstAudibleNs{-1}; ///< first block peaking above -60 dBFS

long long nowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
        .count();
}
// The trap is armed for the audio thread only: the OSC receiver's thread formats its status
// messages (and liblo allocates) meanwhile, legitimately.
void onEnter() {
    if (armAllocations.load(std::memory_order_relaxed)) underfoot::test::armThisThread(true);
}
void onLeave() {
    underfoot::test::armThisThread(false);
    eng::LiveEngine* e = watchedEngine.load(std::memory_order_acquire);
    if (!e) return;
    const auto m = e->meters(); // published by this very callback just before
    const float peak = std::max(m.outputPeak[0], m.outputPeak[1]);
    if (peak > loudest.load(std::memory_order_relaxed))
        loudest.store(peak, std::memory_order_relaxed);
    if (watchChange.load(std::memory_order_acquire) && peak > 0.0f &&
        firstChangeNs.load(std::memory_order_relaxed) < 0) {
        firstChangeBlock.store(m.blocks, std::memory_order_relaxed);
        firstChangeNs.store(nowNs(), std::memory_order_release);
    }
    if (watchChange.load(std::memory_order_acquire) && peak > 1e-3f &&
        firstAudibleNs.load(std::memory_order_relaxed) < 0)
        firstAudibleNs.store(nowNs(), std::memory_order_release);
}

/// Sends one 100 Hz period: a ,fi packet per limb (thighs first: the swing starts there).
void sendPeriod(lo_address to, float thighDps, float shankDps, int sequence) {
    static const char* paths[4] = {"/underfoot/gyro/left_thigh", "/underfoot/gyro/right_thigh",
                                   "/underfoot/gyro/left_shank", "/underfoot/gyro/right_shank"};
    for (int l = 0; l < 4; ++l) lo_send(to, paths[l], "fi", l < 2 ? thighDps : shankDps, sequence);
}

struct Trial {
    double latencyMs = -1;
    double audibleMs = -1; ///< to the first block above -60 dBFS (includes the control dynamics)
    long long blocks = -1;
    float standingPeak = -1;
    float swingPeak = 0;
    long allocations = -1;
    std::uint64_t malformed = 0;
    std::uint64_t framesRecorded = 0;
    std::uint64_t callbacks = 0;
    float quietPeak = -1;           ///< output peak 4.5-5 s after the gyroscopes went silent
    std::uint64_t silentFrames = 0; ///< standing frames the source made up meanwhile
};

/// One trial: a fresh receiver and wading scene; 1.5 s standing (malformed packets in the first
/// half), then a swing; with `armed`, the audio thread's allocations are counted throughout.
Trial runTrial(const eng::AudioSettings& s, bool armed, const std::string& gaitCsv = {},
               bool thenSilence = false) {
    Trial t;
    eng::LiveEngine engine;
    underfoot::test::openJackDevice(engine, s);
    engine.setCallbackHooks({&onEnter, &onLeave});
    eng::OscGyroConfig config;
    config.port = 0;
    auto receiver = std::make_shared<eng::OscGyroReceiver>(config);
    receiver->start();
    eng::WadingOptions options;
    options.depth = "deep";
    options.algorithm = "v2";
    options.seed = 5;
    eng::LiveSceneDescription d;
    d.wading = std::make_unique<eng::WadingNode>(
        options, std::make_unique<eng::LiveGyroGaitSource>(receiver));
    auto scene = eng::LiveScene::create(std::move(d), engine.processSpec(), s.channels);
    EXPECT_NE(scene->summary().find("osc gyroscopes"), std::string::npos) << scene->summary();
    EXPECT_FALSE(scene->hasNode(eng::SceneNode::Reverb));
    watchedEngine = &engine;
    engine.start();
    EXPECT_TRUE(engine.submit(std::move(scene)));

    const std::string port = std::to_string(receiver->port());
    lo_address to = lo_address_new("127.0.0.1", port.c_str());
    const int raw = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(receiver->port()));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);

    int seq = 0;
    auto next = Clock::now();
    auto tick = [&] {
        next += 10ms;
        std::this_thread::sleep_until(next);
    };
    underfoot::test::allocationCount = 0;
    armAllocations = armed;
    const auto blocksBefore = engine.meters().blocks;
    // Standing, with malformed packets: unknown limb, wrong type tags, NaN, garbage datagram.
    for (int k = 0; k < 50; ++k, tick()) {
        sendPeriod(to, 0.0f, 0.0f, seq++);
        if (k % 10 == 5) {
            lo_send(to, "/underfoot/gyro/left_knee", "f", 300.0f);
            lo_send(to, "/underfoot/gyro/left_thigh", "s", "fast");
            lo_send(to, "/underfoot/gyro/right_shank", "f", std::nanf(""));
            const char junk[] = "\x01\x02not osc at all";
            ::sendto(raw, junk, sizeof junk, 0, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
        }
    }
    // Standing (well-formed packets only); the loudest output is watched from here.
    loudest = 0.0f;
    firstChangeNs = -1;
    firstAudibleNs = -1;
    for (int k = 0; k < 100; ++k, tick()) sendPeriod(to, 0.0f, 0.0f, seq++);
    t.standingPeak = loudest.load();
    // The swing: thighs and shanks at 200 deg/s for 0.5 s.
    const auto blocksAtSend = engine.meters().blocks;
    watchChange = true;
    const long long sentNs = nowNs();
    sendPeriod(to, 200.0f, 200.0f, seq++);
    for (int k = 1; k < 50; ++k) {
        tick();
        sendPeriod(to, 200.0f, 200.0f, seq++);
    }
    const auto m = engine.meters();
    armAllocations = false;
    watchChange = false;
    t.callbacks = m.blocks - blocksBefore;
    t.allocations = underfoot::test::allocationCount.load();
    t.swingPeak = loudest.load();
    if (firstChangeNs.load() >= 0) {
        t.latencyMs = static_cast<double>(firstChangeNs.load() - sentNs) / 1e6;
        t.blocks = static_cast<long long>(firstChangeBlock.load() - blocksAtSend);
    }
    if (firstAudibleNs.load() >= 0)
        t.audibleMs = static_cast<double>(firstAudibleNs.load() - sentNs) / 1e6;
    if (thenSilence) { // the sender stops mid-swing (unplugged): the water must calm down
        std::this_thread::sleep_for(4500ms);
        loudest = 0.0f;
        std::this_thread::sleep_for(500ms);
        t.quietPeak = loudest.load();
    }
    engine.submit(nullptr);
    EXPECT_TRUE(engine.waitIdle(2.0));
    watchedEngine = nullptr;
    // The retired scene still holds the node and its gait recording.
    auto retired = engine.takeRetired();
    engine.close();
    receiver->stop();
    lo_address_free(to);
    ::close(raw);
    t.malformed = receiver->status().linesRejected;
    EXPECT_EQ(retired.size(), 1u);
    if (!retired.empty() && retired.front()->wading()) {
        const eng::WadingNode& node = *retired.front()->wading();
        t.framesRecorded = node.recordedFrames();
        EXPECT_EQ(node.unrecordedFrames(), 0u);
        if (const auto* live = dynamic_cast<const eng::LiveGyroGaitSource*>(&node.source()))
            t.silentFrames = live->silentFrames();
        if (!gaitCsv.empty()) node.writeRecording(gaitCsv);
    }
    return t;
}

} // namespace

TEST_F(WadingJack, SwingReachesTheHeadphonesWithinOneBlockOfItsPacket) {
    // The per-thread trap counts what its thread allocates, and only that thread.
    underfoot::test::allocationCount = 0;
    // (Direct calls of operator new: a new-expression may be elided by the optimiser.)
    std::thread other([] {
        underfoot::test::armThisThread(true);
        void* p = ::operator new(sizeof(int));
        underfoot::test::armThisThread(false);
        ::operator delete(p);
    });
    other.join();
    ::operator delete(::operator new(sizeof(int))); // this thread is not armed
    ASSERT_EQ(underfoot::test::allocationCount.load(), 1);

    const auto csv = (underfoot::test::scratchDir("live_wading") / "live_gait.csv").string();
    std::vector<Trial> trials;
    for (int k = 0; k < 3; ++k)
        trials.push_back(
            runTrial(settings("uf_wade"), k == 0, k == 0 ? csv : std::string(), k == 1));
    std::vector<double> latencies;
    for (const auto& t : trials) {
        std::printf(
            "[ wading   ] standing peak %.3g, swing peak %.3g, malformed %llu, packet -> "
            "first changed block %.2f ms (%lld callbacks later; block %.2f ms), first block > "
            "-60 dBFS %.1f ms\n",
            static_cast<double>(t.standingPeak), static_cast<double>(t.swingPeak),
            static_cast<unsigned long long>(t.malformed), t.latencyMs, t.blocks, kBlockMs,
            t.audibleMs);
        EXPECT_EQ(t.standingPeak, 0.0f) << "standing still must be silent";
        EXPECT_GT(t.swingPeak, 0.0f);
        EXPECT_GE(t.malformed, 20u) << "the receiver saw the malformed packets";
        ASSERT_GE(t.latencyMs, 0.0) << "no output block changed after the swing packet";
        latencies.push_back(t.latencyMs);
    }
    std::sort(latencies.begin(), latencies.end());
    const double median = latencies[latencies.size() / 2];
    std::printf("[ wading   ] packet -> sound, median of 3: %.2f ms = %.2f blocks of %d frames; "
                "target <= sensor period 10 ms + 1 block = %.2f ms\n",
                median, median / kBlockMs, kPeriod, 10.0 + kBlockMs);
    EXPECT_LE(median, 10.0 + kBlockMs);
    std::printf("[ wading   ] armed trial: %llu callbacks, %ld allocations\n",
                static_cast<unsigned long long>(trials[0].callbacks), trials[0].allocations);
    EXPECT_GT(trials[0].callbacks, 500u);
    EXPECT_EQ(trials[0].allocations, 0);

    // Trial 2 stopped sending mid-swing: after 100 ms of silence the source stands still (zero
    // frames every 10 ms) and the water calms (the v2 releases are 0.89 / 2.23 s); holding the
    // last swing would keep the swing's level.
    std::printf("[ wading   ] gyroscopes silent after the swing: %llu standing frames made up, "
                "output peak 4.5-5 s later %.3g (swing %.3g)\n",
                static_cast<unsigned long long>(trials[1].silentFrames),
                static_cast<double>(trials[1].quietPeak), static_cast<double>(trials[1].swingPeak));
    EXPECT_GE(trials[1].silentFrames, 100u)
        << "at least 1 s of audio (the dummy driver skips cycles under load)";
    EXPECT_LT(trials[1].quietPeak, 0.1f * trials[1].swingPeak);

    // The trial's gait frames were recorded: ~2 s at 100 Hz (the assembler makes one frame per
    // period), standing then swinging, and the CSV reads back for `underfoot wade --gait`.
    EXPECT_GE(trials[0].framesRecorded, 150u);
    const auto gait = eng::readGaitCsv(csv);
    ASSERT_GE(gait.size(), 150u);
    EXPECT_EQ(gait.front()[eng::Limb::LeftThigh], 0.0);
    EXPECT_EQ(gait.back()[eng::Limb::LeftThigh], 200.0);
    EXPECT_EQ(gait.back()[eng::Limb::RightShank], 200.0);
    eng::WadingOptions o;
    o.depth = "deep";
    o.seed = 5;
    const auto replay = eng::renderWading(o, gait);
    float peak = 0;
    for (float v : replay.samples) peak = std::max(peak, std::fabs(v));
    EXPECT_GT(peak, 0.0f) << "the recorded gait re-renders the swing";
}

namespace {
/// Runs a water scene (virtual gait) offline for `seconds` at 48 kHz / 64 frames; returns the
/// six device outputs (0/1 headphones, 2-5 actuators).
std::vector<std::vector<float>> runVirtualWater(double cadence, double seconds,
                                                eng::OutputModality modality) {
    eng::ChannelMap map;
    map.headphonesLeft = 0;
    map.headphonesRight = 1;
    map.haptic[0] = {2, 3};
    map.haptic[1] = {4, 5};
    eng::WadingOptions o;
    o.depth = "deep";
    o.seed = 3;
    eng::VirtualGaitParameters p;
    p.cadenceStepsPerMin = cadence;
    eng::LiveSceneDescription d;
    d.modality = modality;
    d.seed = 3;
    d.wading = std::make_unique<eng::WadingNode>(
        o, std::make_unique<eng::VirtualGaitSource>(p, seconds + 1.0));
    auto scene = eng::LiveScene::create(std::move(d), {48000, 64}, map);
    const auto frames = static_cast<std::size_t>(seconds * 48000);
    std::vector<std::vector<float>> out(6, std::vector<float>(frames, 0.0f));
    std::vector<float*> ptr(6);
    for (std::size_t pos = 0; pos + 64 <= frames; pos += 64) {
        for (std::size_t c = 0; c < 6; ++c) ptr[c] = out[c].data() + pos;
        scene->process(nullptr, 0, ptr.data(), 6, 64);
    }
    return out;
}
double rms(const std::vector<float>& x) {
    double s = 0;
    for (float v : x) s += double(v) * v;
    return std::sqrt(s / double(x.size()));
}
} // namespace

TEST(LiveWading, VirtualGaitStandsSilentWalksLouderWhenFasterAndDrivesTheShoes) {
    // Standing (cadence 0): every output sample exactly 0.
    const auto still = runVirtualWater(0, 2.0, eng::OutputModality::AudioHaptic);
    for (const auto& ch : still)
        for (float v : ch) ASSERT_EQ(v, 0.0f);
    // The virtual gait is audible, and faster walking (118 steps/min) is louder than slow (27),
    // as offline (docs/explanation/wading.md, measured figures).
    const auto slow = runVirtualWater(27, 6.0, eng::OutputModality::Audio);
    const auto fast = runVirtualWater(118, 6.0, eng::OutputModality::Audio);
    const double slowRms = rms(slow[0]) + rms(slow[1]), fastRms = rms(fast[0]) + rms(fast[1]);
    std::printf("[ wading   ] live scene, virtual gait: headphone RMS (L+R) slow %.4g, fast %.4g\n",
                slowRms, fastRms);
    EXPECT_GT(slowRms, 0.0);
    EXPECT_GT(fastRms, 1.5 * slowRms);
    EXPECT_EQ(rms(fast[2]), 0.0) << "audio-only: the actuators stay silent";
    // With haptics, the left/right outputs drive the left/right shoe (heel and toe).
    const auto both = runVirtualWater(118, 3.0, eng::OutputModality::AudioHaptic);
    for (int c = 2; c < 6; ++c) EXPECT_GT(rms(both[static_cast<std::size_t>(c)]), 0.0) << c;
    EXPECT_EQ(both[2], both[3]) << "heel and toe of one shoe carry the same band";
}
