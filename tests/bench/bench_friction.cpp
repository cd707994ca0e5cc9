// SPDX-License-Identifier: GPL-3.0-or-later
// Time of the friction's per-sample kernel (ElastoPlasticFriction::processSample) on the inputs
// the creaking_wood preset's friction layer gives it along a walk (issue #18): ns per solved
// sample. The kernel's cost in time is set by its chain of dependent operations (each sample's
// solve starts from the last one's state), which instruction counts do not show; this measures
// it. The steady drag of `underfoot bench --only friction-creak` mostly slides fully; along a walk
// most samples are in the raised sine between stick and slip (the longer chain).
//
// The inputs are recorded once: the virtual walker's left foot (seed 7, 12 s) through the
// friction layer's drive (engine/surfaces/SolidLayers.cpp, FrictionLayer::processSpan: the
// load's smoothed rate of change above the slip threshold drags the anchor) with the parameters
// of engine/data/surfaces/creaking_wood.toml as shipped on 29 Nov 2026, keeping the samples the
// layer solves (the others sleep). The benchmark then replays them into a fresh friction model.
// Run: build/tests/bench/bench_friction (counter "per sample": time per solved sample).
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Denormals.h"
#include "engine/dsp/Envelope.h"
#include "engine/models/Friction.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

struct Drive {
    double normal, anchor, anchorVelocity;
};

// creaking_wood.toml's friction layer as shipped (not configureCreakScenario of
// engine/render/AccuracyCost.h: that one keeps the values of the time, sigma3 0.05 and a
// 2.65 kHz top mode, so that its figures stay comparable with the Sound Design Toolkit's)
constexpr double kNormalFraction = 0.15, kSlipPerRate = 0.006, kThreshold = 1200.0;
constexpr double kGainDb = -15.4;

void configureCreak(ElastoPlasticFriction& f) {
    FrictionParams p;
    p.sigma0 = 2e5;
    p.sigma1 = 150.0;
    p.sigma2 = 0.2;
    p.sigma3 = 0.5;
    p.staticCoefficient = 0.55;
    p.dynamicCoefficient = 0.25;
    p.stribeckVelocity = 0.02;
    p.breakAway = 0.6;
    p.exciterMassKg = 0.02;
    p.driveStiffness = 5e5;
    p.driveDamping = 2.0;
    f.configure(p,
                {{310, 0.06, 0.05},
                 {690, 0.05, 0.04},
                 {1130, 0.04, 0.04},
                 {1870, 0.03, 0.05},
                 {4500, 0.01, 0.03}},
                {{1.0, 0.8, 0.25, 0.1, 0.6}});
    f.prepare(kFs);
    f.reset(7);
}

const std::vector<Drive>& walkDrive() {
    static const std::vector<Drive> drive = [] {
        VirtualWalker walker;
        walker.prepare({kFs, 256});
        walker.reset(7);
        std::vector<float> left(static_cast<std::size_t>(12 * kFs)), right(left.size());
        walker.process(left.data(), right.data(), static_cast<int>(left.size()));
        ElastoPlasticFriction f;
        configureCreak(f);
        const double smooth = onePoleCoefficientTau(0.005, kFs);
        const double sleepVelocity = 1e-6 / std::pow(10.0, kGainDb / 20.0);
        double last = 0, rate = 0, anchor = 0;
        long quiet = 1 << 30;
        std::vector<Drive> d;
        for (float g : left) { // (as FrictionLayer::processSpan)
            const double load = std::max(0.0f, g);
            const double change = (load - last) * kFs;
            last = load;
            rate = change + smooth * (rate - change);
            const double shear = std::max(0.0, std::fabs(rate) - kThreshold) * 1e-3 * kSlipPerRate;
            if (shear <= 0.0 && quiet > static_cast<long>(0.05 * kFs)) {
                anchor = f.exciterPosition();
                continue;
            }
            anchor += shear / kFs;
            if (load <= 0.0) {
                const double x = f.exciterPosition();
                f.relax();
                anchor = x;
            }
            d.push_back({kNormalFraction * load, anchor, shear});
            const double y = f.processSample(d.back().normal, 0.0, anchor, shear);
            const bool still = load <= 0.0 || std::fabs(f.relativeVelocity()) < 1e-6;
            quiet = (std::fabs(y) < sleepVelocity && still) ? quiet + 1 : 0;
        }
        return d;
    }();
    return drive;
}

void frictionAlongAWalk(benchmark::State& state, bool avx) {
    ScopedFlushDenormals flush;
    const auto& drive = walkDrive();
    ElastoPlasticFriction f;
    configureCreak(f);
    f.allowAvx(avx);
    std::int64_t samples = 0;
    double sum = 0;
    for (auto _ : state) {
        f.reset(7);
        for (const Drive& d : drive) {
            if (d.normal <= 0.0) f.relax();
            sum += f.processSample(d.normal, 0.0, d.anchor, d.anchorVelocity);
        }
        samples += static_cast<std::int64_t>(drive.size());
    }
    benchmark::DoNotOptimize(sum);
    state.counters["per sample"] = benchmark::Counter(
        static_cast<double>(samples), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["solved samples"] = static_cast<double>(drive.size());
}

} // namespace

BENCHMARK_CAPTURE(frictionAlongAWalk, creaking_wood_avx, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(frictionAlongAWalk, creaking_wood_sse2, false)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
