// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/AudioFile.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>

using namespace underfoot;
using namespace underfoot::soundscapes;

namespace {

constexpr double kFs = 48000.0;

struct Stereo {
    std::vector<float> left, right;
    double levelDb() const {
        double p = 0;
        for (std::size_t i = 0; i < left.size(); ++i)
            p += 0.5 * (static_cast<double>(left[i]) * left[i] +
                        static_cast<double>(right[i]) * right[i]);
        return 10 * std::log10(p / static_cast<double>(left.size()) + 1e-30);
    }
    double peak() const {
        double m = 0;
        for (std::size_t i = 0; i < left.size(); ++i)
            m = std::max({m, std::fabs(static_cast<double>(left[i])),
                          std::fabs(static_cast<double>(right[i]))});
        return m;
    }
    bool finite() const {
        for (std::size_t i = 0; i < left.size(); ++i)
            if (!std::isfinite(left[i]) || !std::isfinite(right[i])) return false;
        return true;
    }
};

Stereo render(SoundscapeRenderer& r, double seconds, int block) {
    const auto n = static_cast<std::size_t>(seconds * kFs);
    Stereo s{std::vector<float>(n), std::vector<float>(n)};
    for (std::size_t done = 0; done < n;) {
        const int m =
            static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(block), n - done));
        r.process(s.left.data() + done, s.right.data() + done, m);
        done += static_cast<std::size_t>(m);
    }
    return s;
}

const std::vector<std::string> kIds = {"beach_summer", "farm_courtyard", "ski_slope", "forest",
                                       "park_fall"};

const char* kHead = "[soundscape]\nid = \"t\"\nname = \"T\"\ntarget_level_dbfs = -30.0\n";

// A renderer of that definition, prepared at 48 kHz for blocks of that size.
std::unique_ptr<SoundscapeRenderer> prepared(SoundscapeDefinition def, int block = 512) {
    auto r = std::make_unique<SoundscapeRenderer>(std::move(def));
    r->prepare({kFs, block});
    return r;
}

// A test soundscape: the common head, then these layers.
SoundscapeDefinition withLayers(const std::string& layers) {
    return parseSoundscapeDefinition(std::string(kHead) + layers, "t.toml");
}

// One event layer of metal clanks (about 1 s each) at that mean interval and jitter, then `more`.
std::string clanks(double meanIntervalS, double jitter, const std::string& more = "") {
    return "[[event]]\nname = \"k\"\ngenerator = \"clank\"\nmean_interval_s = " +
           std::to_string(meanIntervalS) + "\njitter = " + std::to_string(jitter) + "\n" + more;
}

// The five shipped environments, each prepared once (preparation includes calibration).
SoundscapeRenderer& shipped(const std::string& id) {
    static std::map<std::string, std::unique_ptr<SoundscapeRenderer>> cache;
    auto& r = cache[id];
    if (!r) r = prepared(loadSoundscape(id));
    return *r;
}

std::filesystem::path tempDir() {
    auto dir = std::filesystem::temp_directory_path() /
               ("underfoot_soundscapes_" +
                std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir);
    return dir;
}

void writeSine(const std::filesystem::path& path, double rate, double freq, double seconds,
               double amplitude, int channels = 1) {
    engine::AudioBuffer b;
    b.sampleRateHz = rate;
    b.channels = channels;
    const auto n = static_cast<std::size_t>(seconds * rate);
    b.samples.resize(n * static_cast<std::size_t>(channels));
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < channels; ++c)
            b.samples[i * channels + c] = static_cast<float>(
                amplitude * std::sin(2 * M_PI * freq * static_cast<double>(i) / rate));
    engine::writeAudioFile(path.string(), b, engine::SampleFormat::Float32);
}

} // namespace

TEST(SoundscapeRenderer, EveryEnvironmentIsDeterministicFiniteAndAtItsTargetLevel) {
    for (const auto& id : kIds) {
        SCOPED_TRACE(id);
        auto& r = shipped(id);
        r.reset(1);
        const Stereo a = render(r, 60.0, 512);
        ASSERT_TRUE(a.finite());
        // Calibrated to the definition's target (mean channel power of the mix); the tolerance
        // covers the randomness of a one-minute render (measured spread: see
        // docs/reference/soundscapes.md).
        EXPECT_NEAR(a.levelDb(), r.definition().targetLevelDbfs, 2.0);
        EXPECT_LT(a.peak(), 0.9) << "headroom below full scale";
        r.reset(1);
        const Stereo b = render(r, 5.0, 512);
        EXPECT_TRUE(std::equal(b.left.begin(), b.left.end(), a.left.begin()));
        EXPECT_TRUE(std::equal(b.right.begin(), b.right.end(), a.right.begin()));
        r.reset(2);
        const Stereo c = render(r, 5.0, 512);
        EXPECT_FALSE(std::equal(c.left.begin(), c.left.end(), a.left.begin()));
    }
}

// FNV-1a over the float bit patterns of both channels.
std::uint64_t samplesHash(const Stereo& s) {
    std::uint64_t h = 14695981039346656037ull;
    for (const auto* channel : {&s.left, &s.right})
        for (const float x : *channel) {
            std::uint32_t bits = 0;
            std::memcpy(&bits, &x, sizeof bits);
            for (int b = 0; b < 4; ++b) {
                h ^= (bits >> (8 * b)) & 0xffu;
                h *= 1099511628211ull;
            }
        }
    return h;
}

// A stored seed replays what a participant heard, whichever compiler built the program: the
// mix (bed and event scheduling included) is pinned, not only each generator
// (test_generators.cpp). Values rendered by the GCC build and equal in the Clang (sanitizer)
// build; a change of sound updates them in the same commit and says so
// (docs/decisions/soundscape-samples-pinned.md).
TEST(SoundscapeRenderer, EveryEnvironmentReplaysTheSameSamplesInEveryBuild) {
    const std::map<std::string, std::uint64_t> pinned{{"beach_summer", 0x69c9f53be9f8a0c8ull},
                                                      {"farm_courtyard", 0x373abd9f574a0b58ull},
                                                      {"ski_slope", 0xf6a0c54a0409322aull},
                                                      {"forest", 0x8578b9e6f7b6f24cull},
                                                      {"park_fall", 0xaa1b9dfbf7d7aadull}};
    for (const auto& id : kIds) {
        auto& r = shipped(id);
        r.reset(1);
        const std::uint64_t h = samplesHash(render(r, 8.0, 512));
        EXPECT_EQ(h, pinned.at(id)) << id << " rendered 0x" << std::hex << h << "ull";
    }
}

TEST(SoundscapeRenderer, EveryEnvironmentSpeaksWithinTheFirstSeconds) {
    // Recognisable at once: the beds play from the first block and some characteristic event
    // (gull, hen, swish, bird...) starts within 2 s.
    for (const auto& id : kIds) {
        SCOPED_TRACE(id);
        auto& r = shipped(id);
        r.reset(7);
        const Stereo s = render(r, 2.0, 512);
        std::uint64_t events = 0;
        for (std::size_t i = 0; i < r.layerCount(); ++i) events += r.layerStats(i).eventsStarted;
        EXPECT_GE(events, 1u);
        Stereo first{std::vector<float>(s.left.begin(), s.left.begin() + 4800),
                     std::vector<float>(s.right.begin(), s.right.begin() + 4800)};
        EXPECT_GT(first.levelDb(), r.definition().targetLevelDbfs - 20.0) << "audible at once";
    }
}

TEST(SoundscapeRenderer, OutputDoesNotDependOnTheBlockSize) {
    auto small = prepared(loadSoundscape("forest"), 37);
    auto& big = shipped("forest");
    small->reset(3);
    big.reset(3);
    const Stereo a = render(*small, 10.0, 37), b = render(big, 10.0, 512);
    EXPECT_TRUE(a.left == b.left && a.right == b.right);
}

TEST(SoundscapeRenderer, ShippedEventLayersOccurAtTheirDeclaredRates) {
    // Over 4 minutes each Poisson layer's onset count (started + dropped) must fall within
    // 4.5 standard deviations of its expectation 1 + rate * (T - first onset) (a first onset
    // window forces the first event; the rest are Poisson, variance = mean).
    const double seconds = 240.0;
    for (const auto& id : kIds) {
        auto& r = shipped(id);
        r.reset(11);
        render(r, seconds, 4096);
        for (std::size_t i = 0; i < r.layerCount(); ++i) {
            const auto& l = r.definition().layers[i];
            if (l.kind != LayerKind::Event) continue;
            SCOPED_TRACE(id + "/" + l.name);
            const auto& s = r.layerStats(i);
            const double count = static_cast<double>(s.eventsStarted + s.eventsDropped);
            const double rate = l.ratePerMinute / 60.0;
            const double first =
                l.firstOnsetSeconds
                    ? 0.5 * (l.firstOnsetSeconds->first + l.firstOnsetSeconds->second)
                    : 0.0;
            const double expected = (l.firstOnsetSeconds ? 1.0 : 0.0) + rate * (seconds - first);
            // A less-than-Poisson jitter gives a smaller variance; the Poisson bound is safe.
            EXPECT_NEAR(count, expected, 4.5 * std::sqrt(expected) + 1.0);
            EXPECT_LE(static_cast<double>(s.eventsDropped), 0.1 * count + 1.0) << "voices suffice";
        }
    }
}

TEST(SoundscapeRenderer, MeasuredOnsetsInTheAudioMatchTheDeclaredDensity) {
    // Isolated metal clanks (about 1 s long) every 4 s on average with 30 % jitter, so that they
    // never overlap: count the onsets in the audio itself (10 ms energy frames crossing a
    // threshold from below, with 0.6 s refractory time) and compare with the declaration.
    const auto r = prepared(withLayers(clanks(4.0, 0.3)), 256);
    r->reset(5);
    const double seconds = 400.0;
    const Stereo s = render(*r, seconds, 256);
    const int frame = 480;
    double peakEnergy = 0;
    std::vector<double> e;
    for (std::size_t i = 0; i + frame <= s.left.size(); i += frame) {
        double x = 0;
        for (int k = 0; k < frame; ++k) x += static_cast<double>(s.left[i + k]) * s.left[i + k];
        e.push_back(x);
        peakEnergy = std::max(peakEnergy, x);
    }
    int onsets = 0;
    std::size_t last = 0;
    for (std::size_t k = 1; k < e.size(); ++k)
        if (e[k] > 1e-3 * peakEnergy && e[k - 1] <= 1e-3 * peakEnergy &&
            (onsets == 0 || k - last > 60)) {
            ++onsets;
            last = k;
        }
    // Intervals 4 s * (0.7 + 0.3 Exp(1)): mean 4 s, sd 1.2 s; over 400 s the count has a standard
    // deviation of about sqrt(100) * 1.2 / 4 = 3 (renewal CLT). Allow 4 sd.
    EXPECT_NEAR(onsets, seconds / 4.0, 12.0);
    EXPECT_EQ(static_cast<std::uint64_t>(onsets), r->layerStats(0).eventsStarted)
        << "every scheduled event is heard, and nothing else";
}

TEST(SoundscapeRenderer, RegularEventsKeepTheirInterval) {
    const auto r = prepared(withLayers(clanks(2.5, 0.0, "first_onset_s = [0.5, 0.5]\n")));
    r->reset(1);
    render(*r, 100.2, 512);
    EXPECT_EQ(r->layerStats(0).eventsStarted, 40u); // onsets at 0.5, 3.0, ..., 98.0
}

TEST(SoundscapeRenderer, OnlyTheDeclaredLayersAreComputed) {
    const auto r = prepared(withLayers(R"(
[[bed]]
name = "wind"
generator = "wind"
[[bed]]
name = "sea"
generator = "sea"
enabled = false
[[event]]
name = "late"
generator = "cow"
rate_per_minute = 1
first_onset_s = [100, 100]
)"));
    EXPECT_EQ(r->layerCount(), 2u);
    r->reset(1);
    render(*r, 10.0, 512);
    EXPECT_EQ(r->layerStats(0).framesComputed, 480000u);
    EXPECT_EQ(r->layerStats(1).framesComputed, 0u)
        << "an event layer with nothing sounding is free";
    EXPECT_EQ(r->layerStats(1).eventsStarted, 0u);
}

TEST(SoundscapeRenderer, RecordedBedsLoopSeamlesslyAtTheTargetLevelAfterResampling) {
    const auto dir = tempDir();
    writeSine(dir / "tone.wav", 44100.0, 441.0, 3.0, 0.5); // resampled to 48 kHz at prepare
    auto def = loadSoundscapeDefinition([&] {
        const auto p = dir / "d.toml";
        std::ofstream(p) << kHead
                         << "[[bed]]\nname = \"tone\"\nfile = \"tone.wav\"\ncrossfade_s = 0.5\n";
        return p.string();
    }());
    const auto r = prepared(def);
    r->reset(1);
    const Stereo s = render(*r, 10.0, 512); // about four loops of 2.5 s
    EXPECT_NEAR(s.levelDb(), -30.0, 0.2);
    // Frequency kept (zero crossings) and no click at the loop points: no step larger than the
    // largest step of the tone itself (2 pi f / fs times its peak).
    int crossings = 0;
    double maxStep = 0;
    for (std::size_t i = 1; i < s.left.size(); ++i) {
        if ((s.left[i - 1] < 0) != (s.left[i] < 0)) ++crossings;
        maxStep = std::max(maxStep, std::fabs(static_cast<double>(s.left[i] - s.left[i - 1])));
    }
    EXPECT_NEAR(crossings / 2.0 / 10.0, 441.0, 3.0);
    EXPECT_LT(maxStep, 2 * M_PI * 441.0 / kFs * s.peak() * 1.05);
    std::filesystem::remove_all(dir);
}

TEST(SoundscapeRenderer, RecordedEventsPlayTheirClips) {
    const auto dir = tempDir();
    writeSine(dir / "a.wav", 22050.0, 1000.0, 0.2, 0.8, 2);
    writeSine(dir / "b.flac.wav", 96000.0, 2000.0, 0.3, 0.8);
    std::ofstream(dir / "d.toml")
        << kHead
        << "[[event]]\nname = \"e\"\nfiles = [\"a.wav\", \"b.flac.wav\"]\n"
           "rate_per_minute = 30\n";
    const auto r = prepared(loadSoundscapeDefinition((dir / "d.toml").string()));
    r->reset(2);
    const Stereo s = render(*r, 120.0, 512);
    const auto& st = r->layerStats(0);
    EXPECT_NEAR(static_cast<double>(st.eventsStarted), 60.0, 4.5 * std::sqrt(60.0));
    // Every started clip was played to its end (0.2 s or 0.3 s at 48 kHz).
    EXPECT_GE(st.framesComputed, st.eventsStarted * 9600u - 14400u);
    EXPECT_LE(st.framesComputed, st.eventsStarted * 14400u);
    EXPECT_NEAR(s.levelDb(), -30.0, 2.5);
    std::filesystem::remove_all(dir);
}

TEST(SoundscapeRenderer, MissingOrCorruptRecordingsFailAtLoadTimeWithAClearMessage) {
    const auto dir = tempDir();
    { std::ofstream(dir / "corrupt.wav") << "RIFF this is not a wave file at all"; }
    writeSine(dir / "silent.wav", 48000.0, 0.0, 1.0, 0.0);
    auto expectError = [&](const std::string& layer, const std::string& fragment) {
        std::ofstream(dir / "d.toml") << kHead << layer;
        const auto def = loadSoundscapeDefinition((dir / "d.toml").string());
        try {
            SoundscapeRenderer r(def);
            ADD_FAILURE() << "no error for " << layer;
        } catch (const DefinitionError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find((dir / "d.toml").string() + ":5:1: layer 'x'"), std::string::npos)
                << what;
            EXPECT_NE(what.find(fragment), std::string::npos) << what;
        }
    };
    expectError("[[bed]]\nname = \"x\"\nfile = \"missing.flac\"\n",
                (dir / "missing.flac").string());
    expectError("[[bed]]\nname = \"x\"\nfile = \"corrupt.wav\"\n", (dir / "corrupt.wav").string());
    expectError("[[event]]\nname = \"x\"\nfiles = [\"silent.wav\"]\nrate_per_minute = 2\n",
                "is silent");
    std::filesystem::remove_all(dir);
}

TEST(SoundscapeRenderer, LayerBalanceFollowsLevelDb) {
    // Two beds 6 dB apart: their calibrated powers differ by 6 dB and sum to the target.
    const auto r = prepared(withLayers(R"(
[[bed]]
name = "a"
generator = "wind"
level_db = 0
[[bed]]
name = "b"
generator = "traffic"
level_db = -6
)"));
    const double pa = r->layerUnityPower(0) * r->layerGain(0) * r->layerGain(0);
    const double pb = r->layerUnityPower(1) * r->layerGain(1) * r->layerGain(1);
    EXPECT_NEAR(10 * std::log10(pa / pb), 6.0, 1e-9);
    EXPECT_NEAR(10 * std::log10(pa + pb), -30.0, 1e-9);
}
