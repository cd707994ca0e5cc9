// SPDX-License-Identifier: GPL-3.0-or-later
// The "friction" layer's preset reader and its GRF drive (engine/surfaces/FrictionDrive.h), which
// the layer and tests/bench/bench_friction.cpp share.
#include "engine/dsp/ProcessSpec.h"
#include "engine/surfaces/FrictionDrive.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

FrictionLayerSettings readTable(const std::string& text) {
    const toml::table t = toml::parse(text);
    PresetReader reader("test.toml", t, "layer[0]", nullptr);
    auto s = readFrictionLayer(reader, AccuracyOptions{});
    reader.finish();
    return s;
}

// Every key with a value of its own, so that a key read into the wrong field shows.
const char* kAllKeys = R"(
sigma0 = 3e5
sigma1 = 120.0
sigma2 = 0.3
sigma3 = 0.4
static_coefficient = 0.5
dynamic_coefficient = 0.2
stribeck_velocity = 0.03
break_away = 0.65
rubbing_mass_kg = 0.025
normal_fraction = 0.12
drive_stiffness = 4e5
drive_damping = 3.0
slip_m_per_s_per_kn_per_s = 0.007
slip_threshold_n_per_s = 900.0
gain_db = -12.0
settle_after_s = 1.5
settle_tau_s = 0.25
modes = [
  { freq_hz = 300, t60_s = 0.06, mass_kg = 0.05, gain = 1.0 },
  { freq_hz = 700, t60_s = 0.05, mass_kg = 0.04, gain = 0.8 },
]
)";

// The model and its drive, configured from kAllKeys.
struct Rig {
    FrictionLayerSettings s = readTable(kAllKeys);
    ElastoPlasticFriction f;
    FrictionDrive d;
    FrictionDrive::Input in{};
    Rig() {
        f.configure(s.model, s.modes, {s.gains});
        f.prepare(kFs);
        f.reset(3);
        d.configure(s.drive);
        d.prepare(kFs);
        d.reset();
    }
    /// One GRF sample through the drive and, when it runs, the model.
    bool step(double load) {
        if (!d.next(static_cast<float>(load), f, in)) return false;
        d.settle(f.processSample(in.normal, 0.0, in.anchor, in.anchorVelocity, in.roughness), in,
                 f);
        return true;
    }
};
} // namespace

TEST(FrictionDrive, ReaderPutsEveryKeyInItsField) {
    const auto s = readTable(kAllKeys);
    EXPECT_EQ(s.model.sigma0, 3e5);
    EXPECT_EQ(s.model.sigma1, 120.0);
    EXPECT_EQ(s.model.sigma2, 0.3);
    EXPECT_EQ(s.model.sigma3, 0.4);
    EXPECT_EQ(s.model.staticCoefficient, 0.5);
    EXPECT_EQ(s.model.dynamicCoefficient, 0.2);
    EXPECT_EQ(s.model.stribeckVelocity, 0.03);
    EXPECT_EQ(s.model.breakAway, 0.65);
    EXPECT_EQ(s.model.exciterMassKg, 0.025);
    EXPECT_EQ(s.model.driveStiffness, 4e5);
    EXPECT_EQ(s.model.driveDamping, 3.0);
    EXPECT_EQ(s.drive.normalFraction, 0.12);
    EXPECT_EQ(s.drive.slipPerRate, 0.007);
    EXPECT_EQ(s.drive.threshold, 900.0);
    EXPECT_DOUBLE_EQ(s.gain, dbToGain(-12.0));
    EXPECT_DOUBLE_EQ(s.drive.sleepVelocity, 1e-6 / dbToGain(-12.0)); // -120 dBFS at the output
    EXPECT_EQ(s.drive.settling.afterS, 1.5);
    EXPECT_EQ(s.drive.settling.tauS, 0.25);
    ASSERT_EQ(s.modes.size(), 2u);
    EXPECT_EQ(s.modes[1].frequencyHz, 700.0);
    EXPECT_EQ(s.gains[1], 0.8);
}

TEST(FrictionDrive, ReaderRejectsFrictionLawsThatCannotHold) {
    std::string text = kAllKeys;
    text.replace(text.find("dynamic_coefficient = 0.2"), 25, "dynamic_coefficient = 0.7");
    try {
        readTable(text);
        FAIL() << "mu_d > mu_s was accepted";
    } catch (const PresetError& e) {
        EXPECT_NE(std::string(e.what()).find("dynamic_coefficient"), std::string::npos) << e.what();
    }
}

TEST(FrictionDrive, ShearsOnlyWhileTheLoadChangesFasterThanTheThreshold) {
    Rig r;
    // Nobody on the boards: nothing changes, nothing is solved.
    for (int i = 0; i < 4800; ++i) EXPECT_FALSE(r.step(0.0)) << i;
    EXPECT_TRUE(r.d.isSleeping());

    // Loading at 3 kN/s for 0.2 s: once the 5 ms smoothing has settled, the anchor moves at
    // (3000 - 900) N/s * 0.007 (m/s)/(kN/s) = 14.7 mm/s and the normal force is 12 % of the load.
    const double rate = 3000.0;
    double load = 0.0, anchorBefore = 0.0;
    int solved = 0;
    for (int i = 0; i < 9600; ++i) {
        load += rate / kFs;
        anchorBefore = r.in.anchor;
        solved += r.step(load) ? 1 : 0;
    }
    // The smoothed rate rises from 0 towards 3 kN/s: it passes 900 N/s after 1.8 ms (86 samples),
    // and from then on every sample is solved.
    EXPECT_GT(solved, 9600 - 96);
    EXPECT_LT(solved, 9600 - 80);
    EXPECT_FALSE(r.in.unloaded);
    // (within 0.1 %: the GRF is a float signal, whose rounding jitters the load's rate)
    EXPECT_NEAR(r.in.anchorVelocity, (rate - 900.0) * 1e-3 * 0.007, 1e-3 * 0.0147);
    EXPECT_NEAR(r.in.anchor - anchorBefore, r.in.anchorVelocity / kFs, 1e-12);
    // (the float GRF sample: the load is rounded to float before the drive reads it)
    EXPECT_NEAR(r.in.normal, 0.12 * load, 0.12 * load * 1e-6);
    EXPECT_FALSE(r.d.isSleeping());
    EXPECT_EQ(r.in.roughness, 1.0);

    // Holding the load: no more shear. The boards' roughness keeps rubbing for settle_after_s
    // (1.5 s), then fades with settle_tau_s (0.25 s); the boards ring out and fall asleep (50 ms
    // of quiet after the output has dropped below -120 dBFS), and from then on nothing is
    // solved.
    int lastSolved = -1;
    double roughnessAt1s = -1.0, roughnessAt2s = -1.0;
    for (int i = 0; i < 10 * 48000; ++i) {
        if (!r.step(load)) continue;
        lastSolved = i;
        EXPECT_LE(r.in.anchorVelocity, 0.0148);
        if (i == 48000) roughnessAt1s = r.in.roughness;
        if (i == 96000) roughnessAt2s = r.in.roughness;
    }
    EXPECT_EQ(roughnessAt1s, 1.0);
    // 2 s: 0.5 s less the ~6 ms the smoothed rate took to fall below the threshold into the fade
    EXPECT_NEAR(roughnessAt2s, std::exp(-0.5 / 0.25), 0.1);
    // The roughness keeps the output above -120 dBFS through the hold and the first of the fade
    // (it drives the boards at about -90 dBFS); asleep well before the roughness is cut.
    EXPECT_GT(lastSolved, 2 * 48000);
    EXPECT_LT(lastSolved, 5 * 48000);
    EXPECT_TRUE(r.d.isSleeping());
}

TEST(FrictionDrive, LiftingTheFootRelaxesTheContact) {
    Rig r;
    double load = 0.0;
    for (int i = 0; i < 4800; ++i) { // loading at 10 kN/s: the boards shear and stick-slip
        load += 10000.0 / kFs;
        r.step(load);
    }
    ASSERT_NE(r.f.bristle(), 0.0);
    ASSERT_NE(r.f.frictionForce(), 0.0);
    const double exciter = r.f.exciterPosition();
    // The foot leaves at once: the load's rate is far past the threshold, so the sample is
    // solved, unloaded: the model was relaxed and the drag re-anchored at the rubbing mass.
    ASSERT_TRUE(r.d.next(0.0f, r.f, r.in));
    EXPECT_TRUE(r.in.unloaded);
    EXPECT_EQ(r.in.normal, 0.0);
    EXPECT_EQ(r.f.bristle(), 0.0);
    EXPECT_EQ(r.f.frictionForce(), 0.0);
    EXPECT_EQ(r.f.exciterVelocity(), 0.0);
    EXPECT_EQ(r.in.anchor, exciter);
}
