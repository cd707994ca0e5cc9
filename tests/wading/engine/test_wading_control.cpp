// SPDX-License-Identifier: GPL-3.0-or-later
// The control chains against an independent, straightforward implementation written from the
// paper's equations (seed 004: §3.3 Butterworth 2nd order + 0..100 deg/s normalisation + L+R sum;
// §6.1 eqs. (1)-(6) envelope follower and x^k; §6.2 C1-C3, delays, fader ranges). The reference
// designs the Butterworth low-pass from the analogue prototype by the bilinear transform with
// pre-warping, runs it in direct form I, and calls nothing from the engine but the gait sources.
#include "engine/control/GyroBlocks.h"
#include "engine/wading/Gait.h"
#include "engine/wading/WadingControl.h"
#include "tests/wading/engine/WadingReference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>

namespace {
using namespace underfoot::engine;
using namespace underfoot::test::wading;

void expectChainMatches(const std::vector<GaitFrame>& input, const char* what,
                        GyroFilter filter = GyroFilter::Butterworth5Hz) {
    WadingControl chain;
    chain.configure(WadingAlgorithm::V2, filter, WadingMapping{});
    RefV2 ref = filter == GyroFilter::Butterworth5Hz
                    ? RefV2()
                    : RefV2(5, 0.8, 1, kSlowFilterMakeUpGain); // asymmetric: right 0.8 Hz
    double maxC = 0;
    for (std::size_t k = 0; k < input.size(); ++k) {
        const auto& c = chain.push(input[k]);
        const auto r = ref.step(input[k]);
        ASSERT_NEAR(c.c1, r[0], 1e-9) << what << " frame " << k;
        ASSERT_NEAR(c.c2, r[1], 1e-9) << what << " frame " << k;
        ASSERT_NEAR(c.c3, r[2], 1e-9) << what << " frame " << k;
        for (int layer = 0; layer < 3; ++layer)
            for (int side = 0; side < 2; ++side)
                ASSERT_NEAR(c.gain[static_cast<std::size_t>(layer)][static_cast<std::size_t>(side)],
                            r[static_cast<std::size_t>(3 + 2 * layer + side)], 1e-9)
                    << what << " frame " << k << " layer " << layer << " side " << side;
        ASSERT_NEAR(c.eqDb, 9.0 * r[0], 1e-8) << what << " frame " << k;
        maxC = std::max({maxC, c.c1, c.c2, c.c3});
    }
    EXPECT_GT(maxC, 0.5) << what << ": the input must exercise the chain";
}

std::vector<GaitFrame> frames(std::size_t count) {
    std::vector<GaitFrame> f(count);
    for (std::size_t k = 0; k < count; ++k) f[k].timeS = static_cast<double>(k) / 100.0;
    return f;
}

TEST(WadingControl, V2MatchesReferenceOnSteps) {
    auto in = frames(600);
    // Thigh steps at 0.5 s, shank steps at 1.0 s, both off at 2.0 s, left only again at 4 s.
    for (std::size_t k = 0; k < in.size(); ++k) {
        const double t = in[k].timeS;
        in[k][Limb::LeftThigh] = (t >= 0.5 && t < 2.0) ? 150 : (t >= 4 ? 80 : -20);
        in[k][Limb::RightThigh] = (t >= 0.5 && t < 2.0) ? 30 : 0;
        in[k][Limb::LeftShank] = (t >= 1.0 && t < 2.0) ? 250 : (t >= 4.5 ? 60 : 0);
        in[k][Limb::RightShank] = (t >= 1.0 && t < 2.0) ? -40 : 0;
    }
    expectChainMatches(in, "steps");
}

TEST(WadingControl, V2MatchesReferenceOnRamps) {
    auto in = frames(800);
    for (std::size_t k = 0; k < in.size(); ++k) {
        const double t = in[k].timeS;
        const double up = t < 4 ? 60.0 * t - 50 : 190 - 60.0 * (t - 4); // -50 .. 190 .. -50
        in[k][Limb::LeftThigh] = up;
        in[k][Limb::RightThigh] = 0.5 * up;
        in[k][Limb::LeftShank] = 1.5 * up;
        in[k][Limb::RightShank] = -up;
    }
    expectChainMatches(in, "ramps");
}

TEST(WadingControl, V2MatchesReferenceOnRecordedGait) {
    // A gait written to CSV and read back (the recorded-gait path), at a fast cadence.
    VirtualGaitParameters p;
    p.cadenceStepsPerMin = 118;
    const auto path = (std::filesystem::temp_directory_path() / "wading_ref_gait.csv").string();
    writeGaitCsv(path, virtualGait(p, 8.0, 3));
    const auto recorded = readGaitCsv(path);
    std::filesystem::remove(path);
    expectChainMatches(recorded, "recorded gait");
    expectChainMatches(recorded, "recorded gait, asymmetric filter", GyroFilter::Asymmetric);
}

TEST(WadingControl, V1IsFilteredNormalisedThighSum) {
    VirtualGaitParameters p;
    p.cadenceStepsPerMin = 63;
    const auto gait = virtualGait(p, 6.0, 5);
    WadingControl chain;
    chain.configure(WadingAlgorithm::V1, GyroFilter::Butterworth0_8Hz, WadingMapping{});
    RefLowpass l(100, 0.8, kSlowFilterMakeUpGain), r(100, 0.8, kSlowFilterMakeUpGain);
    double maxC = 0;
    for (const auto& f : gait) {
        const auto& c = chain.push(f);
        const double nl = norm100(l(f[Limb::LeftThigh])), nr = norm100(r(f[Limb::RightThigh]));
        const double ref = std::min(nl + nr, 1.0);
        ASSERT_NEAR(c.v1, ref, 1e-9);
        ASSERT_NEAR(c.bubbleRateScale, ref, 1e-9);
        // Overall gain linear in c, split in power between the limbs.
        ASSERT_NEAR(c.gain[0][0] * c.gain[0][0] + c.gain[0][1] * c.gain[0][1], ref * ref, 1e-9);
        ASSERT_EQ(c.gain[2][0], 0.0); // no splash layer in v1
        maxC = std::max(maxC, c.v1);
    }
    EXPECT_GT(maxC, 0.5);
}

TEST(WadingControl, SlowFilterMakeUpGainMatchesSwingPeaks) {
    // kSlowFilterMakeUpGain: ratio of the 5 Hz- to the 0.8 Hz-filtered thigh swing peak for the
    // virtual gait at 63 steps/min (no variability; the ratio does not depend on the stride).
    // Recomputed here.
    VirtualGaitParameters p;
    p.cadenceStepsPerMin = 63;
    p.variability = 0;
    const auto gait = virtualGait(p, 20.0, 1);
    GyroLowpass fast, slow;
    fast.design(100, 5.0);
    slow.design(100, 0.8);
    double peakFast = 0, peakSlow = 0;
    for (std::size_t k = 0; k < gait.size(); ++k) {
        const double a = fast.processSample(gait[k][Limb::LeftThigh]);
        const double b = slow.processSample(gait[k][Limb::LeftThigh]);
        if (k > 500) peakFast = std::max(peakFast, a), peakSlow = std::max(peakSlow, b);
    }
    const double ratio = peakFast / peakSlow;
    std::printf("[ measured ] 5 Hz / 0.8 Hz swing peak ratio at 63 steps/min: %.3f\n", ratio);
    EXPECT_NEAR(kSlowFilterMakeUpGain, ratio, 0.1 * ratio);
}

TEST(WadingControl, RejectsNonFiniteReadingsAndHolds) {
    WadingControl chain;
    chain.configure(WadingAlgorithm::V2, GyroFilter::Butterworth5Hz, WadingMapping{});
    GaitFrame f{};
    f.angularVelocityDps.fill(120);
    for (int i = 0; i < 50; ++i) chain.push(f);
    const double c1 = chain.controls().c1;
    GaitFrame bad = f;
    bad[Limb::LeftThigh] = std::nan("");
    bad[Limb::RightShank] = INFINITY;
    const auto& c = chain.push(bad);
    EXPECT_EQ(chain.rejectedReadings(), 2u);
    EXPECT_TRUE(std::isfinite(c.c1) && std::isfinite(c.c2) && std::isfinite(c.c3));
    EXPECT_NEAR(c.c1, c1, 1e-6); // held at the previous reading
}

TEST(GyroBlocks, BlocksFollowTheirDefinitions) {
    EXPECT_EQ(normaliseForward(-30), 0.0);
    EXPECT_DOUBLE_EQ(normaliseForward(42), 0.42);
    EXPECT_EQ(normaliseForward(250), 1.0);
    EXPECT_EQ(normaliseForward(std::nan("")), 0.0);
    EXPECT_EQ(sumClamped(0.7, 0.6), 1.0);
    EXPECT_DOUBLE_EQ(sumClamped(0.2, 0.3), 0.5);
    EXPECT_DOUBLE_EQ(powerShape(0.5, 2.56), std::pow(0.5, 2.56));
    EXPECT_EQ(powerShape(1.4, 2.0), 1.0);
    EXPECT_DOUBLE_EQ(faderDb(0.5, -40, 5), -17.5);
    // The follower reaches 99 % of a falling step in the release time (eq. 3): 890 ms = 89 frames.
    GyroEnvelope e;
    e.setTimesMs(0, 890, 100);
    e.processSample(1.0);
    EXPECT_EQ(e.value(), 1.0); // attack 0 ms: instantaneous
    for (int i = 0; i < 89; ++i) e.processSample(0.0);
    EXPECT_NEAR(e.value(), 0.01, 1e-9);
    ControlDelay d;
    d.prepare(0.150, 100);
    EXPECT_EQ(d.delaySamples(), 15);
    for (int i = 0; i < 15; ++i) EXPECT_EQ(d.processSample(1.0), 0.0);
    EXPECT_EQ(d.processSample(2.0), 1.0);
    ControlRamp r;
    r.setRampSamples(4);
    r.setTarget(1.0);
    EXPECT_DOUBLE_EQ(r.next(), 0.25);
    r.next(), r.next();
    EXPECT_EQ(r.next(), 1.0);
    EXPECT_EQ(r.next(), 1.0);
    // Butterworth group delay at DC: sqrt(2) / (2 pi fc) for the analogue prototype (45 ms at
    // 5 Hz); the bilinear design at 100 Hz is within a few per cent.
    GyroLowpass lp;
    lp.design(100, 5);
    EXPECT_NEAR(lp.groupDelaySeconds(100, 0), std::sqrt(2.0) / (2 * M_PI * 5), 0.003);
    EXPECT_THROW(lp.design(100, 60), std::invalid_argument);
}

} // namespace
