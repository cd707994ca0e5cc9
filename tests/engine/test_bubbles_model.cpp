// SPDX-License-Identifier: GPL-3.0-or-later
// van den Doel bubbles: measured frequency, decay, pitch rise and amplitude of one bubble against
// the formulas of van den Doel (2005); stream rate; determinism; bounds.
#include "engine/models/Bubbles.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <vector>

using namespace underfoot::engine;

#include "tests/common/AllocationTrap.h"

namespace {
constexpr double kFs = 48000.0;

BubbleStream makeStream(BubbleStreamParameters p = {}, double fs = kFs) {
    BubbleStream s;
    s.configure(p);
    s.prepare(fs, 100000);
    s.reset(3);
    return s;
}

std::vector<float> run(BubbleStream& s, double seconds, double rate, double fs = kFs) {
    const int n = static_cast<int>(seconds * fs);
    std::vector<float> out(static_cast<std::size_t>(n), 0.0f);
    std::vector<float> r(256, static_cast<float>(rate)), a(256, 1.0f);
    for (int done = 0; done < n; done += 256)
        s.process(r.data(), a.data(), out.data() + done, std::min(256, n - done));
    return out;
}

// Upward zero crossings (linearly interpolated), in seconds.
std::vector<double> upCrossings(const std::vector<float>& x, double fs) {
    std::vector<double> t;
    for (std::size_t i = 1; i < x.size(); ++i)
        if (x[i - 1] < 0 && x[i] >= 0)
            t.push_back((static_cast<double>(i - 1) + x[i - 1] / (x[i - 1] - x[i])) / fs);
    return t;
}

// Fits log|peak| of each half cycle against time: returns {slope, intercept}.
std::pair<double, double> decayFit(const std::vector<float>& x, double fs, double fromS,
                                   double toS) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (std::size_t i = 1; i + 1 < x.size(); ++i) {
        const double t = static_cast<double>(i) / fs;
        if (t < fromS || t > toS) continue;
        const double a = std::fabs(x[i]);
        if (a > std::fabs(x[i - 1]) && a >= std::fabs(x[i + 1]) && a > 1e-9) {
            // parabolic interpolation of the peak height
            const double y0 = std::fabs(x[i - 1]), y1 = a, y2 = std::fabs(x[i + 1]);
            const double den = y0 - 2 * y1 + y2;
            const double p = den != 0 ? 0.5 * (y0 - y2) / den : 0.0;
            const double peak = y1 - 0.25 * (y0 - y2) * p;
            const double tp = (static_cast<double>(i) + p) / fs;
            sx += tp;
            sy += std::log(peak);
            sxx += tp * tp;
            sxy += tp * std::log(peak);
            ++n;
        }
    }
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    return {slope, (sy - slope * sx) / n};
}
} // namespace

TEST(Bubbles, FormulasOfVanDenDoel) {
    // r = 3 mm: f0 = 1000 Hz, d = 0.13/0.003 + 0.0072 * 0.003^-1.5 = 43.333 + 43.818 = 87.15 /s
    EXPECT_NEAR(BubblePhysics::frequencyHz(3e-3), 1000.0, 1e-9);
    EXPECT_NEAR(BubblePhysics::dampingPerSecond(3e-3), 43.3333 + 43.8178, 1e-3);
    EXPECT_NEAR(BubblePhysics::amplitude(4e-3, 0.5), 0.5 * 8.0, 1e-12);
}

TEST(Bubbles, OneBubbleRingsAtF0AndDecaysAtD) {
    BubbleStreamParameters p;
    p.xi = 0.0; // no pitch rise: a pure damped sinusoid
    for (double radius : {1e-3, 3e-3, 8e-3}) {
        auto s = makeStream(p);
        s.triggerBubble(radius, 1.0);
        const auto x = run(s, 0.25, 0.0);
        const double f0 = 3.0 / radius, d = BubblePhysics::dampingPerSecond(radius);
        // Crossings while the bubble is loud (within 26 dB of its start: t < 3 / d); the voice
        // ends ~80 dB down, and its last sample to zero is no crossing of the sinusoid.
        const std::vector<float> loud(x.begin(), x.begin() + static_cast<long>(3.0 / d * kFs));
        const auto z = upCrossings(loud, kFs);
        ASSERT_GT(z.size(), 10u);
        const double measuredF = static_cast<double>(z.size() - 1) / (z.back() - z.front());
        EXPECT_NEAR(measuredF, f0, f0 * 1e-3) << "r = " << radius;
        // Fit over the first ~40 dB of decay.
        const auto [slope, intercept] = decayFit(x, kFs, 0.0005, std::min(0.2, 4.6 / d));
        EXPECT_NEAR(-slope, d, d * 0.02) << "r = " << radius;
        // Amplitude at t = 0: (r / 1 mm)^1.5 with depth 1.
        EXPECT_NEAR(std::exp(intercept), std::pow(radius / 1e-3, 1.5),
                    0.03 * std::pow(radius / 1e-3, 1.5))
            << "r = " << radius;
    }
}

TEST(Bubbles, PitchRisesAsF0TimesOnePlusXiDT) {
    BubbleStreamParameters p;
    p.xi = 0.1;
    const double radius = 4e-3; // f0 = 750 Hz, d = 32.5 + 28.46 = 60.96 /s
    auto s = makeStream(p);
    s.triggerBubble(radius, 1.0);
    const auto x = run(s, 0.15, 0.0);
    const double f0 = 750.0, d = BubblePhysics::dampingPerSecond(radius);
    const auto z = upCrossings(x, kFs);
    // Instantaneous frequency from consecutive crossings, compared to f0 (1 + xi d t) at the
    // midpoint (exact for a linear chirp).
    int checked = 0;
    for (std::size_t i = 1; i < z.size(); ++i) {
        const double f = 1.0 / (z[i] - z[i - 1]);
        const double mid = 0.5 * (z[i] + z[i - 1]);
        if (std::fabs(x[static_cast<std::size_t>(mid * kFs)]) < 1e-4) break; // too quiet to time
        EXPECT_NEAR(f, f0 * (1.0 + p.xi * d * mid), 0.5) << "t = " << mid;
        ++checked;
    }
    EXPECT_GT(checked, 80);
    // At 0.1 s the pitch has risen by xi d t = 61 % of ... 0.1 * 61 * 0.1 = 0.61 -> 6.1 %.
    EXPECT_GT(1.0 / (z[80] - z[79]), f0 * 1.04);
}

TEST(Bubbles, StreamRateAndRadiusRange) {
    BubbleStreamParameters p;
    p.radiusMinM = 1e-3;
    p.radiusMaxM = 6e-3;
    auto s = makeStream(p);
    run(s, 20.0, 300.0);
    EXPECT_NEAR(static_cast<double>(s.bubbleCount()), 6000.0, 4.0 * std::sqrt(6000.0));
    // Capped rate.
    BubbleStreamParameters q;
    q.maxRateHz = 200.0;
    auto capped = makeStream(q);
    run(capped, 10.0, 1e6);
    EXPECT_NEAR(static_cast<double>(capped.bubbleCount()), 2000.0, 4.0 * std::sqrt(2000.0));
}

TEST(Bubbles, RadiiBelowTheNyquistLimitAreRaisedAndPitchStopsBelowNyquist) {
    // At 22.05 kHz a 0.2 mm bubble (15 kHz) cannot ring: it is raised to 3 / (0.45 fs).
    BubbleStreamParameters p;
    p.radiusMinM = 0.1e-3;
    p.radiusMaxM = 0.3e-3;
    p.xi = 0.5;
    auto s = makeStream(p, 22050.0);
    EXPECT_NEAR(s.minimumRadiusM(), 3.0 / (0.45 * 22050.0), 1e-12);
    const auto x = run(s, 2.0, 500.0, 22050.0);
    for (float v : x) ASSERT_TRUE(std::isfinite(v));
    // Zero-crossing rate stays below 0.45 fs.
    const auto z = upCrossings(x, 22050.0);
    for (std::size_t i = 1; i < z.size(); ++i) ASSERT_GT(z[i] - z[i - 1], 1.0 / (0.5 * 22050.0));
}

TEST(Bubbles, DeterministicBoundedSilentAndAllocationFree) {
    BubbleStreamParameters p;
    auto a = makeStream(p), b = makeStream(p), c = makeStream(p);
    a.reset(9);
    b.reset(9);
    c.reset(10);
    const auto xa = run(a, 1.0, 400.0), xb = run(b, 1.0, 400.0), xc = run(c, 1.0, 400.0);
    EXPECT_EQ(xa, xb);
    EXPECT_NE(xa, xc);
    // Bounded by voices x the loudest bubble (r = 5 mm: 5^1.5 = 11.2).
    for (float v : xa) ASSERT_LE(std::fabs(v), static_cast<float>(p.voices) * 11.19f);
    // Silent at zero rate, and every bubble ends.
    const auto tail = run(a, 3.0, 0.0);
    EXPECT_TRUE(a.idle());
    for (std::size_t i = tail.size() - 100; i < tail.size(); ++i) ASSERT_EQ(tail[i], 0.0f);
    std::vector<float> rate(256, 800.0f), amp(256, 1.0f), out(256);
    underfoot::test::allocationCount = 0;
    underfoot::test::countAllocations = true;
    for (int i = 0; i < 400; ++i) a.process(rate.data(), amp.data(), out.data(), 256);
    underfoot::test::countAllocations = false;
    EXPECT_EQ(underfoot::test::allocationCount.load(), 0);
}
