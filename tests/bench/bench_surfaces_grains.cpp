// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of one voice (one foot) of every aggregate and liquid surface at 48 kHz, driven by the
// virtual walker (70 kg, 100 steps/min): ns per output sample and the real-time factor
// (counter "xRT": seconds of sound per second of CPU; the target is > 100).
// Run: build/tests/bench/bench_surfaces_grains
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Denormals.h"
#include "engine/surfaces/Surface.h"

#include <benchmark/benchmark.h>

#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;
constexpr int kBlock = 256;

const std::vector<float>& walkerGrf() {
    static const std::vector<float> grf = [] {
        VirtualWalker walker;
        walker.prepare({kFs, kBlock});
        walker.reset(7);
        std::vector<float> left(static_cast<std::size_t>(12 * kFs)), right(left.size());
        walker.process(left.data(), right.data(), static_cast<int>(left.size()));
        return left; // 12 s = 5 steps of the left foot, with the swing phases
    }();
    return grf;
}

void surfaceVoice(benchmark::State& state, const char* id, int maxEventsPerSecond) {
    ScopedFlushDenormals flush;
    AccuracyOptions options;
    options.maxEventsPerSecond = maxEventsPerSecond;
    auto surface = Surface::loadById(id, options);
    surface->prepare({kFs, kBlock});
    surface->reset(1);
    const auto& grf = walkerGrf();
    std::vector<float> out(kBlock);
    std::size_t position = 0;
    std::int64_t samples = 0;
    for (auto _ : state) {
        if (position + kBlock > grf.size()) position = 0;
        surface->process(grf.data() + position, out.data(), kBlock);
        benchmark::DoNotOptimize(out.data());
        position += kBlock;
        samples += kBlock;
    }
    state.SetItemsProcessed(samples);
    state.counters["ns/sample"] = benchmark::Counter(
        static_cast<double>(samples), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["xRT"] =
        benchmark::Counter(static_cast<double>(samples) / kFs, benchmark::Counter::kIsRate);
}
} // namespace

#define UNDERFOOT_SURFACE_BENCH(id)                                                                \
    BENCHMARK_CAPTURE(surfaceVoice, id, #id, 4000)->MinTime(1.0);                                  \
    BENCHMARK_CAPTURE(surfaceVoice, id##_cap1000, #id, 1000)->MinTime(0.5)

UNDERFOOT_SURFACE_BENCH(beach_sand);
UNDERFOOT_SURFACE_BENCH(gravel);
UNDERFOOT_SURFACE_BENCH(dirt_pebbles);
UNDERFOOT_SURFACE_BENCH(deep_snow);
UNDERFOOT_SURFACE_BENCH(frozen_snow);
UNDERFOOT_SURFACE_BENCH(high_grass);
UNDERFOOT_SURFACE_BENCH(forest_underbrush);
UNDERFOOT_SURFACE_BENCH(dry_leaves);
UNDERFOOT_SURFACE_BENCH(carpet);
UNDERFOOT_SURFACE_BENCH(puddles);
UNDERFOOT_SURFACE_BENCH(water);

BENCHMARK_MAIN();
