// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot fit` on layers of noise bursts (excitation = "noise",
// engine/surfaces/GranularLayers.h): the knobs noise_decay, noise_band and noise_attack exist for
// them, and the fit moves the bursts' build-up (noise_attack_ratio) towards recordings whose bursts
// build up slowly.
#include "engine/io/AudioFile.h"
#include "realism/Compare.h"
#include "realism/Fit.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {

// One grains layer of noise bursts: 20 ms bursts whose power builds up over `attackRatio` of
// their decay (0: each starts at once, like a tap).
std::string noisePreset(double attackRatio) {
    return fmt::format(R"(id = 'noisefit'
name = 'Noise fit test'
category = 'aggregate'
description = 'noise bursts for the fit test'
gain_db = -6.0

[[layer]]
type = 'grains'
purpose = 'friction hiss of test grains under the sole'
excitation = 'noise'
noise_decay_ms = 20.0
noise_attack_ratio = {}
noise_corner_hz = 1000.0
events_per_s_per_kn = 40.0
events_per_kn_rise = 60.0
gamma = -1.3
energy_min = 0.01
voices = 16
)",
                       attackRatio);
}

class FitNoise : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ =
            fs::temp_directory_path() / ("underfoot-fit-noise-" + std::to_string(long(::getpid())));
        fs::create_directories(dir_);
        const auto recorded = (dir_ / "recorded.toml").string();
        std::ofstream(recorded) << noisePreset(0.8);
        int n = 0;
        for (const char* walker : {"cadence=100", "cadence=92"}) {
            Recording r;
            r.file = fmt::format("own/{}.wav", n);
            r.path = (dir_ / fmt::format("{}.wav", n)).string();
            r.source = r.package = "own";
            r.licence = "CC0-1.0";
            r.material = "sand";
            underfoot::engine::writeAudioFile(
                r.path,
                renderForComparison(recorded, RenderSpec{walker, 4.0, unsigned(30 + n), 48000}),
                underfoot::engine::SampleFormat::Float32);
            own_.push_back(r);
            ++n;
        }
        preset_ = (dir_ / "noisefit.toml").string();
        std::ofstream(preset_) << noisePreset(0.0);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path dir_;
    std::vector<Recording> own_;
    std::string preset_;
};

} // namespace

TEST_F(FitNoise, TheBurstsBuildUpTowardsTheRecordings) {
    FitOptions o;
    o.spec.seconds = 3.0;
    o.maxEvaluations = 12;
    o.modalSeed = false;
    // Everything but the build-up held: a one-knob fit.
    o.keep = {"grain_band",   "grain_q",     "grain_rate", "burst",
              "burst_length", "noise_decay", "noise_band"};
    const auto r = fitSurface(preset_, own_, o);
    ASSERT_EQ(r.knobs.size(), 1u);
    EXPECT_EQ(r.knobs[0].name, "noise_attack");
    const auto root = toml::parse(r.presetText);
    const double ratio = root["layer"][0]["noise_attack_ratio"].value<double>().value_or(-1);
    // Recorded with 0.8, started from 0: the fit builds the bursts up, within the key's range.
    EXPECT_GT(ratio, 0.3) << "distance " << r.distanceBefore << " -> " << r.distanceAfter;
    EXPECT_LE(ratio, 0.9);
    EXPECT_LT(r.distanceAfter, r.distanceBefore);
    EXPECT_DOUBLE_EQ(root["layer"][0]["noise_decay_ms"].value<double>().value_or(0), 20.0);
}

TEST_F(FitNoise, NoiseKnobsAreOfferedOnlyForNoiseLayers) {
    FitOptions o;
    o.spec.seconds = 2.0;
    o.maxEvaluations = 2;
    o.modalSeed = false;
    o.keep = {"noise_attack"};
    const auto r = fitSurface(preset_, own_, o);
    std::vector<std::string> names;
    for (const auto& k : r.knobs) names.push_back(k.name);
    for (const char* want : {"noise_decay", "noise_band"})
        EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
    // A preset of resonant grains only has no noise knob to keep.
    const auto resonant = (dir_ / "resonant.toml").string();
    std::string text = noisePreset(0.0);
    for (const char* line : {"excitation = 'noise'\n", "noise_decay_ms = 20.0\n",
                             "noise_attack_ratio = 0\n", "noise_corner_hz = 1000.0\n"}) {
        const auto at = text.find(line);
        ASSERT_NE(at, std::string::npos) << line;
        text.erase(at, std::string(line).size());
    }
    std::ofstream(resonant) << text;
    try {
        fitSurface(resonant, own_, o);
        ADD_FAILURE() << "noise_attack was kept on a preset without noise bursts";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("noise_attack"), std::string::npos) << e.what();
    }
}
