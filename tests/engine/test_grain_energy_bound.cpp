// SPDX-License-Identifier: GPL-3.0-or-later
// The grains' energy bound (docs/explanation/realism.md "Levels"): the summed amplitude of the
// grains ringing at once never exceeds amplitude_cap, a grain's energy scale saturates softly at
// energy_saturation, nothing changes below them, the bound is block-size independent and
// deterministic, and process() still does not allocate.
#include "engine/control/VirtualWalker.h"
#include "engine/models/Aggregate.h"
#include "engine/render/Renderer.h"
#include "engine/surfaces/GranularLayers.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/common/AllocationTrap.h"
#include "tests/common/SurfaceBlocks.h"

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

AggregateParameters denseGrains(double cap) {
    AggregateParameters p;
    p.gamma = -0.5; // many large events
    p.energyMin = 0.05;
    p.resonances = 2;
    p.freqMinHz = 300;
    p.freqMaxHz = 1200;
    p.qMin = 10;
    p.qMax = 30; // rings for tens of ms: grains pile up
    p.voices = 128;
    p.maxRateHz = 20000;
    p.amplitudeCap = cap;
    return p;
}

// Drives the model at a constant rate and energy scale; returns the output.
std::vector<float> drive(AggregateModel& m, double rateHz, double scale, double seconds,
                         int block = 256) {
    const int n = static_cast<int>(seconds * kFs);
    std::vector<float> out(static_cast<std::size_t>(n), 0.0f);
    std::vector<float> r(static_cast<std::size_t>(block), static_cast<float>(rateHz));
    std::vector<float> s(static_cast<std::size_t>(block), static_cast<float>(scale));
    for (int done = 0; done < n; done += block)
        m.process(r.data(), s.data(), out.data() + done, std::min(block, n - done));
    return out;
}

double peakOf(const std::vector<float>& x) {
    double p = 0;
    for (float v : x) p = std::max(p, std::fabs(static_cast<double>(v)));
    return p;
}

// Left foot of the virtual walker, `seconds` long.
std::vector<float> walkerLeft(const char* walker, double seconds, std::uint64_t seed) {
    return walkerGrf(WalkerParameters::parse(walker), seconds, kFs, seed).channels.at(0);
}

std::vector<float> renderLayerSurface(const std::string& id, const std::vector<float>& grf,
                                      int block, std::uint64_t seed,
                                      std::uint64_t* capped = nullptr) {
    auto s = Surface::loadById(id);
    auto out = underfoot::test::processInBlocks(*s, grf, kFs, block, seed);
    if (capped) {
        *capped = 0;
        for (int i = 0; i < s->layerCount(); ++i)
            if (auto* g = dynamic_cast<const GrainsLayer*>(&s->layer(i)))
                *capped += g->model().cappedEvents();
    }
    return out;
}
} // namespace

TEST(GrainEnergyBound, SummedAmplitudeNeverExceedsTheCap) {
    // Unbounded, a dense heavy stream piles up far beyond the bound ...
    AggregateModel free;
    free.configure(denseGrains(0.0));
    free.prepare(kFs, 20000);
    free.reset(3);
    const double cap = 4.0;
    const double freePeak = peakOf(drive(free, 8000, 9.0, 1.0));
    EXPECT_GT(freePeak, 2.0 * std::sqrt(2.0) * cap);
    // ... bounded, the summed amplitude stays at the cap and the output below sqrt(K) x cap.
    AggregateModel bounded;
    bounded.configure(denseGrains(cap));
    bounded.prepare(kFs, 20000);
    bounded.reset(3);
    const auto out = drive(bounded, 8000, 9.0, 1.0);
    EXPECT_LE(peakOf(out), std::sqrt(2.0) * cap * 1.0001);
    EXPECT_LE(bounded.peakSummedAmplitude(), cap * (1 + 1e-12));
    EXPECT_GT(bounded.peakSummedAmplitude(), 0.9 * cap); // it is reached: the bound acts
    EXPECT_GT(bounded.cappedEvents(), 100u);
    EXPECT_GT(peakOf(out), 0.5 * cap); // still sounding
}

TEST(GrainEnergyBound, NothingChangesBelowTheCap) {
    // A light stream whose summed amplitude stays below the cap: same samples bit for bit.
    AggregateModel a, b;
    a.configure(denseGrains(0.0));
    b.configure(denseGrains(50.0));
    for (auto* m : {&a, &b}) {
        m->prepare(kFs, 20000);
        m->reset(5);
    }
    const auto x = drive(a, 200, 0.5, 1.0), y = drive(b, 200, 0.5, 1.0);
    EXPECT_EQ(x, y);
    EXPECT_EQ(b.cappedEvents(), 0u);
    EXPECT_GT(b.peakSummedAmplitude(), 0.0);
}

TEST(GrainEnergyBound, RejectsANegativeCap) {
    auto p = denseGrains(-1.0);
    EXPECT_THROW(p.validate(), std::invalid_argument);
    p.amplitudeCap = std::nan("");
    EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(GrainEnergyBound, EnergyScaleSaturatesWithLoad) {
    // One grains layer, rate and energies driven by the GRF; energies observed per event.
    AggregateParameters m;
    m.gamma = -1.0;
    m.energyMin = 0.5; // energies in [0.5, 1] x scale
    m.voices = 64;
    GrainsControl c;
    c.eventsPerKnRise = 200;
    c.riseEnergy = 3.0;
    c.highpassHz = 0;
    struct Max {
        double energy = 0;
    };
    auto maxEnergy = [&](double saturation, const char* walker) {
        c.energySaturation = saturation;
        GrainsLayer layer(m, c, AccuracyOptions{});
        layer.prepare({kFs, 256});
        layer.reset(2);
        Max mx;
        layer.model().setEventObserver(
            [](void* u, const AggregateEvent& e) {
                auto* p = static_cast<Max*>(u);
                p->energy = std::max(p->energy, e.energy);
            },
            &mx);
        const auto grf = walkerLeft(walker, 3.0, 2);
        std::vector<float> out(grf.size(), 0.0f);
        layer.process(grf.data(), out.data(), static_cast<int>(grf.size()));
        return mx.energy;
    };
    const double s = 6.0;
    const double heavyFree = maxEnergy(0.0, "mass=200,shoe=1,cadence=150");
    const double heavySat = maxEnergy(s, "mass=200,shoe=1,cadence=150");
    const double lightFree = maxEnergy(0.0, "mass=70,cadence=100");
    const double lightSat = maxEnergy(s, "mass=70,cadence=100");
    EXPECT_GT(heavyFree, 3.0 * s); // the linear law grows without bound with load change
    EXPECT_LE(heavySat, s);        // saturated: never above S x energy_max
    EXPECT_GT(heavySat, 0.6 * s);
    EXPECT_LT(lightFree, 0.7 * s);                 // a 70 kg walker stays in the linear part:
    EXPECT_GT(lightSat, 0.85 * lightFree);         // its largest grain loses < 15 % energy
    EXPECT_LE(lightSat, lightFree * (1.0 + 1e-6)); // tanh never raises it
}

TEST(GrainEnergyBound, BlockSizeIndependentAndDeterministic) {
    // The bound is evaluated per event from the voices' own decays: the same drive cut into
    // different blocks gives the same samples, with the bound acting.
    auto heavy = [](int block, std::uint64_t seed, std::uint64_t* capped) {
        AggregateModel m;
        m.configure(denseGrains(4.0));
        m.prepare(kFs, 20000);
        m.reset(seed);
        const int n = static_cast<int>(0.5 * kFs);
        std::vector<float> rate(static_cast<std::size_t>(n)), scale(rate.size()),
            out(rate.size(), 0.0f);
        for (int i = 0; i < n; ++i) { // a heel strike: rate and energy rise and fall
            const double x = std::sin(3.141592653589793 * i / n);
            rate[static_cast<std::size_t>(i)] = static_cast<float>(9000 * x * x);
            scale[static_cast<std::size_t>(i)] = static_cast<float>(10 * x);
        }
        for (int done = 0; done < n; done += block) {
            const int k = std::min(block, n - done);
            const auto u = static_cast<std::size_t>(done);
            m.process(rate.data() + u, scale.data() + u, out.data() + u, k);
        }
        *capped = m.cappedEvents();
        return out;
    };
    std::uint64_t c1 = 0, c2 = 0, c3 = 0;
    const auto a = heavy(512, 9, &c1), b = heavy(37, 9, &c2), c = heavy(1, 9, &c3);
    EXPECT_EQ(a, b);
    EXPECT_EQ(a, c);
    EXPECT_GT(c1, 100u);
    EXPECT_EQ(c1, c2);
    // Shipped presets with a heavy walker: same seed, same samples; the bound acts.
    const auto grf = walkerLeft("mass=200,shoe=1,cadence=150", 3.0, 4);
    for (const char* id : {"frozen_snow", "dry_leaves", "gravel"}) {
        std::uint64_t capped = 0;
        const auto x = renderLayerSurface(id, grf, 256, 9, &capped);
        const auto y = renderLayerSurface(id, grf, 256, 9);
        EXPECT_EQ(x, y) << id;
        EXPECT_GT(capped, 0u) << id << ": the heavy walker should reach the bound";
    }
}

TEST(GrainEnergyBound, ProcessDoesNotAllocate) {
    const auto grf = walkerLeft("mass=200,shoe=1,cadence=150", 2.0, 6);
    for (const char* id : {"frozen_snow", "forest_underbrush"}) {
        auto s = Surface::loadById(id);
        s->prepare({kFs, 256});
        s->reset(1);
        std::vector<float> out(256);
        underfoot::test::AllocationTrap trap;
        for (std::size_t done = 0; done + 256 <= grf.size(); done += 256)
            s->process(grf.data() + done, out.data(), 256);
        EXPECT_EQ(trap.count(), 0) << id;
    }
}
