// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/CookEnvelope.h"
#include "engine/control/GrfFile.h"
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Random.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <unistd.h>

#include "tests/common/ScratchDir.h"

using namespace underfoot::engine;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
    return underfoot::test::scratchDir("test_grf");
}

std::string writeText(const std::string& name, const std::string& text) {
    const auto path = (tempDir() / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string writeWav(const std::string& name, const std::vector<float>& x, int rate, int format) {
    const auto path = (tempDir() / name).string();
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | format;
    SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
    sf_command(f, SFC_SET_CLIPPING, nullptr, SF_TRUE);
    sf_writef_float(f, x.data(), static_cast<sf_count_t>(x.size()));
    sf_close(f);
    return path;
}

std::string loadError(const std::string& path, const GrfLoadOptions& o = {}) {
    try {
        loadGrfFile(path, o);
    } catch (const FileError& e) {
        return e.what();
    }
    return "(loaded)";
}

// A smooth half-sine "step" of 0.6 s at `rate` Hz peaking at `peak`, with 0.2 s of zeros around it.
std::vector<double> halfSineStep(double rate, double peak) {
    std::vector<double> x;
    const auto n = static_cast<std::size_t>(1.0 * rate);
    for (std::size_t i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / rate - 0.2;
        x.push_back(t >= 0 && t < 0.6 ? peak * std::sin(M_PI * t / 0.6) : 0.0);
    }
    return x;
}

} // namespace

TEST(GrfFile, WavRoundTripAtEngineRate) {
    VirtualWalker w(WalkerParameters::parse("cadence=110,mass=75,shoe=0.7,variability=0.02"));
    w.prepare({48000, 512});
    w.reset(5);
    GrfSignal g;
    g.sampleRateHz = 48000;
    g.names = {"left", "right"};
    g.channels.assign(2, std::vector<float>(96000));
    w.process(g.channels[0].data(), g.channels[1].data(), 96000);
    const auto path = (tempDir() / "walk.wav").string();
    writeGrfWav(path, g, 1500.0);
    GrfLoadOptions o;
    o.fullScaleNewtons = 1500.0;
    const GrfSignal r = loadGrfFile(path, o);
    EXPECT_EQ(r.sampleRateHz, 48000);
    EXPECT_EQ(r.names, (std::vector<std::string>{"left", "right"}));
    EXPECT_DOUBLE_EQ(r.durationSeconds(), 2.0);
    for (int c = 0; c < 2; ++c)
        for (std::size_t i = 0; i < 96000; i += 17)
            ASSERT_NEAR(r.channels[c][i], g.channels[c][i], 1e-3) << c << " " << i;
}

TEST(GrfFile, WavFullScaleAndResamplingKeepTheForce) {
    // 1 kHz PCM24 mono half-sine with peak 0.8 of full scale -> 800 N at the default 1000 N.
    const auto ref = halfSineStep(1000, 0.8);
    std::vector<float> x(ref.begin(), ref.end());
    const auto path = writeWav("fs.wav", x, 1000, SF_FORMAT_PCM_24);
    const GrfSignal g = loadGrfFile(path); // to 48 kHz
    ASSERT_EQ(g.names, std::vector<std::string>{"grf"});
    EXPECT_EQ(g.sampleRateHz, 48000);
    EXPECT_EQ(g.frames(), 48000u);
    const auto& y = g.channels[0];
    const auto peak = std::max_element(y.begin(), y.end());
    EXPECT_NEAR(*peak, 800.0, 0.5);
    EXPECT_NEAR(double(peak - y.begin()) / 48000.0, 0.5, 0.001); // the half-sine's centre
    EXPECT_GE(*std::min_element(y.begin(), y.end()), 0.0f);
    // Same file, full scale 2000 N: twice the force.
    GrfLoadOptions o;
    o.fullScaleNewtons = 2000;
    o.targetRateHz = 1000;
    const GrfSignal g2 = loadGrfFile(path, o);
    EXPECT_NEAR(*std::max_element(g2.channels[0].begin(), g2.channels[0].end()), 1600.0, 1e-3);
}

TEST(GrfFile, ClippedWavIsAnErrorUnlessAllowed) {
    auto ref = halfSineStep(1000, 1.3); // overdriven: flat top at full scale after PCM clipping
    std::vector<float> x(ref.begin(), ref.end());
    const auto path = writeWav("clipped.wav", x, 1000, SF_FORMAT_PCM_16);
    const std::string msg = loadError(path);
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("clipped"), std::string::npos) << msg;
    // First sample above 1/1.3 of the half-sine: t = 0.2 + 0.6 asin(1/1.3)/pi = 0.3678 s.
    EXPECT_NE(msg.find("t = 0.36"), std::string::npos) << msg;
    GrfLoadOptions o;
    o.allowClipped = true;
    EXPECT_NO_THROW(loadGrfFile(path, o));
    // Touching full scale for a single sample is not clipping.
    std::vector<float> once(100, 0.5f);
    once[50] = 1.0f;
    EXPECT_NO_THROW(loadGrfFile(writeWav("once.wav", once, 1000, SF_FORMAT_PCM_16)));
}

TEST(GrfFile, FloatFilesHaveNoFullScaleToClipAt) {
    // A live recording (float WAV, 1.0 = 1000 N) of a heavy walker resting near 1000 N for a
    // while is a force, not a clipped signal; the same plateau in 16-bit PCM is clipping.
    std::vector<float> x(200, 0.2f);
    for (int i = 80; i < 120; ++i) x[static_cast<std::size_t>(i)] = 1.0f;
    for (int i = 120; i < 130; ++i) x[static_cast<std::size_t>(i)] = 1.2f;
    GrfLoadOptions o;
    o.targetRateHz = 1000;
    const GrfSignal g = loadGrfFile(writeWav("plateau_float.wav", x, 1000, SF_FORMAT_FLOAT), o);
    EXPECT_NEAR(g.channels[0][100], 1000.0f, 1e-3f);
    EXPECT_NEAR(g.channels[0][125], 1200.0f, 1e-3f);
    EXPECT_NE(loadError(writeWav("plateau_pcm.wav", x, 1000, SF_FORMAT_PCM_16)).find("clipped"),
              std::string::npos);
}

TEST(GrfFile, NegativeForcesBeyondNoiseAreErrorsSmallOnesAreZeroed) {
    auto ref = halfSineStep(1000, 0.8);
    std::vector<float> x(ref.begin(), ref.end());
    x[10] = -0.01f; // -10 N, within 2 % of the 800 N peak
    GrfLoadOptions o;
    o.targetRateHz = 1000;
    const GrfSignal g = loadGrfFile(writeWav("noise.wav", x, 1000, SF_FORMAT_FLOAT), o);
    EXPECT_EQ(g.channels[0][10], 0.0f);
    x[20] = -0.1f; // -100 N
    const std::string msg = loadError(writeWav("neg.wav", x, 1000, SF_FORMAT_FLOAT), o);
    EXPECT_NE(msg.find("negative force -100.000 N"), std::string::npos) << msg;
    EXPECT_NE(msg.find("frame 20"), std::string::npos) << msg;
}

TEST(GrfFile, BadWavFilesGiveClearErrors) {
    std::vector<float> x = {0.1f, 0.2f, std::numeric_limits<float>::infinity(), 0.1f};
    EXPECT_NE(loadError(writeWav("inf.wav", x, 1000, SF_FORMAT_FLOAT)).find("non-finite"),
              std::string::npos);
    EXPECT_NE(loadError(writeWav("empty.wav", {}, 1000, SF_FORMAT_PCM_16)).find("empty"),
              std::string::npos);
    EXPECT_NE(loadError((tempDir() / "missing.wav").string()).find("not found"), std::string::npos);
    GrfLoadOptions o;
    o.targetRateHz = 0;
    EXPECT_NE(
        loadError(writeWav("ok.wav", {0.1f, 0.2f}, 1000, SF_FORMAT_PCM_16), o).find("target rate"),
        std::string::npos);
}

TEST(GrfFile, CsvInNewtonsAndBodyWeights) {
    // 1 kHz, two columns: left in newtons, right in body weights.
    const auto ref = halfSineStep(1000, 1.0);
    std::string text = "# force plate export\ntime_s,left,right_bw\n";
    for (std::size_t i = 0; i < ref.size(); ++i)
        text += std::to_string(0.5 + static_cast<double>(i) * 0.001) + "," +
                std::to_string(700 * ref[i]) + "," + std::to_string(1.1 * ref[i]) + "\r\n";
    GrfLoadOptions o;
    o.bodyMassKg = 80;
    const GrfSignal g = loadGrfFile(writeText("plate.csv", text), o);
    EXPECT_EQ(g.names, (std::vector<std::string>{"left", "right"}));
    EXPECT_EQ(g.sampleRateHz, 48000);
    EXPECT_NEAR(g.durationSeconds(), 1.0, 0.001);
    auto peak = [](const std::vector<float>& v) { return *std::max_element(v.begin(), v.end()); };
    EXPECT_NEAR(peak(g.channels[0]), 700.0, 0.5);
    EXPECT_NEAR(peak(g.channels[1]), 1.1 * 80 * kGravity, 0.5);
    // 100 Hz (a ratio of 480, done in two resampling stages) keeps the shape too.
    const auto coarse = halfSineStep(100, 1.0);
    std::string t2 = "time_s,grf_bw\n";
    for (std::size_t i = 0; i < coarse.size(); ++i)
        t2 +=
            std::to_string(static_cast<double>(i) * 0.01) + "," + std::to_string(coarse[i]) + "\n";
    const GrfSignal g2 = loadGrfFile(writeText("coarse.csv", t2), o);
    EXPECT_NEAR(g2.durationSeconds(), 1.0, 0.001);
    EXPECT_NEAR(peak(g2.channels[0]), 80 * kGravity, 0.01 * 80 * kGravity);
    // Half-sine value at t = 0.35 s: sin(pi 0.15 / 0.6) = 0.7071 BW.
    EXPECT_NEAR(g2.channels[0][static_cast<std::size_t>(0.35 * 48000)] / (80 * kGravity), 0.7071,
                0.01);
}

// A force-plate walk: steps of 0.6 s (half-sines peaking at 700 N) every 1.0 s, 0.4 s of swing
// between them, at 1 kHz, plus Gaussian noise of `sigma` N around `level` N (0, 0: clean).
std::vector<float> plateWalk(double level, double sigma, std::uint64_t seed = 3) {
    Random random(seed);
    std::vector<float> x;
    for (int i = 0; i < 6000; ++i) {
        const double t = std::fmod(i / 1000.0, 1.0);
        const double g = random.gaussian();
        x.push_back(static_cast<float>((t < 0.6 ? 700.0 * std::sin(M_PI * t / 0.6) : 0.0) +
                                       (sigma > 0 ? level + sigma * g : level)));
    }
    return x;
}

TEST(GrfFile, TareMeasuresThePlatesZeroAndLeavesCleanChannelsAlone) {
    // Clean: exact zeros in the air, nothing measured, nothing taken off.
    const GrfTare clean = measureGrfTare(plateWalk(0, 0));
    EXPECT_EQ(clean.subtractedN, 0.0);
    EXPECT_EQ(clean.levelN, 0.0);
    EXPECT_EQ(clean.noiseN, 0.0);
    // Noise of 3 N around +2 N: the level and the noise come back within ~10 % (2400 swing
    // samples), and the zero taken off is level + 4 sigma.
    const GrfTare noisy = measureGrfTare(plateWalk(2.0, 3.0));
    EXPECT_NEAR(noisy.levelN, 2.0, 0.3);
    EXPECT_NEAR(noisy.noiseN, 3.0, 0.3);
    EXPECT_NEAR(noisy.subtractedN, noisy.levelN + 4.0 * noisy.noiseN, 1e-9);
    EXPECT_GT(noisy.samplesNearZero, 2000u);
    std::vector<float> x = plateWalk(2.0, 3.0);
    applyGrfTare(x, noisy);
    std::size_t airborne = 0; // swing samples still above the layers' 5 N contact threshold
    for (std::size_t i = 0; i < x.size(); ++i)
        if (std::fmod(static_cast<double>(i) / 1000.0, 1.0) >= 0.6 && x[i] > 5.0f) ++airborne;
    EXPECT_EQ(airborne, 0u);
    for (float v : x) ASSERT_GE(v, 0.0f);
    // Standing only (no sample near 0 N): nothing to learn the zero from, nothing taken off.
    std::vector<float> standing(6000);
    for (std::size_t i = 0; i < standing.size(); ++i)
        standing[i] = static_cast<float>(700.0 + 15.0 * std::sin(static_cast<double>(i) / 400.0));
    EXPECT_EQ(measureGrfTare(standing).subtractedN, 0.0);
    // A "zero" that would be 5 % of the peak or more is load, not noise: left alone.
    EXPECT_EQ(measureGrfTare(plateWalk(0.0, 12.0)).subtractedN, 0.0);
}

TEST(GrfFile, TareIsAnOptionOfTheLoaderAndReplaysReadTheFileAsItIs) {
    const auto x = plateWalk(1.0, 3.0);
    std::string text = "time_s,left\n";
    for (std::size_t i = 0; i < x.size(); ++i)
        text += std::to_string(static_cast<double>(i) * 0.001) + "," + std::to_string(x[i]) + "\n";
    const auto path = writeText("noisy_plate.csv", text);
    // Default (as replays load their recordings): the noise is kept, no tare reported.
    const GrfSignal raw = loadGrfFile(path);
    EXPECT_TRUE(raw.tare.empty());
    EXPECT_EQ(describeGrfTare(raw, path), "");
    auto swingMax = [](const GrfSignal& g) {
        float m = 0.0f; // mid-swing, 0.7-0.9 s of each second, away from the resampler's edges
        for (std::size_t i = 0; i < g.frames(); ++i) {
            const double t = std::fmod(static_cast<double>(i) / g.sampleRateHz, 1.0);
            if (t > 0.7 && t < 0.9) m = std::max(m, g.channels[0][i]);
        }
        return m;
    };
    EXPECT_GT(swingMax(raw), 5.0f); // the plate's noise crosses the layers' contact threshold
    GrfLoadOptions o;
    o.tare = GrfTareMode::Apply;
    const GrfSignal tared = loadGrfFile(path, o);
    ASSERT_EQ(tared.tare.size(), 1u);
    EXPECT_GT(tared.tare[0].subtractedN, 10.0);
    EXPECT_LT(swingMax(tared), 0.5f);
    // Measure (what `grf info` shows): the same zero, the samples as they are, nothing reported.
    o.tare = GrfTareMode::Measure;
    const GrfSignal measured = loadGrfFile(path, o);
    ASSERT_EQ(measured.tare.size(), 1u);
    EXPECT_EQ(measured.tare[0].subtractedN, tared.tare[0].subtractedN);
    EXPECT_FALSE(measured.tare[0].applied);
    EXPECT_TRUE(tared.tare[0].applied);
    EXPECT_EQ(measured.channels, raw.channels);
    EXPECT_EQ(describeGrfTare(measured, path), "");
    o.tare = GrfTareMode::Apply;
    const std::string note = describeGrfTare(tared, path);
    EXPECT_NE(note.find("noisy_plate.csv: channel \"left\": force-plate zero +"), std::string::npos)
        << note;
    EXPECT_NE(note.find("N taken off every sample"), std::string::npos) << note;
    // The same file in WAV (float, 1000 N full scale) gives the same zero.
    std::vector<float> scaled(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) scaled[i] = x[i] / 1000.0f;
    const GrfSignal wav =
        loadGrfFile(writeWav("noisy_plate.wav", scaled, 1000, SF_FORMAT_FLOAT), o);
    ASSERT_EQ(wav.tare.size(), 1u);
    EXPECT_NEAR(wav.tare[0].subtractedN, tared.tare[0].subtractedN, 0.01);
    // A clean file loads the same samples with and without the tare.
    const auto c = plateWalk(0, 0);
    std::string clean = "time_s,left\n";
    for (std::size_t i = 0; i < c.size(); ++i)
        clean += std::to_string(static_cast<double>(i) * 0.001) + "," + std::to_string(c[i]) + "\n";
    const auto cleanPath = writeText("clean_plate.csv", clean);
    EXPECT_EQ(loadGrfFile(cleanPath, o).channels, loadGrfFile(cleanPath).channels);
}

TEST(GrfFile, AFileThatStartsAndEndsUnderLoadIsNoLandingAndNoRinging) {
    // A recording cut from a longer trial: 600 N from the first sample to the last, at 1 kHz (CSV)
    // and at 44.1 kHz (WAV). The resampler used to start from silence: the load rose from 0 N over
    // a few milliseconds with the sinc's ringing (682 N peak) and ended the same way, and a wood
    // floor heard a landing at the first sample (-20.5 dBFS) and a strike at the last.
    std::string text = "time_s,left\n";
    for (int i = 0; i < 1000; ++i) text += std::to_string(i * 0.001) + ",600\n";
    const GrfSignal csv = loadGrfFile(writeText("held.csv", text));
    const GrfSignal wav =
        loadGrfFile(writeWav("held.wav", std::vector<float>(44100, 0.6f), 44100, SF_FORMAT_FLOAT));
    for (const GrfSignal* g : {&csv, &wav}) {
        ASSERT_EQ(g->frames(), 48000u);
        const auto [lo, hi] = std::minmax_element(g->channels[0].begin(), g->channels[0].end());
        EXPECT_NEAR(*lo, 600.0f, 0.5f);
        EXPECT_NEAR(*hi, 600.0f, 0.5f);
    }
    auto wood = Surface::loadById("wood");
    wood->prepare({48000.0, 480});
    wood->reset(1);
    std::vector<float> out(480);
    float peak = 0.0f;
    for (std::size_t i = 0; i + 480 <= csv.frames(); i += 480) {
        std::fill(out.begin(), out.end(), 0.0f);
        wood->process(csv.channels[0].data() + i, out.data(), 480);
        for (float v : out) peak = std::max(peak, std::fabs(v));
    }
    EXPECT_EQ(peak, 0.0f) << "a landing or a strike was heard in a load held from start to end";
}

TEST(GrfFile, CsvErrorsNameFileLineColumnAndExpectation) {
    const std::string head = "time_s,left,right\n";
    struct Case {
        std::string name, text, expect;
    };
    const std::vector<Case> cases = {
        {"nan.csv", head + "0,1,2\n0.001,nan,2\n", ":3:7: non-finite value \"nan\""},
        {"inf.csv", head + "0,1,2\n0.001,1,-inf\n", ":3:9: non-finite value \"-inf\""},
        {"text.csv", head + "0,1,2\n0.001,1,heavy\n",
         ":3:9: not a number \"heavy\"; expected a force"},
        {"time.csv", head + "0,1,2\nzero,1,2\n", ":3:1: not a number \"zero\"; expected a time"},
        {"emptycell.csv", head + "0,1,2\n0.001,,2\n", ":3:7: not a number"},
        {"empty.csv", "", ": empty file"},
        {"comments.csv", "# nothing\n\n", ": empty file"},
        {"headeronly.csv", head, ": 0 data row(s)"},
        {"badheader.csv", "t,left\n0,1\n", ":1:1: expected the header"},
        {"nocolumns.csv", "time_s\n0\n", ":1:7: expected at least one force column"},
        {"dup.csv", "time_s,left,left\n", ":1:13: column \"left\" appears twice"},
        {"back.csv", head + "0,1,2\n0.001,1,2\n0.0005,1,2\n", ":4:1: time 0.0005 s is not after"},
        {"same.csv", head + "0,1,2\n0,1,2\n", ":3:1: time 0 s is not after"},
        {"gap.csv", head + "0,1,2\n0.001,1,2\n0.002,1,2\n0.010,1,2\n0.011,1,2\n",
         ":5:1: time step 0.008 s differs"},
        {"count.csv", head + "0,1,2\n0.001,1\n", ":3:1: expected 3 comma-separated values"},
        {"neg.csv", head + "0,100,2\n0.001,-50,2\n0.002,100,2\n",
         ":3: column \"left\": negative force -50.000 N"},
    };
    for (const auto& c : cases) {
        const auto path = writeText(c.name, c.text);
        const std::string msg = loadError(path);
        EXPECT_NE(msg.find(path + c.expect), std::string::npos)
            << c.name << ": " << msg << "\n  expected: " << c.expect;
    }
    EXPECT_NE(loadError((tempDir() / "nope.csv").string()).find("not found"), std::string::npos);
    // Small negative noise (within 2 % of the peak) is accepted and set to 0.
    GrfLoadOptions o;
    o.targetRateHz = 1000;
    const GrfSignal g =
        loadGrfFile(writeText("noise.csv", head + "0,-5,0\n0.001,500,0\n0.002,400,0\n"), o);
    EXPECT_EQ(g.channels[0][0], 0.0f);
    EXPECT_EQ(g.channels[0][1], 500.0f);
}

// Cook's filter written out exactly as in TVCG 2011 eq. (1), as the reference.
TEST(CookEnvelope, MatchesCooksEquationWithTheDocumentedCoefficients) {
    const double fs = 48000;
    CookEnvelope env;
    env.prepare({fs, 256}, 1);
    env.setSettings({1.0, 100.0, 1.0});
    const double bUp = std::exp(std::log(0.01) / (1.0 * fs / 1000));
    const double bDown = std::exp(std::log(0.01) / (100.0 * fs / 1000));
    EXPECT_NEAR(env.upCoefficient(), 0.90852, 1e-5); // values quoted in CookEnvelope.h
    EXPECT_NEAR(env.downCoefficient(), 0.99904, 1e-5);
    EXPECT_DOUBLE_EQ(env.upCoefficient(), bUp);
    Random r(9);
    double e = 0;
    for (int i = 0; i < 48000; ++i) {
        const double burst = (i % 12000) < 3000 ? 1.0 : 0.05;
        const float x = static_cast<float>(burst * r.bipolar());
        const double ax = std::fabs(static_cast<double>(x));
        const double b = ax > e ? bUp : bDown;
        e = (1 - b) * ax + b * e;
        ASSERT_NEAR(env.processFrame(&x), e, 1e-6 * std::max(1.0, e)) << i;
    }
}

TEST(CookEnvelope, RiseAndFallTimesAreTheSettings) {
    for (double fs : {44100.0, 96000.0}) {
        CookEnvelope env;
        env.prepare({fs, 64}, 1);
        env.setSettings({5.0, 200.0, 2.0});
        const float one = 1.0f, zero = 0.0f;
        int n99 = 0;
        while (env.processFrame(&one) < 0.99f * 2.0f) ++n99;
        EXPECT_NEAR(n99 + 1, 5.0e-3 * fs, 1.5) << fs;
        for (int i = 0; i < int(fs); ++i) env.processFrame(&one);
        int n01 = 0;
        while (env.processFrame(&zero) > 0.01f * 2.0f) ++n01;
        EXPECT_NEAR(n01 + 1, 0.2 * fs, 2.0) << fs;
    }
}

TEST(CookEnvelope, FollowsTheLoudestOfSeveralMicrophones) {
    const double fs = 48000;
    CookEnvelope env, single;
    env.prepare({fs, 128}, 4);
    single.prepare({fs, 128}, 1);
    std::vector<std::vector<float>> mic(4, std::vector<float>(48000, 0.0f));
    Random r(1);
    // Mic 2 hears the step loudest, the others 0.3x of the same sound.
    std::vector<float> ref(48000);
    for (int i = 0; i < 48000; ++i) {
        const double envTrue = i < 4800 ? 0.0 : std::exp(-(i - 4800) / (0.05 * fs));
        ref[i] = static_cast<float>(0.8 * envTrue * r.bipolar());
        for (int c = 0; c < 4; ++c) mic[c][i] = c == 2 ? ref[i] : 0.3f * ref[i];
    }
    const float* in[4] = {mic[0].data(), mic[1].data(), mic[2].data(), mic[3].data()};
    std::vector<float> out(48000), expect(48000);
    env.process(in, out.data(), 48000);
    single.process(std::array<const float*, 1>{ref.data()}.data(), expect.data(), 48000);
    EXPECT_EQ(out, expect);
    EXPECT_EQ(env.loudestChannel(), 2);
    EXPECT_THROW(env.prepare({fs, 128}, 0), std::invalid_argument);
    EXPECT_THROW(env.prepare({fs, 128}, CookEnvelope::kMaxChannels + 1), std::invalid_argument);
    EXPECT_THROW(env.setSettings({-1.0, 10.0, 1.0}), std::invalid_argument);
}

TEST(CookEnvelope, OfflineFootstepToGrfScaledToPeakForce) {
    // A synthetic footstep: noise under a 10 ms linear rise then an 80 ms exponential decay,
    // stereo (right channel quieter), written as 44.1 kHz PCM24 and read at 48 kHz.
    const double fs = 44100;
    AudioBuffer rec;
    rec.sampleRateHz = fs;
    rec.channels = 2;
    Random r(3);
    const auto n = static_cast<std::size_t>(0.6 * fs);
    for (std::size_t i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / fs - 0.1;
        const double a = t < 0 ? 0 : (t < 0.01 ? t / 0.01 : std::exp(-(t - 0.01) / 0.08));
        const float x = static_cast<float>(0.7 * a * r.bipolar());
        rec.samples.push_back(x);
        rec.samples.push_back(0.5f * x);
    }
    const auto path = (tempDir() / "step.wav").string();
    writeAudioFile(path, rec);
    const GrfSignal g = grfFromFootstepFile(path, 850.0, 48000);
    EXPECT_EQ(g.sampleRateHz, 48000);
    ASSERT_EQ(g.channels.size(), 1u);
    const auto& y = g.channels[0];
    const auto peak = std::max_element(y.begin(), y.end());
    EXPECT_FLOAT_EQ(*peak, 850.0f);
    // The envelope peaks at the end of the rise (0.11 s) within the noise's randomness.
    EXPECT_NEAR(double(peak - y.begin()) / 48000.0, 0.11, 0.02);
    EXPECT_LT(y[static_cast<std::size_t>(0.09 * 48000)], 1e-3f); // nothing before the step
    // Decays with the sound: 0.3 s after the peak the sound is at exp(-0.3/0.08) = 2.4 %.
    EXPECT_LT(y[static_cast<std::size_t>(0.41 * 48000)], 0.06f * 850.0f);
    AudioBuffer silent;
    silent.sampleRateHz = 48000;
    silent.channels = 1;
    silent.samples.assign(1000, 0.0f);
    EXPECT_THROW(grfFromFootstep(silent, 800, {}), FileError);
}
