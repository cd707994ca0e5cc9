// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of the zero-latency convolution reverb (engine/reverb/Convolver):
//   - per shipped IR: median, p99 and worst 64-frame block of the Convolver alone, and the same
//     for zita-convolver used as its author intends (one Convproc, quantum 64, partitions
//     64..8192, its worker threads, 64 samples of latency, process(true) so that every block
//     waits for the work due in it);
//   - per reverb surface (one voice, the virtual walker at 100 steps/min, FootstepScene at 64
//     frames, reverb included): median, p99 and worst block, worst / median, x real time;
//     and the same surface dry (ReverbMode::Off) for reference.
// Timing method: engine/render/SceneBench's timeBlocks (the same as `underfoot bench --only
// surfaces|scenes`): the same deterministic input runs `repeats` times, everything reset in
// between so that block b does the same work in every repeat; x real time from the fastest
// repeat's whole-run CPU time; median / p99 / worst over the per-block minima (steady clock).
//
// Instructions per sample against zita-convolver (callgrind; difference of a long and a short
// run, so that loading, planning and start-up cancel):
//   bench_reverb --driver=ours --ir=hall --seconds=2     (and 12; likewise --driver=zita)
// see docs/explanation/performance.md and docs/decisions/time-distributed-convolver.md.
//
// Run: build/tests/bench/bench_reverb [--benchmark_filter=...]
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Denormals.h"
#include "engine/io/AudioFile.h"
#include "engine/render/FootstepScene.h"
#include "engine/render/Renderer.h"
#include "engine/render/SceneBench.h"
#include "engine/reverb/Convolver.h"
#include "tests/bench/BenchCommon.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace underfoot::engine;
using underfoot::bench::noise;
using underfoot::bench::Zita;

namespace {
constexpr int kRate = 48000;
constexpr int kBlock = 64;

AudioBuffer shippedIr(const std::string& name) {
    return readAudioFile(findImpulseResponse(name), kRate);
}

void report(benchmark::State& state, const BlockCostStats& s) {
    state.counters["median_us"] = s.medianUs;
    state.counters["p99_us"] = s.p99Us;
    state.counters["worst_us"] = s.worstUs;
    state.counters["worst_over_median"] = s.worstOverMedian();
    state.counters["budget_pct_worst"] = 100.0 * s.budgetShare();
    state.counters["ns_per_sample"] = s.nsPerSample;
    state.counters["ns_per_sample_minima"] = s.minimaNsPerSample;
    state.counters["x_realtime"] = s.realTimeFactor;
}

constexpr double kSeconds = 20.0;
constexpr int kRepeats = 5;

void irOurs(benchmark::State& state, const std::string& name) {
    ScopedFlushDenormals flush;
    Convolver conv;
    conv.prepare(shippedIr(name), kRate, kBlock);
    const std::size_t blocks = static_cast<std::size_t>(kSeconds * kRate / kBlock);
    const auto in = noise(blocks * kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    BlockCostStats s;
    for (auto _ : state)
        s = timeBlocks(
            blocks, kRepeats, kBlock, kRate, [&] { conv.reset(); },
            [&](std::size_t b) {
                conv.process(in.data() + b * kBlock, l.data(), r.data(), kBlock);
                benchmark::DoNotOptimize(l.data());
            });
    report(state, s);
}

void irZita(benchmark::State& state, const std::string& name) {
    ScopedFlushDenormals flush;
    auto* z = new Zita(shippedIr(name), kBlock); // never destroyed (see Zita)
    // zita has no reset: the repeats continue its stream. Its period is 8192 samples (128
    // blocks): with a whole number of periods per repeat block b does the same work in every
    // repeat. Process CPU time: its worker threads count.
    const std::size_t blocks = static_cast<std::size_t>(kSeconds * kRate / kBlock) / 128 * 128;
    const auto in = noise(blocks * kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    BlockCostStats s;
    for (auto _ : state)
        s = timeBlocks(
            blocks, kRepeats, kBlock, kRate, [] {},
            [&](std::size_t b) {
                z->block(in.data() + b * kBlock, l.data(), r.data());
                benchmark::DoNotOptimize(l.data());
            },
            BenchClock::Process);
    report(state, s);
}

void surface(benchmark::State& state, const std::string& id, bool withReverb) {
    SceneBenchSpec spec;
    spec.surface = id;
    spec.reverb = withReverb ? ReverbMode::AsPreset : ReverbMode::Off;
    spec.seconds = kSeconds;
    spec.repeats = kRepeats;
    SceneBenchResult r;
    for (auto _ : state) r = measureScene(spec);
    state.counters["has_reverb"] = r.hasReverb ? 1 : 0;
    report(state, r.stats);
}

/// The instruction-count driver: `--driver=ours|zita --ir=NAME --seconds=S`.
int driver(const std::string& which, const std::string& ir, double seconds) {
    ScopedFlushDenormals flush;
    const AudioBuffer h = shippedIr(ir);
    const auto in = noise(kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    const auto blocks = static_cast<long long>(seconds * kRate / kBlock);
    double sink = 0;
    if (which == "ours") {
        Convolver conv;
        conv.prepare(h, kRate, kBlock);
        for (long long b = 0; b < blocks; ++b) {
            conv.process(in.data(), l.data(), r.data(), kBlock);
            sink += l[0];
        }
    } else if (which == "zita") {
        auto* z = new Zita(h, kBlock); // never destroyed (see Zita)
        for (long long b = 0; b < blocks; ++b) {
            z->block(in.data(), l.data(), r.data());
            sink += l[0];
        }
    } else {
        std::fprintf(stderr, "bench_reverb: --driver=%s: expected ours or zita\n", which.c_str());
        return 2;
    }
    std::printf("%s %s %.1f s: %lld blocks (checksum %g)\n", which.c_str(), ir.c_str(), seconds,
                blocks, sink);
    std::fflush(stdout);
    std::_Exit(0); // zita's worker threads are never joined
}

} // namespace

int main(int argc, char** argv) {
    std::string drv, ir = "hall";
    double seconds = 2.0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a.rfind("--driver=", 0) == 0)
            drv = a.substr(9);
        else if (a.rfind("--ir=", 0) == 0)
            ir = a.substr(5);
        else if (a.rfind("--seconds=", 0) == 0)
            seconds = std::atof(a.c_str() + 10);
    }
    if (!drv.empty()) {
        if (!(seconds > 0 && seconds <= 3600)) {
            std::fprintf(stderr, "bench_reverb: --seconds=%g: expected (0, 3600]\n", seconds);
            return 2;
        }
        return driver(drv, ir, seconds);
    }
    for (const std::string name : {"small_room", "wooden_room", "hall"}) {
        benchmark::RegisterBenchmark(("reverbIr/ours/" + name).c_str(), irOurs, name)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("reverbIr/zita/" + name).c_str(), irZita, name)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
    }
    for (const std::string id : {"wood_reverb", "metal_reverb", "creaking_wood_reverb"}) {
        benchmark::RegisterBenchmark(("surface/reverb/" + id).c_str(), surface, id, true)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("surface/dry/" + id).c_str(), surface, id, false)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
