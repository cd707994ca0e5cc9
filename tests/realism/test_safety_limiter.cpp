// SPDX-License-Identifier: GPL-3.0-or-later
// The output safety limiter of the offline renderer and the live engine.
#include "engine/render/Renderer.h"
#include "engine/render/SafetyLimiter.h"
#include "engine/surfaces/Surface.h"
#include "tests/common/AllocationTrap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace underfoot::engine;

TEST(SafetyLimiter, PassesQuietSignalsBitForBit) {
    std::mt19937 g(1);
    std::uniform_real_distribution<float> u(-0.96f, 0.96f); // below -0.3 dBFS (0.9661)
    std::vector<float> l(4800), r(4800);
    for (auto& v : l) v = u(g);
    for (auto& v : r) v = u(g);
    auto l0 = l, r0 = r;
    SafetyLimiter lim;
    lim.prepare(48000);
    lim.process(l.data(), r.data(), 4800);
    EXPECT_EQ(l, l0);
    EXPECT_EQ(r, r0);
    EXPECT_FALSE(lim.report().acted());
}

TEST(SafetyLimiter, NeverExceedsTheCeilingAndReportsWhenItActs) {
    SafetyLimiter lim;
    lim.prepare(48000, -0.3, 0.05);
    const float ceiling = static_cast<float>(std::pow(10.0, -0.3 / 20));
    std::vector<float> l(48000), r(48000);
    for (std::size_t i = 0; i < l.size(); ++i) {
        const double t = double(i) / 48000;
        // a 1.6x (+4 dB) burst in the middle of a 0.5 amplitude tone
        const double a = (t > 0.3 && t < 0.35) ? 1.6 : 0.5;
        l[i] = static_cast<float>(a * std::sin(2 * std::numbers::pi * 440 * t));
        r[i] = -l[i];
    }
    {
        underfoot::test::AllocationTrap trap;
        for (std::size_t s = 0; s < l.size(); s += 64) lim.process(l.data() + s, r.data() + s, 64);
        EXPECT_EQ(trap.count(), 0) << "the limiter allocated on the audio thread";
    }
    float peak = 0;
    for (std::size_t i = 0; i < l.size(); ++i)
        peak = std::max({peak, std::fabs(l[i]), std::fabs(r[i])});
    EXPECT_LE(peak, ceiling);
    EXPECT_TRUE(lim.report().acted());
    EXPECT_NEAR(lim.report().maxReductionDb, 20 * std::log10(1.6) + 0.3, 0.05);
    // Before the burst the tone passed untouched; 0.5 s after it the gain is back to 1.
    EXPECT_FLOAT_EQ(
        l[1000], static_cast<float>(0.5 * std::sin(2 * std::numbers::pi * 440 * 1000.0 / 48000)));
    const std::size_t late = 44000;
    EXPECT_NEAR(l[late], 0.5 * std::sin(2 * std::numbers::pi * 440 * double(late) / 48000), 1e-5);
}

TEST(SafetyLimiter, RenderReportsNothingForADefaultSurface) {
    WalkerParameters w;
    const auto grf = walkerGrf(w, 2.0, 48000, 3);
    RenderOptions o;
    o.seed = 3;
    const auto r = renderSurface("wood", grf, o);
    EXPECT_FALSE(r.limiter.acted());
}

// Headroom of every bundled surface: a 70 kg walker at both ends of the documented cadence range
// (60-150 steps/min), soft and hard shoes, several seeds: the limiter never has to act (peaks stay
// below -0.3 dBFS). Heavier walkers (up to 200 kg) may reach the limiter; it then reports it.
TEST(SafetyLimiter, NoDefaultRenderReachesTheLimiter) {
    int renders = 0;
    for (const auto& info : listSurfaces())
        for (const char* walker : {"cadence=60,shoe=1", "cadence=150,shoe=0"})
            for (std::uint64_t seed : {1u, 2u}) {
                const auto grf = walkerGrf(WalkerParameters::parse(walker), 2.5, 48000, seed);
                RenderOptions o;
                o.seed = seed;
                o.tailSeconds = 0.5;
                const auto r = renderSurface(info.id, grf, o);
                EXPECT_FALSE(r.limiter.acted())
                    << info.id << " " << walker << " seed " << seed << ": "
                    << r.limiter.maxReductionDb << " dB of limiting";
                ++renders;
            }
    EXPECT_GE(renders, 4 * 18);
}
