// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/Biquad.h"
#include "engine/dsp/Denormals.h"
#include "engine/dsp/Envelope.h"
#include "engine/dsp/Random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::engine;

TEST(Butterworth, LowpassIsMinus3dBAtCutoffForEveryOrder) {
    for (int order = 1; order <= 8; ++order) {
        Butterworth f;
        f.design(FilterType::Lowpass, order, 48000.0, 1000.0);
        EXPECT_NEAR(20 * std::log10(f.magnitudeAt(48000.0, 1000.0)), -3.0103, 1e-3) << order;
        EXPECT_NEAR(f.magnitudeAt(48000.0, 1.0), 1.0, 1e-6) << order;
        // Roll-off of 6 dB per octave per order, well above cutoff (bilinear adds more near
        // Nyquist).
        const double atFourOctaves = 20 * std::log10(f.magnitudeAt(48000.0, 16000.0));
        EXPECT_LT(atFourOctaves, -24.0 * order + 3.0) << order;
    }
}

TEST(Butterworth, MeasuredSineGainMatchesDesign) {
    Butterworth f;
    f.design(FilterType::Highpass, 2, 48000.0, 200.0);
    const double freq = 100.0;
    double peak = 0;
    for (int n = 0; n < 48000; ++n) {
        const double y = f.processSample(std::sin(kTwoPi * freq * n / 48000.0));
        if (n > 24000) peak = std::max(peak, std::fabs(y));
    }
    EXPECT_NEAR(peak, f.magnitudeAt(48000.0, freq), 2e-3);
}

TEST(Butterworth, RejectsCutoffAtOrAboveNyquist) {
    Butterworth f;
    EXPECT_THROW(f.design(FilterType::Lowpass, 2, 48000.0, 24000.0), std::invalid_argument);
    EXPECT_THROW(f.design(FilterType::Lowpass, 0, 48000.0, 100.0), std::invalid_argument);
}

TEST(EnvelopeFollower, ReachesNinetyNinePercentInTheReleaseTime) {
    const double fs = 1000.0;
    EnvelopeFollower env;
    env.setTimesMs(0.0, 890.0, fs);
    env.reset();
    EXPECT_DOUBLE_EQ(env.processSample(1.0), 1.0); // attack 0 ms: instantaneous
    int n = 0;
    while (env.processSample(0.0) > 0.01) ++n;
    EXPECT_NEAR(n + 1, 890, 1);
}

TEST(EnvelopeFollower, CookCoefficientsFollowRiseFasterThanFall) {
    EnvelopeFollower env;
    env.setCoefficients(0.8, 0.999);
    double e = 0;
    for (int i = 0; i < 20; ++i) e = env.processSample(1.0);
    EXPECT_GT(e, 0.98);
    for (int i = 0; i < 20; ++i) e = env.processSample(0.0);
    EXPECT_GT(e, 0.96); // 0.988 * 0.999^20
}

TEST(Random, SameSeedSameSequenceDifferentSeedDifferent) {
    Random a(7), b(7), c(8);
    for (int i = 0; i < 1000; ++i) {
        const auto va = a.next();
        EXPECT_EQ(va, b.next());
        (void)c.next();
    }
    Random d(7), e(8);
    int same = 0;
    for (int i = 0; i < 100; ++i) same += d.next() == e.next();
    EXPECT_EQ(same, 0);
}

TEST(Random, StoredSeedsReplayTheSameDraws) {
    // Pinned outputs (a stored render seed must give the same samples after any change to the
    // code), computed with the engine's own xoshiro256** before it moved to base/Xoshiro.h: a
    // program printing these draws, compiled with g++ -O2 against engine/dsp/Random.h of that
    // commit. The experiment's generator gives the same next() for seed 7
    // (tests/experiment/test_random.cpp).
    Random a(7);
    EXPECT_EQ(a.next(), 0xb358faf74ef9765aull);
    EXPECT_EQ(a.next(), 0x475c3d964f482cd2ull);
    EXPECT_EQ(a.next(), 0xd6f1d349952c7996ull);
    EXPECT_EQ(Random::deriveSeed(1, 2), 0x6d1db36ccba982d2ull);
    Random b(12345);
    EXPECT_EQ(b.below(7), 5u);
    EXPECT_EQ(b.below(7), 0u);
    EXPECT_EQ(b.below(7), 6u);
    Random c(99);
    EXPECT_EQ(c.uniform(), 0.34870385642514956);
    EXPECT_DOUBLE_EQ(c.gaussian(), -0.92932055252163526); // through libm log and cos
    EXPECT_DOUBLE_EQ(c.powerLaw(-1.5, 0.1, 10.0), 1.8914317062956854);
}

TEST(Random, PowerLawAndExponentialHaveTheRightMeans) {
    Random r(1);
    const int n = 200000;
    double sumExp = 0, sumPow = 0;
    for (int i = 0; i < n; ++i) {
        sumExp += r.exponential(4.0);
        sumPow += r.powerLaw(-2.0, 1.0, 10.0);
    }
    EXPECT_NEAR(sumExp / n, 0.25, 0.005);
    // E[x] for p(x) ~ x^-2 on [1,10]: ln(10) / (1 - 1/10)
    EXPECT_NEAR(sumPow / n, std::log(10.0) / 0.9, 0.02);
}

TEST(Denormals, GuardFlushesAndRestores) {
    {
        ScopedFlushDenormals guard;
        EXPECT_TRUE(ScopedFlushDenormals::active());
    }
    EXPECT_FALSE(ScopedFlushDenormals::active());
}
