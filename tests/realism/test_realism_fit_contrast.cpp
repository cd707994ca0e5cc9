// SPDX-License-Identifier: GPL-3.0-or-later
// The contrastive objective of `underfoot fit` (realism/Fit.h): with recordings of another
// material, the fit minimises d_own + LAMBDA max(0, d_own - d_other + margin), so that the
// fitted render ends closer to its own recordings than to the other material's.
#include "engine/io/AudioFile.h"
#include "realism/Compare.h"
#include "realism/Fit.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {

// One grains layer: the fit moves its band, Q and rate.
std::string grainsPreset(double bandScale) {
    return fmt::format(R"(id = 'contrasttest'
name = 'Contrast test'
category = 'aggregate'
description = 'grains for the contrastive fit test'
gain_db = -6.0

[[layer]]
type = 'grains'
purpose = 'crunch of test grains under the sole'
events_per_s_per_kn = 60.0
events_per_kn_rise = 200.0
events_per_kn_fall = 60.0
gamma = -1.3
energy_min = 0.01
freq_min_hz = {}
freq_max_hz = {}
q_min = 4.0
q_max = 12.0
resonances = 1
voices = 24
)",
                       600.0 * bandScale, 2400.0 * bandScale);
}

class FitContrast : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("underfoot-fit-contrast-" + std::to_string(long(::getpid())));
        fs::create_directories(dir_);
        // "Own" material ("clay"): two sources, the preset's grains a fifth of an octave and an
        // octave and a fifth higher (a heterogeneous material), with a faint noise floor the
        // preset cannot make.
        int n = 0;
        for (double octaves : {0.2, 1.2})
            for (const char* walker : {"cadence=100", "cadence=96"})
                own_.push_back(record(grainsPreset(std::exp2(octaves)), walker, "own", "clay",
                                      unsigned(20 + n++), -40.0));
        preset_ = (dir_ / "contrasttest.toml").string();
        std::ofstream(preset_) << grainsPreset(1.0);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // A render of `preset` as a recording, with seeded white noise `noiseDb` below its peak.
    Recording record(const std::string& preset, const std::string& walker,
                     const std::string& source, const std::string& material, unsigned seed,
                     double noiseDb) {
        const auto p = (dir_ / fmt::format("src{}.toml", seed)).string();
        std::ofstream(p) << preset;
        RenderSpec spec{walker, 4.0, seed, 48000};
        Recording r;
        r.file = fmt::format("{}/{}.wav", source, seed);
        r.path = (dir_ / fmt::format("{}.wav", seed)).string();
        r.source = r.package = source;
        r.licence = "CC0-1.0";
        r.material = material;
        auto audio = renderForComparison(p, spec);
        double peak = 0;
        for (float v : audio.samples) peak = std::max(peak, double(std::fabs(v)));
        std::mt19937 g(seed);
        std::normal_distribution<double> w(0.0, peak * std::pow(10.0, noiseDb / 20.0));
        for (auto& v : audio.samples) v = float(v + w(g));
        underfoot::engine::writeAudioFile(r.path, audio, underfoot::engine::SampleFormat::Float32);
        return r;
    }

    // "Other" material ("slate"): one tight source that sounds like `presetText`.
    void recordOthers(const std::string& presetText) {
        int n = 0;
        for (const char* walker : {"cadence=100", "cadence=104"})
            others_.push_back(
                record(presetText, walker, "other", "slate", unsigned(40 + n++), -300));
    }

    FitOptions options(double contrast) const {
        FitOptions o;
        o.spec.seconds = 3.0;
        o.maxEvaluations = 30;
        o.others = others_;
        o.others.insert(o.others.end(), own_.begin(), own_.end()); // skipped by ownMaterial
        o.ownMaterial = "clay";
        o.contrast = contrast;
        o.margin = 0.1;
        return o;
    }

    fs::path dir_;
    std::vector<Recording> own_, others_;
    std::string preset_;
};

} // namespace

TEST(FitContrastObjective, HingeAboveTheMargin) {
    EXPECT_DOUBLE_EQ(contrastiveObjective(0.5, 1.0, 2.0, 0.1), 0.5); // 0.4 apart: no penalty
    EXPECT_DOUBLE_EQ(contrastiveObjective(0.5, 0.55, 2.0, 0.1), 0.5 + 2.0 * 0.05);
    EXPECT_DOUBLE_EQ(contrastiveObjective(0.8, 0.3, 3.0, 0.0), 0.8 + 3.0 * 0.5);
    EXPECT_DOUBLE_EQ(contrastiveObjective(0.8, 0.3, 0.0, 0.1), 0.8);  // contrast off
    EXPECT_DOUBLE_EQ(contrastiveObjective(0.8, -1.0, 2.0, 0.1), 0.8); // no other material
}

TEST_F(FitContrast, PlainFitLandsNearerTheOtherMaterialTheContrastiveOneDoesNot) {
    // The plain fit (no other material) finds its optimum for clay; slate is recorded where it
    // landed (as in the real case, where the render a plain fit lands on is nearest another
    // material's recordings: sand near water, dirt near snow).
    auto plainOptions = options(0.0);
    const auto plain = fitSurface(preset_, own_, plainOptions);
    EXPECT_FALSE(plain.contrastive);
    EXPECT_LT(plain.distanceAfter, plain.distanceBefore);
    recordOthers(plain.presetText);
    // Measured on the plain fit's preset: it is nearer slate than clay.
    const auto plainFile = (dir_ / "plain.toml").string();
    std::ofstream(plainFile) << plain.presetText;
    const auto render = renderForComparison(plainFile, plainOptions.spec);
    const double plainOwn = compareAudio(plainFile, render, own_).comparison.distance;
    const double plainOther = compareAudio(plainFile, render, others_).comparison.distance;
    EXPECT_NEAR(plainOwn, plain.distanceAfter, 1e-9);
    EXPECT_GT(plainOwn, plainOther + 0.1) << "the test case no longer fools the plain fit";

    // The contrastive fit from the same preset: closer to clay than to slate by the margin.
    const auto contrast = fitSurface(preset_, own_, options(2.0));
    ASSERT_TRUE(contrast.contrastive);
    EXPECT_EQ(contrast.before.nearestMaterial, "slate");
    EXPECT_EQ(contrast.after.nearestMaterial, "slate");
    EXPECT_LT(contrast.after.own + 0.1, contrast.after.nearest)
        << "own " << contrast.after.own << " vs slate " << contrast.after.nearest;
    EXPECT_NEAR(contrast.after.own, contrast.distanceAfter, 1e-12);
    EXPECT_NEAR(contrast.before.own, plain.distanceBefore, 1e-12);
    // Its figures are those `compare` measures on the same render.
    const auto contrastFile = (dir_ / "contrast.toml").string();
    std::ofstream(contrastFile) << contrast.presetText;
    const auto r2 = renderForComparison(contrastFile, plainOptions.spec);
    EXPECT_NEAR(compareAudio(contrastFile, r2, others_).comparison.distance, contrast.after.nearest,
                1e-9);
    EXPECT_NEAR(compareAudio(contrastFile, r2, own_).comparison.distance, contrast.after.own, 1e-9);
    // Provenance names the nearest other material before and after.
    const auto root = toml::parse(contrast.presetText);
    const auto* c = root["provenance"]["contrast"].as_table();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ((*c)["nearest_other_after"].value<std::string>().value_or(""), "slate");
    EXPECT_DOUBLE_EQ((*c)["contrast"].value<double>().value_or(0), 2.0);
    EXPECT_DOUBLE_EQ((*c)["margin"].value<double>().value_or(0), 0.1);
    EXPECT_NEAR((*c)["nearest_other_distance_after"].value<double>().value_or(-1),
                contrast.after.nearest, 6e-4);
    EXPECT_EQ(plain.presetText.find("[provenance.contrast]"), std::string::npos);
    // Deterministic: same input and seed, same preset text.
    const auto again = fitSurface(preset_, own_, options(2.0));
    EXPECT_EQ(again.presetText, contrast.presetText);
}

TEST_F(FitContrast, KeptKnobsStayAndUnknownOnesAreNamed) {
    auto o = options(2.0);
    o.maxEvaluations = 8;
    o.keep = {"grain_band"};
    const auto r = fitSurface(preset_, own_, o);
    for (const auto& k : r.knobs) EXPECT_NE(k.name, "grain_band");
    const auto root = toml::parse(r.presetText);
    EXPECT_DOUBLE_EQ(root["layer"][0]["freq_min_hz"].value<double>().value_or(0), 600.0);
    EXPECT_DOUBLE_EQ(root["layer"][0]["freq_max_hz"].value<double>().value_or(0), 2400.0);
    EXPECT_EQ(root["provenance"]["knobs_kept"][0].value<std::string>().value_or(""), "grain_band");
    o.keep = {"grain_bandwidth"};
    try {
        fitSurface(preset_, own_, o);
        ADD_FAILURE() << "an unknown knob was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("grain_bandwidth"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("grain_q"), std::string::npos) << e.what();
    }
}

// Several starts (FitOptions::starts, `underfoot fit --starts N`): the preset's own knobs and
// N - 1 Sobol points of the knob box, each refined by BOBYQA; the best result is kept.
TEST(FitStarts, ThePresetThenSobolPointsInsideTheBox) {
    const std::vector<double> lo{-1.5, -2, -2, -12}, hi{1.5, 2, 1, 12};
    const auto one = fitStartPoints(1, lo, hi);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0], std::vector<double>(4, 0.0));
    const auto p = fitStartPoints(9, lo, hi);
    ASSERT_EQ(p.size(), 9u);
    EXPECT_EQ(p[0], std::vector<double>(4, 0.0));
    EXPECT_EQ(p[1], (std::vector<double>{0.0, 0.0, -0.5, 0.0})); // Sobol's first: the centre
    for (std::size_t i = 1; i < p.size(); ++i)
        for (std::size_t k = 0; k < lo.size(); ++k) {
            EXPECT_GE(p[i][k], lo[k]);
            EXPECT_LT(p[i][k], hi[k]);
            for (std::size_t j = 1; j < i; ++j) EXPECT_NE(p[i], p[j]);
        }
    // Each coordinate of the first 7 Sobol points (with the sequence's origin, a (0, 3, s)-net)
    // falls in a different eighth of its range: the points spread over the whole box.
    for (std::size_t k = 0; k < lo.size(); ++k) {
        std::vector<int> cells(8, 0);
        for (std::size_t i = 1; i < 8; ++i)
            ++cells[static_cast<std::size_t>((p[i][k] - lo[k]) / (hi[k] - lo[k]) * 8)];
        EXPECT_EQ(cells, (std::vector<int>{0, 1, 1, 1, 1, 1, 1, 1})) << "knob " << k;
    }
    EXPECT_EQ(fitStartPoints(9, lo, hi), p); // a fixed set
    EXPECT_THROW(fitStartPoints(0, lo, hi), std::invalid_argument);
    EXPECT_THROW(fitStartPoints(3, {0.5}, {1.0}), std::invalid_argument); // 0 outside the box
}

TEST_F(FitContrast, SeveralStartsAreDeterministicAndNoWorseThanOne) {
    auto o = options(2.0);
    o.maxEvaluations = 10;
    const auto single = fitSurface(preset_, own_, o);
    EXPECT_EQ(single.startPoints, 1);
    EXPECT_EQ(single.presetText.find("[provenance.starts]"), std::string::npos);
    o.starts = 3;
    const auto multi = fitSurface(preset_, own_, o);
    ASSERT_EQ(multi.startObjectives.size(), 3u);
    ASSERT_EQ(single.startObjectives.size(), 1u);
    EXPECT_LE(multi.evaluations, 30);
    EXPECT_GT(multi.evaluations, single.evaluations);
    // The first start is the single fit: the best of three is no worse.
    EXPECT_EQ(multi.startObjectives[0], single.startObjectives[0]);
    const auto bestIt =
        std::min_element(multi.startObjectives.begin(), multi.startObjectives.end());
    EXPECT_LE(*bestIt, single.startObjectives[0]);
    EXPECT_EQ(bestIt - multi.startObjectives.begin(), multi.bestStartPoint);
    const auto root = toml::parse(multi.presetText);
    EXPECT_EQ(root["provenance"]["starts"]["points"].value<std::int64_t>().value_or(0), 3);
    EXPECT_EQ(root["provenance"]["starts"]["best"].value<std::int64_t>().value_or(-1),
              multi.bestStartPoint);
    // Same preset text twice: the same fitted preset.
    EXPECT_EQ(fitSurface(preset_, own_, o).presetText, multi.presetText);
}

// Several render seeds (FitOptions::seeds, `underfoot fit --seeds 3,7,8,11`): every evaluation
// renders once per seed and the objective is the mean of the per-seed objectives, so a margin
// must hold for each realisation of the random surface, not only for one.
TEST_F(FitContrast, SeveralSeedsAverageThePerSeedObjectives) {
    recordOthers(grainsPreset(std::exp2(0.6))); // slate between the preset and clay
    auto o = options(2.0);
    o.maxEvaluations = 6;
    // One seed given is the single-seed fit with that seed, bit for bit.
    auto one = o;
    one.spec.seed = 5;
    auto listed = o;
    listed.seeds = {5};
    const auto single = fitSurface(preset_, own_, one);
    EXPECT_EQ(fitSurface(preset_, own_, listed).presetText, single.presetText);

    // Before any knob moves, the multi-seed figures are the means of the single-seed ones.
    std::vector<FitResult> per;
    for (std::uint64_t seed : {5u, 9u, 13u}) {
        auto s = o;
        s.seeds = {seed};
        s.maxEvaluations = 5; // (the "before" figures do not depend on the budget)
        per.push_back(fitSurface(preset_, own_, s));
    }
    auto multi = o;
    multi.seeds = {5, 9, 13};
    const auto m = fitSurface(preset_, own_, multi);
    double own = 0, nearest = 0, objective = 0, thinnest = -1e300;
    std::string thinnestMaterial;
    for (const auto& p : per) {
        own += p.before.own / 3;
        nearest += p.before.nearest / 3;
        objective += p.before.objective / 3;
        if (p.before.own - p.before.nearest > thinnest) {
            thinnest = p.before.own - p.before.nearest;
            thinnestMaterial = p.before.nearestMaterial;
        }
    }
    EXPECT_NE(per[0].before.own, per[1].before.own) << "the seeds render the same steps";
    EXPECT_NEAR(m.before.own, own, 1e-12);
    EXPECT_NEAR(m.before.nearest, nearest, 1e-12);
    EXPECT_NEAR(m.before.objective, objective, 1e-12);
    EXPECT_EQ(m.before.nearestMaterial, thinnestMaterial);
    EXPECT_LE(m.after.objective, m.before.objective + 1e-12); // BOBYQA starts at the preset
    // Provenance lists the seeds instead of one seed; same input, same preset.
    const auto root = toml::parse(m.presetText);
    const auto* seeds = root["provenance"]["seeds"].as_array();
    ASSERT_NE(seeds, nullptr);
    ASSERT_EQ(seeds->size(), 3u);
    EXPECT_EQ((*seeds)[1].value<std::int64_t>().value_or(0), 9);
    EXPECT_FALSE(root["provenance"]["seed"]);
    EXPECT_EQ(fitSurface(preset_, own_, multi).presetText, m.presetText);
    // A bound on the work an option can ask for.
    multi.seeds.assign(33, 1);
    EXPECT_THROW(fitSurface(preset_, own_, multi), std::invalid_argument);
}
