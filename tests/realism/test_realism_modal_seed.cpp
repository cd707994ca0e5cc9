// SPDX-License-Identifier: GPL-3.0-or-later
// The modal seed of `underfoot fit` (realism/ModalSeed.h, Fit.h): recorded modes clustered
// across files and sources, written into a solid preset, and a seeded fit that is deterministic.
#include "engine/io/AudioFile.h"
#include "engine/surfaces/Surface.h"
#include "realism/Fit.h"
#include "realism/ModalSeed.h"

#include <gtest/gtest.h>

#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {

struct Truth {
    double f, t60, a;
};
const std::vector<Truth> kModes = {{220, 0.12, 1.0}, {610, 0.08, 0.6}, {1450, 0.05, 0.35}};

// A "recording" of three footsteps 0.6 s apart, each a struck sum of the known modes (detuned
// by `detune`, as two floors of one material differ), in seeded noise 50 dB below the peak.
void writeRecording(const std::string& path, double detune, unsigned seed) {
    const double fs = 48000;
    underfoot::engine::AudioBuffer b;
    b.sampleRateHz = fs;
    b.channels = 1;
    b.samples.assign(std::size_t(2.2 * fs), 0.0f);
    std::mt19937 g(seed);
    std::normal_distribution<double> w(0.0, 0.3 * std::pow(10.0, -50.0 / 20.0));
    std::uniform_real_distribution<double> phase(0, 2 * std::numbers::pi);
    for (int step = 0; step < 3; ++step) {
        const std::size_t at = std::size_t((0.2 + 0.6 * step) * fs);
        std::vector<double> phi;
        for (std::size_t k = 0; k < kModes.size(); ++k) phi.push_back(phase(g));
        for (std::size_t i = 0; at + i < b.samples.size() && i < std::size_t(0.55 * fs); ++i) {
            const double t = double(i) / fs;
            double v = 0;
            for (std::size_t k = 0; k < kModes.size(); ++k) {
                const auto& m = kModes[k];
                v += m.a * std::exp(-std::log(1000.0) / m.t60 * t) *
                     std::cos(2 * std::numbers::pi * m.f * detune * t + phi[k]);
            }
            b.samples[at + i] += float(0.15 * v);
        }
    }
    for (auto& s : b.samples) s += float(w(g));
    underfoot::engine::writeAudioFile(path, b, underfoot::engine::SampleFormat::Float32);
}

// A small impact preset with three modes far from the recorded ones.
const char* kPreset = R"(id = 'seedtest'
name = 'Seed test'
category = 'solid'
description = 'a floor for the modal seed test'
gain_db = 0.0

[[layer]]
type = 'impact'
purpose = 'heel strikes on a test floor'
alpha = 1.5
dissipation = 0.6
gain_db = 1.8
press_fraction = 0.0
sole_mass_kg = 0.1
stiffness = 2.0e9
strike_velocity = 0.45
modes = [
    { freq_hz = 100, gain = 2.0, mass_kg = 4.0, t60_s = 0.3 },
    { freq_hz = 900, gain = 1.0, mass_kg = 1.0, t60_s = 0.1 },
    { freq_hz = 3000, gain = 0.5, mass_kg = 0.6, t60_s = 0.05 },
]
)";

class ModalSeed : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("underfoot-modal-seed-" + std::to_string(long(::getpid())));
        fs::create_directories(dir_);
        int n = 0;
        for (const char* source : {"labA", "labB"})
            for (int file = 0; file < 2; ++file) {
                Recording r;
                r.file = std::string(source) + "/step" + std::to_string(file) + ".wav";
                r.path = (dir_ / (std::string(source) + std::to_string(file) + ".wav")).string();
                r.source = r.package = source;
                r.licence = "CC0-1.0";
                r.material = "wood";
                writeRecording(r.path, 1.0 + 0.004 * (n - 1.5), unsigned(100 + n));
                recordings_.push_back(r);
                ++n;
            }
        preset_ = (dir_ / "seedtest.toml").string();
        std::ofstream(preset_) << kPreset;
    }
    void TearDown() override { fs::remove_all(dir_); }
    // A fit small enough for a test: 2 s renders, 6 evaluations per start, one step per file.
    static FitOptions smallFit() {
        FitOptions o;
        o.spec.seconds = 2.0;
        o.maxEvaluations = 6;
        o.seed.stepsPerFile = 1;
        o.seed.maxSamples = 768;
        return o;
    }
    fs::path dir_;
    std::vector<Recording> recordings_;
    std::string preset_;
};

const RecordedMode* nearest(const std::vector<RecordedMode>& est, double f) {
    const RecordedMode* best = nullptr;
    for (const auto& m : est)
        if (!best ||
            std::fabs(std::log2(m.frequencyHz / f)) < std::fabs(std::log2(best->frequencyHz / f)))
            best = &m;
    return best;
}

} // namespace

TEST(ModalSeedAggregate, ClustersWeightedMediansAndSourceWeights) {
    // Source A (weight 1 in one file) sees 400 Hz; source B (two files, 0.5 each) sees 402 and
    // 404 Hz and, alone, 1000 Hz. A stray 2000 Hz estimate is weak.
    std::vector<ModeObservation> obs = {
        {400, 0.10, 1.0, 1.0},         {402, 0.20, 1.0, 0.5},  {404, 0.30, 1.0, 0.5},
        {1000, 0.05, 1.0, 0.5},        {1005, 0.07, 0.5, 0.5}, {2000, 0.9, 0.05, 0.5},
        {std::nan(""), 0.1, 1.0, 1.0}, {500, -1.0, 1.0, 1.0}, // ignored
    };
    ModalSeedOptions o;
    o.maxModes = 2;
    const auto m = aggregateModes(obs, o);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_NEAR(m[0].frequencyHz, 400, 0.5); // weighted median: A's weight is half the cluster's
    EXPECT_NEAR(m[0].t60S, 0.10, 1e-12);
    EXPECT_DOUBLE_EQ(m[0].gain, 1.0); // strongest cluster (mass 2) is the reference
    EXPECT_EQ(m[0].observations, 3);
    EXPECT_NEAR(m[1].frequencyHz, 1000, 0.5);
    EXPECT_NEAR(m[1].gain, (0.5 + 0.25) / 2.0, 1e-12);
    // Support: every observation is a step of its own here (step -1): 2 of the total 3.5.
    EXPECT_NEAR(m[0].support, 2.0 / 3.5, 1e-12);
    // Order of the input does not matter.
    std::reverse(obs.begin(), obs.end());
    const auto r = aggregateModes(obs, o);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_DOUBLE_EQ(r[0].frequencyHz, m[0].frequencyHz);
    EXPECT_DOUBLE_EQ(r[1].t60S, m[1].t60S);
    EXPECT_TRUE(aggregateModes({}, o).empty());
}

TEST_F(ModalSeed, RecoversTheKnownModesOfASyntheticRecordingSet) {
    for (bool emphasis : {false, true}) {
        SCOPED_TRACE(emphasis ? "first difference" : "signal");
        ModalSeedOptions o;
        o.maxModes = 3;
        o.stepsPerFile = 2; // keeps the test short
        o.maxSamples = 768;
        o.preEmphasis = emphasis;
        std::vector<std::string> skipped;
        const auto modes = recordedModes(recordings_, o, &skipped);
        EXPECT_TRUE(skipped.empty());
        ASSERT_EQ(modes.size(), 3u);
        for (const auto& t : kModes) {
            const auto* m = nearest(modes, t.f);
            ASSERT_NE(m, nullptr);
            EXPECT_NEAR(m->frequencyHz, t.f, 0.01 * t.f);
            EXPECT_NEAR(m->t60S, t.t60, 0.25 * t.t60);
            EXPECT_NEAR(m->gain, t.a / kModes[0].a, 0.35 * t.a / kModes[0].a);
            EXPECT_GT(m->support, 0.9); // every step found every mode
        }
    }
}

TEST_F(ModalSeed, TheSeededPresetCarriesTheRecordedModes) {
    ModalSeedOptions o;
    o.maxModes = 3;
    o.stepsPerFile = 1;
    o.maxSamples = 768;
    const auto modes = recordedModes(recordings_, o);
    const auto text = modalSeededPreset(preset_, modes);
    const auto seeded = (dir_ / "seeded.toml").string();
    std::ofstream(seeded) << text;
    ASSERT_NO_THROW(underfoot::engine::Surface::load(seeded));
    const auto root = toml::parse(text);
    const auto* layer = root["layer"][0].as_table();
    ASSERT_NE(layer, nullptr);
    const auto* arr = (*layer)["modes"].as_array();
    ASSERT_NE(arr, nullptr);
    ASSERT_EQ(arr->size(), 3u);
    double mobility = 0;
    std::vector<double> ratio;
    for (std::size_t k = 0; k < 3; ++k) {
        const auto& m = *(*arr)[k].as_table();
        const double f = m["freq_hz"].value<double>().value_or(0);
        EXPECT_NEAR(f, kModes[k].f, 0.01 * kModes[k].f);
        EXPECT_NEAR(m["t60_s"].value<double>().value_or(0), kModes[k].t60, 0.25 * kModes[k].t60);
        const double g = m["gain"].value<double>().value_or(0);
        const double mass = m["mass_kg"].value<double>().value_or(0);
        mobility += g * g / mass;
        ratio.push_back(g * g / mass / modes[k].gain);
    }
    // g^2 / m of each mode follows its recorded amplitude.
    EXPECT_NEAR(ratio[1] / ratio[0], 1.0, 1e-4);
    EXPECT_NEAR(ratio[2] / ratio[0], 1.0, 1e-4);
    // The floor's mobility at the contact (sum of g^2 / m) is the original's: 4/4 + 1/1 +
    // 0.25/0.6.
    EXPECT_NEAR(mobility, 1.0 + 1.0 + 0.25 / 0.6, 1e-3);
    EXPECT_THROW(modalSeededPreset(preset_, {}), std::invalid_argument);
}

TEST_F(ModalSeed, ASeededFitIsDeterministic) {
    FitOptions o = smallFit();
    // Modes two to four octaves above the recorded ones: the knobs (decay, tilt) cannot bring
    // them down, the seed can.
    std::string high = kPreset;
    for (const auto& [from, to] :
         {std::pair<std::string, std::string>{"freq_hz = 100,", "freq_hz = 3500,"},
          {"freq_hz = 900,", "freq_hz = 6100,"},
          {"freq_hz = 3000,", "freq_hz = 9800,"}})
        high.replace(high.find(from), from.size(), to);
    const auto highPreset = (dir_ / "seedtest_high.toml").string();
    std::ofstream(highPreset) << high;
    const auto a = fitSurface(highPreset, recordings_, o);
    const auto b = fitSurface(highPreset, recordings_, o);
    // Three starts (the preset's own modes and two seeds), the best kept.
    ASSERT_EQ(a.startObjectives.size(), 3u);
    EXPECT_TRUE(a.seedTried);
    EXPECT_TRUE(a.modalSeeded);
    EXPECT_LT(std::min(a.startObjectives[1], a.startObjectives[2]), a.startObjectives[0]);
    EXPECT_EQ(a.seededModes.size(), 3u);
    EXPECT_FALSE(a.seedStart.empty());
    EXPECT_EQ(a.presetText, b.presetText);
    EXPECT_NE(a.presetText.find("modal_seed"), std::string::npos);
    EXPECT_LE(a.distanceAfter, a.distanceSeeded + 0.01);
    // The fitted preset carries the recorded modes (the knobs scale decays and gains only).
    const auto root = toml::parse(a.presetText);
    const auto& modes = *root["layer"][0]["modes"].as_array();
    ASSERT_EQ(modes.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k)
        EXPECT_NEAR(modes[k].as_table()->get("freq_hz")->value<double>().value_or(0), kModes[k].f,
                    0.01 * kModes[k].f);
    // Without the seed the preset's own modes stay.
    o.modalSeed = false;
    const auto own = fitSurface(preset_, recordings_, o);
    EXPECT_FALSE(own.modalSeeded);
    EXPECT_FALSE(own.seedTried);
    EXPECT_EQ(own.startObjectives.size(), 1u);
    const auto ownRoot = toml::parse(own.presetText);
    EXPECT_DOUBLE_EQ(ownRoot["layer"][0]["modes"][1]["freq_hz"].value<double>().value_or(0), 900.0);
}

TEST_F(ModalSeed, ASeedThatRefinesWorseThanThePresetIsNotKept) {
    // The test preset's modes (100, 900, 3000 Hz) straddle the recorded ones: with six
    // evaluations the knobs bring them as close as the seeds get (objective 1.475 against
    // 1.491 and 1.491). The fit keeps the preset's own modes and is never worse than them.
    FitOptions o = smallFit();
    const auto r = fitSurface(preset_, recordings_, o);
    ASSERT_EQ(r.startObjectives.size(), 3u);
    EXPECT_TRUE(r.seedTried);
    EXPECT_LE(r.startObjectives[0], std::min(r.startObjectives[1], r.startObjectives[2]));
    EXPECT_FALSE(r.modalSeeded);
    EXPECT_TRUE(r.seededModes.empty());
    EXPECT_EQ(r.seedStart, "the preset's own parameters");
    EXPECT_LT(r.distanceAfter, r.distanceBefore);
    const auto root = toml::parse(r.presetText);
    EXPECT_DOUBLE_EQ(root["layer"][0]["modes"][1]["freq_hz"].value<double>().value_or(0), 900.0);
    // The provenance says the seed was tried and which start was kept.
    EXPECT_EQ(root["provenance"]["modal_seed"]["starts_tried"].value<std::int64_t>(), 3);
    EXPECT_EQ(root["provenance"]["modal_seed"]["start"].value<std::string>(),
              "the preset's own parameters");
}
