// SPDX-License-Identifier: GPL-3.0-or-later
// The heel burst of a grains layer (engine/surfaces/GranularLayers.h,
// docs/decisions/realism-revoicing.md "Heel-driven grains and several starts"): extra events at the
// heel's contact whose rate and energy follow e(t) = (t / T) exp(1 - t / T) up to T = heel_ms, then
// exp(-(t - T) / D); none for a load that appears mid-stance; off (heel_rate_hz = 0) it changes
// nothing; block-size independent, deterministic, bounded by energy_saturation and amplitude_cap,
// no allocation.
#include "engine/control/VirtualWalker.h"
#include "engine/render/Renderer.h"
#include "engine/surfaces/GranularLayers.h"
#include "engine/surfaces/Preset.h"
#include "engine/surfaces/Surface.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "tests/common/AllocationTrap.h"
#include "tests/common/SurfaceBlocks.h"

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

// A step: no contact for 50 ms, the load rises to 700 N in 60 ms, holds until 0.6 s, then 0.
std::vector<float> stepGrf(double seconds = 1.0) {
    std::vector<float> g(static_cast<std::size_t>(seconds * kFs), 0.0f);
    for (std::size_t i = 0; i < g.size(); ++i) {
        const double t = static_cast<double>(i) / kFs - 0.05;
        if (t > 0 && t < 0.6) g[i] = static_cast<float>(700.0 * std::min(1.0, t / 0.06));
    }
    return g;
}

AggregateParameters grains() {
    AggregateParameters m;
    m.gamma = -1.0;
    m.energyMin = 0.5; // energies in [0.5, 1] x scale
    m.resonances = 1;
    m.freqMinHz = 300;
    m.freqMaxHz = 1200;
    m.qMin = 2;
    m.qMax = 4;
    m.voices = 64;
    m.maxRateHz = 20000;
    return m;
}

struct Events {
    std::vector<double> times, energies;
};

Events observe(GrainsLayer& layer, const std::vector<float>& grf, int block = 256) {
    Events ev;
    layer.model().setEventObserver(
        [](void* u, const AggregateEvent& e) {
            auto* p = static_cast<Events*>(u);
            p->times.push_back(static_cast<double>(e.sample) / kFs);
            p->energies.push_back(e.energy);
        },
        &ev);
    std::vector<float> out(grf.size(), 0.0f);
    const int n = static_cast<int>(grf.size());
    for (int done = 0; done < n; done += block)
        layer.process(grf.data() + done, out.data() + done, std::min(block, n - done));
    return ev;
}

GrainsControl heelOnly(double rateHz, double ms, double decayMs, double energy) {
    GrainsControl c;
    c.highpassHz = 0;
    c.heelRateHz = rateHz;
    c.heelMs = ms;
    c.heelDecayMs = decayMs;
    c.heelEnergy = energy;
    return c;
}

std::string heelPreset(double heelRate) {
    return fmt::format(R"(id = 'heeltest'
name = 'Heel test'
category = 'aggregate'
description = 'grains with a heel burst'
gain_db = -6.0

[[layer]]
type = 'grains'
purpose = 'crunch under the sole with a burst at the heel strike'
events_per_s_per_kn = 40.0
events_per_kn_rise = 100.0
gamma = -1.3
energy_min = 0.01
freq_min_hz = 200.0
freq_max_hz = 900.0
q_min = 3.0
q_max = 9.0
resonances = 2
voices = 32
energy_saturation = 4.0
amplitude_cap = 6.0
heel_rate_hz = {}
heel_ms = 12.0
heel_decay_ms = 40.0
heel_energy = 3.0
)",
                       heelRate);
}

class HeelPresetFile : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               fmt::format("underfoot-heel-{}", ::testing::UnitTest::GetInstance()->random_seed());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::string write(const std::string& text, const char* name) {
        const auto p = (dir_ / name).string();
        std::ofstream(p) << text;
        return p;
    }
    std::vector<float> render(const std::string& file, const std::vector<float>& grf, int block,
                              std::uint64_t seed) {
        auto s = Surface::load(file);
        return underfoot::test::processInBlocks(*s, grf, kFs, block, seed);
    }
    std::filesystem::path dir_;
};
} // namespace

TEST(HeelBurst, EventsFollowTheEnvelopeFromTheContact) {
    // Heel burst only (no load-driven events): R = 2000 events/s at T = 10 ms, D = 30 ms.
    // Expected count R (T (e - 2) + D) = 74.4 per step; mean over 20 seeds within 5 %.
    const double R = 2000, T = 0.010, D = 0.030, E = 2.0;
    const auto grf = stepGrf();
    double count = 0, early = 0, afterPeak = 0;
    double maxEnergy = 0;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        GrainsLayer layer(grains(), heelOnly(R, T * 1e3, D * 1e3, E), AccuracyOptions{});
        layer.prepare({kFs, 256});
        layer.reset(seed);
        const auto ev = observe(layer, grf);
        for (std::size_t k = 0; k < ev.times.size(); ++k) {
            // The model runs from the contact (the layer sleeps before it and wakes at its first
            // sample in contact, whatever the block), so its times count from there.
            const double t = ev.times[k]; // since the contact
            ASSERT_GE(t, 0.0) << "an event before the contact";
            ASSERT_LE(t, T + 10 * D + 1e-3) << "an event after the burst's end";
            count += 1;
            if (t < T) early += 1;
            if (t >= T && t < T + D) afterPeak += 1;
            // Energy scale E e(t): energies within [0.5, 1] x E e(t).
            const double e = t < T ? t / T * std::exp(1 - t / T) : std::exp(-(t - T) / D);
            EXPECT_LE(ev.energies[k], E * e * 1.0001 + 1e-9);
            EXPECT_GE(ev.energies[k], 0.5 * E * e * 0.999 - 1e-4);
            maxEnergy = std::max(maxEnergy, ev.energies[k]);
        }
    }
    const double expected = R * (T * (std::exp(1.0) - 2.0) + D);
    EXPECT_NEAR(count / 20, expected, 0.05 * expected);
    // Shares of the envelope's integral: rise T (e - 2) / (T (e - 2) + D) = 0.193, first decay
    // time constant D (1 - 1/e) / (...) = 0.510 (Poisson: 1490 events in all, +-0.03).
    EXPECT_NEAR(early / count, 0.193, 0.03);
    EXPECT_NEAR(afterPeak / count, 0.510, 0.03);
    EXPECT_GT(maxEnergy, 0.8 * E); // the peak's grains reach the stated scale
}

TEST(HeelBurst, NoBurstWhenTheLoadAppearsMidStanceAndOneEveryStep) {
    GrainsLayer layer(grains(), heelOnly(2000, 10, 30, 1), AccuracyOptions{});
    layer.prepare({kFs, 256});
    layer.reset(3);
    // The load is there from the first sample (a GRF file starting mid-stance): no burst.
    std::vector<float> cut(static_cast<std::size_t>(0.5 * kFs), 600.0f);
    EXPECT_TRUE(observe(layer, cut).times.empty());
    // Then it ends and two real steps follow: one burst each.
    layer.reset(3);
    auto two = stepGrf(0.8);
    const auto second = stepGrf(0.8);
    two.insert(two.end(), second.begin(), second.end());
    const auto ev = observe(layer, two);
    const auto firstStep =
        std::count_if(ev.times.begin(), ev.times.end(), [](double t) { return t < 0.8; });
    EXPECT_GT(firstStep, 30);
    EXPECT_GT(static_cast<long>(ev.times.size()) - firstStep, 30);
}

TEST(HeelBurst, BoundedBySaturationAndCap) {
    AggregateParameters m = grains();
    m.amplitudeCap = 3.0;
    m.qMin = 20;
    m.qMax = 40; // grains ring long: they pile up
    GrainsControl c = heelOnly(8000, 10, 40, 50.0);
    c.energySaturation = 4.0;
    GrainsLayer layer(m, c, AccuracyOptions{});
    layer.prepare({kFs, 256});
    layer.reset(4);
    const auto ev = observe(layer, stepGrf());
    ASSERT_FALSE(ev.energies.empty());
    EXPECT_LE(*std::max_element(ev.energies.begin(), ev.energies.end()), 4.0 * (1 + 1e-9));
    EXPECT_LE(layer.model().peakSummedAmplitude(), 3.0 * (1 + 1e-12));
    EXPECT_GT(layer.model().cappedEvents(), 0u);
}

TEST_F(HeelPresetFile, OffChangesNothingBitForBit) {
    // heel_rate_hz = 0 with the other heel keys set: the same samples as without any heel key.
    std::string plain = heelPreset(0.0);
    for (const char* key : {"heel_rate_hz", "heel_ms", "heel_decay_ms", "heel_energy"}) {
        const auto at = plain.find(key);
        plain.erase(at, plain.find('\n', at) - at + 1);
    }
    const auto grf = walkerGrf(WalkerParameters::parse("cadence=100"), 3.0, kFs, 5).channels.at(0);
    const auto a = render(write(plain, "plain.toml"), grf, 256, 7);
    const auto b = render(write(heelPreset(0.0), "off.toml"), grf, 256, 7);
    EXPECT_EQ(a, b);
    const auto c = render(write(heelPreset(1500.0), "on.toml"), grf, 256, 7);
    EXPECT_NE(a, c); // and on, it does something
}

TEST(HeelBurst, BlockSizeIndependent) {
    // The burst is computed per sample from the samples since the contact: the same walk cut
    // into blocks of 512, 37 and 1 gives the same samples. (A heel-only layer without tone
    // filters: a grains layer's load-driven rate uses dF/dt, whose state is reset when the
    // layer falls asleep at a block boundary, and its filters likewise: that holds for every
    // grains layer, heel or not, and is not what this test is about.)
    const auto grf =
        walkerGrf(WalkerParameters::parse("mass=90,cadence=120"), 3.0, kFs, 8).channels.at(0);
    auto run = [&](int block) {
        GrainsLayer layer(grains(), heelOnly(1500, 12, 40, 2), AccuracyOptions{});
        layer.prepare({kFs, block});
        layer.reset(9);
        std::vector<float> out(grf.size(), 0.0f);
        const int n = static_cast<int>(grf.size());
        for (int done = 0; done < n; done += block)
            layer.process(grf.data() + done, out.data() + done, std::min(block, n - done));
        return out;
    };
    const auto a = run(512);
    EXPECT_GT(*std::max_element(a.begin(), a.end()), 0.01f); // it sounds
    EXPECT_EQ(a, run(37));
    EXPECT_EQ(a, run(1));
}

TEST_F(HeelPresetFile, DeterministicAndAllocationFree) {
    const auto file = write(heelPreset(1500.0), "heel.toml");
    const auto grf =
        walkerGrf(WalkerParameters::parse("mass=90,cadence=120"), 3.0, kFs, 8).channels.at(0);
    EXPECT_EQ(render(file, grf, 512, 9), render(file, grf, 512, 9));
    EXPECT_NE(render(file, grf, 512, 9), render(file, grf, 512, 10)); // the seed matters
    auto s = Surface::load(file);
    s->prepare({kFs, 256});
    s->reset(1);
    std::vector<float> out(256);
    underfoot::test::AllocationTrap trap;
    for (std::size_t done = 0; done + 256 <= grf.size(); done += 256)
        s->process(grf.data() + done, out.data(), 256);
    EXPECT_EQ(trap.count(), 0);
}

TEST_F(HeelPresetFile, OutOfRangeValuesAreRefusedWithTheirName) {
    std::string bad = heelPreset(1500.0);
    bad.replace(bad.find("heel_ms = 12.0"), 14, "heel_ms = 0.0");
    try {
        Surface::load(write(bad, "bad.toml"));
        ADD_FAILURE() << "heel_ms = 0 was accepted";
    } catch (const PresetError& e) {
        EXPECT_NE(std::string(e.what()).find("heel_ms"), std::string::npos) << e.what();
    }
}
