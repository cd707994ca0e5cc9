// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of live scenes at 48 kHz / 64 frames, run through LiveEngine's callback body
// (processBlock, exactly what the device callback runs), as % of one core:
//   - heaviest reference scene: creaking wood + 2.2 s stereo reverb (hall) + soundscape
//     (forest) + 4 haptic channels (target < 25 %);
//   - dry single surface (wood, headphones only; target < 3 %);
//   - the reverb alone (our zero-latency Convolver) against zita-convolver's own figure for
//     the same IR (one Convproc, quantum 64, partitions 64..8192, its worker threads, 64
//     samples of latency; target ours <= 1.5 x zita);
//   - per node of each scene (clock reads around each node), proving that a dry scene does no
//     reverb, soundscape or haptic work.
// The liveCostSummary benchmark measures all of them in ONE run (scenes interleaved block by
// block, the two reverbs alternately in chunks) and reports the figures and the ratio as
// counters. Per-node costs are steady-clock time around each node, so on a loaded machine they
// include preemption; the % of core figures are CPU time.
// Run: build/tests/bench/bench_live [--benchmark_filter=Summary]
#include "engine/dsp/Denormals.h"
#include "engine/io/AudioFile.h"
#include "engine/reverb/Convolver.h"
#include "engine/scene/LiveEngine.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"
#include "tests/bench/BenchCommon.h"

#include <benchmark/benchmark.h>

#include <ctime>
#include <memory>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr int kRate = 48000;
constexpr int kBlock = 64;

using underfoot::bench::noise;
using underfoot::bench::processCpuSeconds;
using underfoot::bench::Zita;
double threadCpu() {
    return underfoot::bench::threadCpuSeconds();
}

class Ambience final : public AmbienceSource {
  public:
    explicit Ambience(const std::string& id)
        : r_(underfoot::soundscapes::loadSoundscape(id)), id_(id) {}
    void prepare(const ProcessSpec& spec) override { r_.prepare(spec); }
    void reset(std::uint64_t seed) noexcept override { r_.reset(seed); }
    void process(float* l, float* r, int n) noexcept override { r_.process(l, r, n); }
    std::string name() const override { return id_; }

  private:
    underfoot::soundscapes::SoundscapeRenderer r_;
    std::string id_;
};

AudioSettings settings() {
    AudioSettings s;
    s.sampleRateHz = kRate;
    s.blockSize = kBlock;
    s.channels.haptic[0] = {2, 3};
    s.channels.haptic[1] = {4, 5};
    return s;
}

/// An offline engine with one scene, driven block by block.
struct Rig {
    explicit Rig(bool heaviest) {
        engine.openOffline(settings());
        LiveSceneDescription d;
        d.seed = 3;
        if (heaviest) {
            d.surface = "creaking_wood";
            d.impulseResponse = "hall";
            d.ambience = std::make_unique<Ambience>("forest");
            d.modality = OutputModality::AudioHaptic;
        } else {
            d.surface = "wood";
        }
        auto s = LiveScene::create(std::move(d), engine.processSpec(), engine.settings().channels);
        s->setMeasureCost(true);
        scene = s.get(); // owned by the engine; read only from this (the "audio") thread
        engine.submit(std::move(s));
        out.assign(6, std::vector<float>(kBlock));
        for (auto& c : out) outPtr.push_back(c.data());
    }
    void block() { engine.processBlock(nullptr, outPtr.data(), kBlock); }
    LiveEngine engine;
    LiveScene* scene = nullptr;
    std::vector<std::vector<float>> out;
    std::vector<float*> outPtr;
};

/// zita-convolver on the hall, one instance for the whole program, never destroyed (see
/// tests/bench/BenchCommon.h).
Zita& zitaHall() {
    static Zita* instance = new Zita(readAudioFile(findImpulseResponse("hall"), kRate), kBlock);
    return *instance;
}

std::vector<float> noiseBlock(int n, std::uint32_t seed) {
    return noise(static_cast<std::size_t>(n), seed);
}

void sceneBench(benchmark::State& state, bool heaviest) {
    Rig rig(heaviest);
    std::int64_t blocks = 0;
    for (auto _ : state) {
        rig.block();
        benchmark::DoNotOptimize(rig.out[0].data());
        ++blocks;
    }
    const double audio = double(blocks) * kBlock / kRate;
    state.counters["core_pct"] = benchmark::Counter(audio / 100.0, benchmark::Counter::kIsRate |
                                                                       benchmark::Counter::kInvert);
    for (const auto& c : rig.scene->nodeCosts())
        state.counters[std::string(toString(c.node)) + "_pct"] =
            c.present ? 100.0 * c.seconds / audio : 0.0;
}

void reverbOurs(benchmark::State& state) {
    ScopedFlushDenormals flush;
    Convolver conv;
    conv.prepare(readAudioFile(findImpulseResponse("hall")), kRate, kBlock);
    const auto in = noiseBlock(kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    std::int64_t blocks = 0;
    for (auto _ : state) {
        conv.process(in.data(), l.data(), r.data(), kBlock);
        benchmark::DoNotOptimize(l.data());
        ++blocks;
    }
    state.counters["core_pct"] =
        benchmark::Counter(double(blocks) * kBlock / kRate / 100.0,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void reverbZita(benchmark::State& state) {
    ScopedFlushDenormals flush;
    Zita& z = zitaHall();
    const auto in = noiseBlock(kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    std::int64_t blocks = 0;
    for (auto _ : state) {
        z.block(in.data(), l.data(), r.data());
        benchmark::DoNotOptimize(l.data());
        ++blocks;
    }
    state.counters["core_pct"] =
        benchmark::Counter(double(blocks) * kBlock / kRate / 100.0,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// Everything in one run, 20 s of audio each: the two scenes interleaved block by block
/// (thread CPU time, so the load of a shared machine hits them alike); then our reverb and
/// zita's alternately in ten 2 s chunks, each alone with its caches (ours: thread CPU time;
/// zita: process CPU time over the chunk, which includes its worker threads).
void liveCostSummary(benchmark::State& state) {
    Rig heavy(true), dry(false);
    Convolver conv;
    conv.prepare(readAudioFile(findImpulseResponse("hall")), kRate, kBlock);
    Zita& z = zitaHall();
    const auto in = noiseBlock(kBlock, 1);
    std::vector<float> l(kBlock), r(kBlock);
    const std::int64_t blocks = std::int64_t(20) * kRate / kBlock;
    double tHeavy = 0, tDry = 0, tOurs = 0, tZita = 0;
    for (auto _ : state) {
        for (std::int64_t b = 0; b < blocks; ++b) {
            const double t0 = threadCpu();
            heavy.block();
            const double t1 = threadCpu();
            dry.block();
            const double t2 = threadCpu();
            tHeavy += t1 - t0;
            tDry += t2 - t1;
            benchmark::DoNotOptimize(heavy.out[0].data());
        }
        ScopedFlushDenormals flush;
        for (int chunk = 0; chunk < 10; ++chunk) {
            const double t0 = threadCpu();
            for (std::int64_t b = 0; b < blocks / 10; ++b) {
                conv.process(in.data(), l.data(), r.data(), kBlock);
                benchmark::DoNotOptimize(l.data());
            }
            tOurs += threadCpu() - t0;
            const double p0 = processCpuSeconds();
            for (std::int64_t b = 0; b < blocks / 10; ++b) {
                z.block(in.data(), l.data(), r.data());
                benchmark::DoNotOptimize(l.data());
            }
            tZita += processCpuSeconds() - p0;
        }
    }
    const double audio = double(blocks) * kBlock / kRate * double(state.iterations());
    state.counters["heaviest_core_pct"] = 100.0 * tHeavy / audio;
    state.counters["dry_core_pct"] = 100.0 * tDry / audio;
    state.counters["reverb_ours_pct"] = 100.0 * tOurs / audio;
    state.counters["reverb_zita_pct"] = 100.0 * tZita / audio;
    state.counters["ours_over_zita"] = tOurs / std::max(tZita, 1e-12);
    auto nodes = [&](const char* prefix, LiveScene* sc) {
        for (const auto& c : sc->nodeCosts())
            state.counters[std::string(prefix) + toString(c.node) + "_pct"] =
                c.present ? 100.0 * c.seconds / audio : -1.0; // -1: the node does not exist
    };
    nodes("heavy_", heavy.scene);
    nodes("dry_", dry.scene);
}

} // namespace

BENCHMARK_CAPTURE(sceneBench, heaviest, true)->MinTime(2.0);
BENCHMARK_CAPTURE(sceneBench, dry_single_surface, false)->MinTime(2.0);
BENCHMARK(reverbOurs)->MinTime(2.0);
BENCHMARK(reverbZita)->MinTime(2.0)->MeasureProcessCPUTime();
BENCHMARK(liveCostSummary)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
