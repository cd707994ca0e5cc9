// SPDX-License-Identifier: GPL-3.0-or-later
// "grains" and "bubbles" layers: GRF -> event-rate mapping, silence and sleep at zero GRF,
// bounded output over randomized sweeps of every declared parameter range, no allocation.
#include "engine/control/VirtualWalker.h"
#include "engine/surfaces/GranularLayers.h"
#include "engine/surfaces/LiquidLayers.h"
#include "engine/surfaces/Surface.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <map>
#include <string>
#include <vector>

using namespace underfoot::engine;

#include "tests/common/AllocationTrap.h"

namespace {
constexpr double kFs = 48000.0;

std::unique_ptr<Surface> surfaceWithLayer(const std::string& layerBody,
                                          const std::string& type = "grains") {
    const std::string text = fmt::format(R"(id = "test"
category = "aggregate"
description = "test"
[[layer]]
type = "{}"
purpose = "under test"
{}
)",
                                         type, layerBody);
    auto s = loadSurfaceFromString(text, "test.toml");
    s->prepare({kFs, 512});
    s->reset(5);
    return s;
}

std::vector<float> walkerGrf(double seconds, std::uint64_t seed = 7, double massKg = 70.0) {
    WalkerParameters p;
    p.massKg = massKg;
    VirtualWalker w(p);
    w.prepare({kFs, 512});
    w.reset(seed);
    std::vector<float> left(static_cast<std::size_t>(seconds * kFs)), right(left.size());
    w.process(left.data(), right.data(), static_cast<int>(left.size()));
    return left;
}

std::vector<float> render(Surface& s, const std::vector<float>& grf, int block = 512) {
    std::vector<float> out(grf.size());
    const int n = static_cast<int>(grf.size());
    for (int done = 0; done < n; done += block) {
        const int k = std::min(block, n - done);
        s.process(grf.data() + done, out.data() + done, k);
    }
    return out;
}

std::uint64_t events(const Surface& s) {
    return dynamic_cast<const GrainsLayer&>(s.layer(0)).model().eventCount();
}
} // namespace

TEST(GrainsLayer, StaticLoadRateFollowsTheGrf) {
    // (settle_after_s: the bed does not settle within the 20 s)
    auto s = surfaceWithLayer(
        "events_per_s_per_kn = 500.0\nmax_rate_hz = 20000.0\nsettle_after_s = 3600.0");
    // 800 N held for 20 s: 400 events/s -> 8000 events (the initial step adds rise events: none
    // with events_per_kn_rise = 0).
    std::vector<float> grf(static_cast<std::size_t>(20 * kFs), 800.0f);
    render(*s, grf);
    EXPECT_NEAR(static_cast<double>(events(*s)), 8000.0, 4.0 * std::sqrt(8000.0));
}

TEST(GrainsLayer, AHeldLoadSettlesAndAShiftOfTheWeightWakesTheBed) {
    // Default settling: 2 s at the full 400 events/s, then a fade of 0.5 s time constant, so
    // 400 x (2 + 0.5) = 1000 events in all, none after ~7 s.
    auto s = surfaceWithLayer("events_per_s_per_kn = 500.0\nmax_rate_hz = 20000.0");
    std::vector<float> grf(static_cast<std::size_t>(10 * kFs), 800.0f);
    render(*s, grf);
    const auto settled = events(*s);
    EXPECT_NEAR(static_cast<double>(settled), 1000.0, 4.0 * std::sqrt(1000.0));
    auto out = render(*s, grf); // 10 s more standing: not one event, silence
    EXPECT_EQ(events(*s), settled);
    for (float v : out) ASSERT_EQ(v, 0.0f);
    // The weight shifts (800 -> 400 N in 0.2 s, 2 kN/s) and stays: the events are back at once,
    // 300 /s over the shift (600 N on average) and then at the lower load's rate for 2 s and the
    // fade: 60 + 200 x 2.5 = 560 more.
    std::vector<float> shift(static_cast<std::size_t>(10 * kFs), 400.0f);
    for (std::size_t i = 0; i < static_cast<std::size_t>(0.2 * kFs); ++i)
        shift[i] = static_cast<float>(800.0 - 400.0 * static_cast<double>(i) / (0.2 * kFs));
    render(*s, shift);
    EXPECT_NEAR(static_cast<double>(events(*s) - settled), 560.0, 4.0 * std::sqrt(560.0));
}

TEST(GrainsLayer, LoadChangesGiveEventsPerKilonewton) {
    // A slow triangle 0 -> 1000 N -> 0 over 2 s repeated 10 times: 10 kN of rise and 10 kN of
    // fall; with 300 events per kN rise and 100 per kN fall: 3000 + 1000 events.
    auto s = surfaceWithLayer("events_per_kn_rise = 300.0\nevents_per_kn_fall = 100.0");
    std::vector<float> grf(static_cast<std::size_t>(20 * kFs));
    for (std::size_t i = 0; i < grf.size(); ++i) {
        const double phase = std::fmod(static_cast<double>(i) / kFs, 2.0);
        grf[i] = static_cast<float>(1000.0 * (phase < 1.0 ? phase : 2.0 - phase));
    }
    render(*s, grf);
    EXPECT_NEAR(static_cast<double>(events(*s)), 4000.0, 4.0 * std::sqrt(4000.0));
}

TEST(GrainsLayer, SilentAndSleepingWhenTheGrfIsZero) {
    auto s = surfaceWithLayer("events_per_kn_rise = 300.0\nevents_per_s_per_kn = 200.0\n"
                              "onset_energy = 1.0\nlowpass_hz = 3000.0");
    std::vector<float> zero(static_cast<std::size_t>(kFs), 0.0f);
    auto out = render(*s, zero);
    for (float v : out) ASSERT_EQ(v, 0.0f);
    EXPECT_TRUE(s->isSleeping());
    EXPECT_EQ(events(*s), 0u);
    // A step wakes it; when the foot is off the ground again it falls silent and sleeps.
    auto step = walkerGrf(0.8);
    out = render(*s, step);
    EXPECT_FALSE(s->isSleeping() && events(*s) == 0);
    double energy = 0;
    for (float v : out) energy += static_cast<double>(v) * v;
    EXPECT_GT(energy, 0.0);
    out = render(*s, zero);
    EXPECT_TRUE(s->isSleeping());
    for (std::size_t i = out.size() / 2; i < out.size(); ++i) ASSERT_EQ(out[i], 0.0f);
    // NaN, Inf and negative GRF samples read as "no contact".
    std::vector<float> bad(4800, std::nanf(""));
    for (std::size_t i = 0; i < bad.size(); i += 3) bad[i] = -50.0f;
    bad[7] = INFINITY;
    out = render(*s, bad);
    for (float v : out) ASSERT_TRUE(std::isfinite(v));
}

TEST(GrainsLayer, OnsetEventFiresOncePerStep) {
    auto s = surfaceWithLayer("onset_energy = 1.0\nonset_force_n = 200.0\nresonances = 1\n"
                              "freq_min_hz = 80.0\nfreq_max_hz = 120.0");
    auto grf = walkerGrf(6.0); // 100 steps/min: one foot lands every 1.2 s -> 5 landings
    render(*s, grf);
    EXPECT_EQ(events(*s), 5u);
}

namespace {
// Draws every numeric parameter a layer declares, uniformly (or log-uniformly) in its range.
std::string randomLayerBody(const std::vector<ParamInfo>& params, Random& random,
                            std::map<std::string, double>& drawn) {
    std::string body;
    for (const auto& p : params) {
        const auto dot = p.path.rfind('.');
        if (dot == std::string::npos || p.path.rfind("layer[1]", 0) != 0) continue;
        const std::string key = p.path.substr(dot + 1);
        double v;
        if (p.logScale && p.minValue > 0)
            v = p.minValue * std::pow(p.maxValue / p.minValue, random.uniform());
        else
            v = random.uniform(p.minValue, p.maxValue);
        drawn[key] = v;
        body += fmt::format("{} = {:.17g}\n", key, v);
    }
    return body;
}

// The largest load (kN) and the largest rise and fall rates (kN/s) of a GRF.
struct GrfExtremes {
    double maxKn = 0, maxRise = 0, maxSpeed = 0;
};
GrfExtremes extremes(const std::vector<float>& grf) {
    GrfExtremes e;
    double prev = 0;
    for (float f : grf) {
        const double v = std::max(0.0, static_cast<double>(f));
        e.maxKn = std::max(e.maxKn, v * 1e-3);
        e.maxRise = std::max(e.maxRise, (v - prev) * kFs * 1e-3);
        e.maxSpeed = std::max(e.maxSpeed, std::fabs(v - prev) * kFs * 1e-3);
        prev = v;
    }
    return e;
}

std::vector<float> hardGrf() {
    // Abrupt steps to 1500 N and back, with a fast wobble: far harsher than any walker.
    std::vector<float> g(static_cast<std::size_t>(3 * kFs));
    for (std::size_t i = 0; i < g.size(); ++i) {
        const double t = static_cast<double>(i) / kFs;
        const bool on = std::fmod(t, 0.6) < 0.35;
        g[i] = on ? static_cast<float>(1200.0 + 300.0 * std::sin(6.283 * 40.0 * t)) : 0.0f;
    }
    return g;
}
} // namespace

TEST(GrainsLayer, RandomizedSweepsWithinDeclaredRangesStayFiniteAndBounded) {
    // The declared ranges: read them from the layer itself (PresetReader records each one).
    const auto probe = surfaceWithLayer("");
    const auto params = probe->parameters();
    ASSERT_GE(params.size(), 20u);
    Random random(2024);
    const std::vector<std::vector<float>> grfs = {walkerGrf(3.0, 3, 120.0), hardGrf()};
    for (int trial = 0; trial < 40; ++trial) {
        std::map<std::string, double> v;
        std::string body = randomLayerBody(params, random, v);
        const int resonances = 1 + static_cast<int>(random.below(4));
        const int voices = 1 + static_cast<int>(random.below(256));
        body += fmt::format("resonances = {}\nvoices = {}\n", resonances, voices);
        SCOPED_TRACE(body);
        auto s = surfaceWithLayer(body);
        const auto& grf = grfs[static_cast<std::size_t>(trial % 2)];
        const auto out = render(*s, grf, 1 + static_cast<int>(random.below(700)));
        // Bound: every voice peaks at most at sum_k a_k <= sqrt(K E) <= 2 sqrt(E); E is at most
        // the largest energy scale (load^p (1 + rise_energy rise / 10)) or the onset energy x 3;
        // the two 2nd-order Butterworth sections have impulse-response L1 norms below 2 each.
        const auto e = extremes(grf);
        const double scale = std::pow(std::max(e.maxKn, 1e-9), v["load_exponent"]) *
                             (1.0 + v["rise_energy"] * e.maxRise / 10.0);
        const double maxEnergy = std::max(scale, 3.0 * v["onset_energy"]);
        const double bound = dbToGain(v["gain_db"]) * voices * 2.0 * std::sqrt(maxEnergy) * 4.0;
        for (float x : out) {
            ASSERT_TRUE(std::isfinite(x));
            ASSERT_LE(std::fabs(x), bound);
        }
    }
}

TEST(BubblesLayer, RandomizedSweepsStayFiniteBoundedAndEndInSilence) {
    const auto probe = surfaceWithLayer("", "bubbles");
    const auto params = probe->parameters();
    ASSERT_GE(params.size(), 18u);
    Random random(77);
    const std::vector<std::vector<float>> grfs = {walkerGrf(3.0, 4, 120.0), hardGrf()};
    for (int trial = 0; trial < 30; ++trial) {
        std::map<std::string, double> v;
        std::string body = randomLayerBody(params, random, v);
        const int voices = 1 + static_cast<int>(random.below(256));
        body += fmt::format("voices = {}\n", voices);
        SCOPED_TRACE(body);
        auto s = surfaceWithLayer(body, "bubbles");
        auto grf = grfs[static_cast<std::size_t>(trial % 2)];
        auto out = render(*s, grf, 1 + static_cast<int>(random.below(700)));
        // Bound: voices x the loudest bubble (r_max / 1 mm)^1.5, plus the two noise bands
        // (white noise in [-1, 1] through a band-pass of L1 norm < 4) at their largest
        // envelopes (splash: rise / 10 kN/s; slosh: |dF/dt| / 10 kN/s + the wake, <= 2).
        const auto e = extremes(grf);
        const double rMax = std::max(v["radius_min_mm"], v["radius_max_mm"]);
        const double noise = 4.0 * (dbToGain(v["splash_noise_db"]) * e.maxRise / 10.0 +
                                    dbToGain(v["slosh_db"]) * (e.maxSpeed / 10.0 + 2.0));
        const double bound = dbToGain(v["gain_db"]) * (voices * std::pow(rMax, 1.5) + noise);
        for (float x : out) {
            ASSERT_TRUE(std::isfinite(x));
            ASSERT_LE(std::fabs(x), bound);
        }
        // Ends in silence: 20 s of no contact covers the longest wake and bubble (30 mm rings
        // for ~ 1 s).
        std::vector<float> zero(static_cast<std::size_t>(20 * kFs), 0.0f);
        out = render(*s, zero);
        EXPECT_TRUE(s->isSleeping());
        EXPECT_EQ(out.back(), 0.0f);
    }
}

TEST(BubblesLayer, SilentAtZeroAndSplashesOnLanding) {
    auto s = surfaceWithLayer("splash_bubbles_per_kn = 400.0\nsplash_ms = 60.0\n"
                              "splash_noise_db = -6.0\nwake_ms = 100.0\nwake_bubbles_hz = 100.0",
                              "bubbles");
    std::vector<float> zero(static_cast<std::size_t>(kFs), 0.0f);
    auto out = render(*s, zero);
    for (float v : out) ASSERT_EQ(v, 0.0f);
    EXPECT_TRUE(s->isSleeping());
    const auto& layer = dynamic_cast<const BubblesLayer&>(s->layer(0));
    EXPECT_EQ(layer.stream().bubbleCount(), 0u);
    out = render(*s, walkerGrf(1.2));
    // The splash: 400 bubbles per kN gained in the first 60 ms (~0.3-0.5 kN) plus the wake.
    EXPECT_GT(layer.stream().bubbleCount(), 60u);
    EXPECT_LT(layer.stream().bubbleCount(), 400u);
    out = render(*s, zero);
    EXPECT_TRUE(s->isSleeping());
}

TEST(BubblesLayer, ALegHeldStillCalmsTheWater) {
    // Standing in the water with a quiet stance's sway (+-15 N at 0.4 Hz, at most 0.04 kN/s):
    // the sway stirs bubbles and slosh for the 2 s of settle_after_s, then they fade (0.5 s time
    // constant) and the water is silent; a quick shift of the weight stirs it again.
    auto s = surfaceWithLayer("bubbles_per_kn = 400.0\nslosh_db = 0.0", "bubbles");
    const auto& layer = dynamic_cast<const BubblesLayer&>(s->layer(0));
    const double pi = 3.141592653589793;
    std::vector<float> sway(static_cast<std::size_t>(10 * kFs));
    for (std::size_t i = 0; i < sway.size(); ++i)
        sway[i] = static_cast<float>(
            600.0 + 15.0 * std::sin(2.0 * pi * 0.4 * static_cast<double>(i) / kFs));
    auto out = render(*s, sway);
    const auto stirred = layer.stream().bubbleCount();
    EXPECT_GT(stirred, 0u); // (the first 2 s: 400 x 0.02-0.04 kN/s)
    for (std::size_t i = static_cast<std::size_t>(8 * kFs); i < out.size(); ++i)
        ASSERT_EQ(out[i], 0.0f) << "still sounding at " << static_cast<double>(i) / kFs << " s";
    out = render(*s, sway); // 10 s more: not one bubble
    EXPECT_EQ(layer.stream().bubbleCount(), stirred);
    std::vector<float> shift(static_cast<std::size_t>(kFs), 300.0f);
    for (std::size_t i = 0; i < static_cast<std::size_t>(0.15 * kFs); ++i)
        shift[i] = static_cast<float>(600.0 - 300.0 * static_cast<double>(i) / (0.15 * kFs));
    render(*s, shift); // 2 kN/s for 0.15 s: 400 x 0.3 kN = 120 bubbles
    EXPECT_GT(layer.stream().bubbleCount(), stirred + 60u);
}

TEST(SurfaceLayers, NoAllocationWhileProcessing) {
    for (const char* id : {"gravel", "dry_leaves", "water", "puddles"}) {
        auto s = Surface::loadById(id);
        s->prepare({kFs, 256});
        s->reset(1);
        const auto grf = walkerGrf(4.0);
        std::vector<float> out(256);
        underfoot::test::allocationCount = 0;
        underfoot::test::countAllocations = true;
        for (std::size_t done = 0; done + 256 <= grf.size(); done += 256)
            s->process(grf.data() + done, out.data(), 256);
        underfoot::test::countAllocations = false;
        EXPECT_EQ(underfoot::test::allocationCount.load(), 0) << id;
    }
}

TEST(GrainsLayer, AGrfStartingMidStanceIsNoLanding) {
    // A GRF file (or the walker) may start in the middle of a step: the load is there at the
    // first sample. That is no landing: no onset event and no burst of "rise" events.
    auto s = surfaceWithLayer("events_per_kn_rise = 300.0\nonset_energy = 1.0");
    std::vector<float> grf(static_cast<std::size_t>(0.5 * kFs), 600.0f);
    render(*s, grf);
    EXPECT_EQ(events(*s), 0u);
    auto b = surfaceWithLayer("splash_bubbles_per_kn = 2000.0\nsplash_noise_db = 0.0", "bubbles");
    const auto out = render(*b, grf);
    EXPECT_EQ(dynamic_cast<const BubblesLayer&>(b->layer(0)).stream().bubbleCount(), 0u);
    for (float v : out) ASSERT_EQ(v, 0.0f);
    // A real landing (a ramp over 50 ms) does fire.
    std::vector<float> ramp(static_cast<std::size_t>(0.5 * kFs), 600.0f);
    for (std::size_t i = 0; i < static_cast<std::size_t>(0.05 * kFs); ++i)
        ramp[i] = static_cast<float>(600.0 * static_cast<double>(i) / (0.05 * kFs));
    s->reset(1);
    render(*s, ramp);
    EXPECT_GT(events(*s), 100u); // 300 per kN x 0.6 kN = 180 expected, plus the onset
}
