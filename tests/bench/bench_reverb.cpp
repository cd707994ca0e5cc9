// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of the zero-latency convolution reverb (engine/reverb/Convolver), issue #18:
//   - per shipped IR: median, p99 and worst 64-frame block of the Convolver alone, and the same
//     for zita-convolver used as its author intends (one Convproc, quantum 64, partitions
//     64..8192, its worker threads, 64 samples of latency, process(true) so that every block
//     waits for the work due in it);
//   - per reverb surface (one voice, the virtual walker at 100 steps/min, FootstepScene at 64
//     frames, reverb included): median, p99 and worst block, worst / median, x real time;
//     and the same surface dry (ReverbMode::Off) for reference.
// Timing method: the same deterministic input is run `repeats` times (the state reset in
// between, so block b does the same work in every repeat); each block's time is the MINIMUM
// over the repeats (steady clock around each process() call). A shared machine only ever slows
// a block down (preemption, another process in the cache), so the minimum is the block's own
// cost; median / p99 / worst are taken over those per-block minima.
//
// Instructions per sample against zita-convolver (callgrind; difference of a long and a short
// run, so that loading, planning and start-up cancel):
//   bench_reverb --driver=ours --ir=hall --seconds=2     (and 12; likewise --driver=zita)
// see docs/performance-reverb.md for the commands and figures.
//
// Run: build/tests/bench/bench_reverb [--benchmark_filter=...]
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Denormals.h"
#include "engine/io/AudioFile.h"
#include "engine/render/FootstepScene.h"
#include "engine/render/Renderer.h"
#include "engine/reverb/Convolver.h"

#include <benchmark/benchmark.h>
#include <zita-convolver.h>

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

namespace {
constexpr int kRate = 48000;
constexpr int kBlock = 64;

/// zita-convolver, mono in, stereo IR out, partitions 64..8192 with its threads (as
/// tests/bench/bench_live.cpp). Never destroyed: the Debian build's stop_process()/cleanup()
/// can wait forever for its worker threads after a run faster than real time.
struct Zita {
    explicit Zita(const AudioBuffer& ir) {
        const auto len = static_cast<unsigned>(ir.frames());
        zita.set_options(Convproc::OPT_VECTOR_MODE);
        if (zita.configure(1, 2, len, kBlock, kBlock, 8192, 0.0f) != 0)
            throw std::runtime_error("zita configure failed");
        for (int c = 0; c < 2; ++c) {
            std::vector<float> h(len);
            for (unsigned i = 0; i < len; ++i) h[i] = ir.at(i, ir.channels > 1 ? c : 0);
            zita.impdata_create(0, static_cast<unsigned>(c), 1, h.data(), 0, static_cast<int>(len));
        }
        if (zita.start_process(0, SCHED_OTHER) != 0) throw std::runtime_error("zita start failed");
    }
    void block(const float* in, float* l, float* r) {
        std::copy(in, in + kBlock, zita.inpdata(0));
        zita.process(true); // synchronous: waits for the worker threads' partitions due now
        std::copy(zita.outdata(0), zita.outdata(0) + kBlock, l);
        std::copy(zita.outdata(1), zita.outdata(1) + kBlock, r);
    }
    Convproc zita;
};

std::vector<float> noise(std::size_t n, std::uint32_t seed) {
    std::vector<float> x(n);
    for (auto& v : x) {
        seed = seed * 1664525u + 1013904223u;
        v = (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f) * 0.2f;
    }
    return x;
}

AudioBuffer shippedIr(const std::string& name) {
    return readAudioFile(findImpulseResponse(name), kRate);
}

struct BlockStats {
    double medianUs = 0, p99Us = 0, worstUs = 0, meanUs = 0;
};

/// Per-block minimum over `repeats` runs of `blocks` blocks; `reset` runs before each repeat
/// and `block(b)` processes block b.
BlockStats timeBlocks(std::size_t blocks, int repeats, const std::function<void()>& reset,
                      const std::function<void(std::size_t)>& block) {
    using Clock = std::chrono::steady_clock;
    std::vector<double> best(blocks, 1e300);
    for (int r = 0; r < repeats; ++r) {
        reset();
        for (std::size_t b = 0; b < blocks; ++b) {
            const auto t0 = Clock::now();
            block(b);
            const auto t1 = Clock::now();
            best[b] = std::min(best[b], std::chrono::duration<double, std::micro>(t1 - t0).count());
        }
    }
    BlockStats s;
    for (double v : best) s.meanUs += v;
    s.meanUs /= double(blocks);
    std::vector<double> sorted = best;
    std::sort(sorted.begin(), sorted.end());
    s.medianUs = sorted[sorted.size() / 2];
    s.p99Us = sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
    s.worstUs = sorted.back();
    return s;
}

void report(benchmark::State& state, const BlockStats& s) {
    state.counters["median_us"] = s.medianUs;
    state.counters["p99_us"] = s.p99Us;
    state.counters["worst_us"] = s.worstUs;
    state.counters["worst_over_median"] = s.worstUs / s.medianUs;
    state.counters["budget_pct_worst"] = 100.0 * s.worstUs / (1e6 * kBlock / kRate);
    state.counters["x_realtime"] = (1e6 * kBlock / kRate) / s.meanUs;
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
    BlockStats s;
    for (auto _ : state)
        s = timeBlocks(
            blocks, kRepeats, [&] { conv.reset(); },
            [&](std::size_t b) {
                conv.process(in.data() + b * kBlock, l.data(), r.data(), kBlock);
                benchmark::DoNotOptimize(l.data());
            });
    report(state, s);
}

void irZita(benchmark::State& state, const std::string& name) {
    ScopedFlushDenormals flush;
    auto* z = new Zita(shippedIr(name)); // never destroyed (see Zita)
    const std::size_t blocks = static_cast<std::size_t>(kSeconds * kRate / kBlock);
    const auto in = noise(blocks * kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    BlockStats s;
    // zita has no reset: the repeats continue its stream (same work per block after the
    // first IR length).
    for (auto _ : state)
        s = timeBlocks(
            blocks, kRepeats, [] {},
            [&](std::size_t b) {
                z->block(in.data() + b * kBlock, l.data(), r.data());
                benchmark::DoNotOptimize(l.data());
            });
    report(state, s);
}

void surface(benchmark::State& state, const std::string& id, bool withReverb) {
    FootstepScene scene;
    SceneOptions options;
    options.voices = 1;
    options.reverb = withReverb ? ReverbMode::AsPreset : ReverbMode::Off;
    scene.build(id, options);
    scene.prepare(ProcessSpec{double(kRate), kBlock});
    const GrfSignal grf = walkerGrf(WalkerParameters{}, kSeconds, kRate, 1);
    const std::size_t blocks = grf.frames() / kBlock;
    std::vector<float> l(kBlock), r(kBlock);
    BlockStats s;
    for (auto _ : state)
        s = timeBlocks(
            blocks, kRepeats, [&] { scene.reset(1); },
            [&](std::size_t b) {
                const float* g = grf.channels[0].data() + b * kBlock;
                scene.process(&g, l.data(), r.data(), kBlock);
                benchmark::DoNotOptimize(l.data());
            });
    state.counters["has_reverb"] = scene.hasReverb() ? 1 : 0;
    report(state, s);
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
        auto* z = new Zita(h); // never destroyed (see Zita)
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
