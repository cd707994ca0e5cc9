// SPDX-License-Identifier: GPL-3.0-or-later
// Soundscape speed: the five environments of experiment 2 rendered together at 48 kHz on one
// thread. The `rtf` counter is the real-time factor (seconds of audio per second of CPU for
// the five together); the goal is more than 50.
//   build-*/tests/bench/bench_soundscapes
#include "engine/dsp/Denormals.h"
#include "engine/dsp/Random.h"
#include "soundscapes/Generators.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

namespace {

using namespace underfoot;

constexpr double kFs = 48000.0;

std::vector<std::unique_ptr<soundscapes::SoundscapeRenderer>>
prepare(const std::vector<std::string>& ids, int block) {
    std::vector<std::unique_ptr<soundscapes::SoundscapeRenderer>> out;
    for (const auto& id : ids) {
        out.push_back(
            std::make_unique<soundscapes::SoundscapeRenderer>(soundscapes::loadSoundscape(id)));
        out.back()->prepare({kFs, block});
        out.back()->reset(1);
    }
    return out;
}

void run(benchmark::State& state, const std::vector<std::string>& ids) {
    const int block = static_cast<int>(state.range(0));
    auto renderers = prepare(ids, block);
    std::vector<float> left(static_cast<std::size_t>(block)), right(left.size());
    engine::ScopedFlushDenormals ftz;
    for (auto _ : state) {
        for (auto& r : renderers) {
            r->process(left.data(), right.data(), block);
            benchmark::DoNotOptimize(left.data());
            benchmark::DoNotOptimize(right.data());
        }
    }
    // Audio seconds per CPU second, for all the listed environments together.
    state.counters["rtf"] = benchmark::Counter(
        static_cast<double>(state.iterations()) * block / kFs, benchmark::Counter::kIsRate);
}

void allFive(benchmark::State& state) {
    run(state, {"beach_summer", "farm_courtyard", "ski_slope", "forest", "park_fall"});
}
void one(benchmark::State& state, const std::string& id) {
    run(state, {id});
}

// One generator alone (beds: continuous; events: back-to-back events), ns per output sample.
void generator(benchmark::State& state, const std::string& name) {
    const auto* info = soundscapes::findGenerator(name);
    soundscapes::ParamSet params;
    params.setGenerator(info);
    const int block = 512;
    std::vector<float> left(block), right(block);
    engine::ScopedFlushDenormals ftz;
    if (info->kind == soundscapes::LayerKind::Bed) {
        auto bed = soundscapes::makeBedGenerator(name, params);
        bed->prepare({kFs, block});
        bed->reset(1);
        for (auto _ : state) {
            bed->process(left.data(), right.data(), block);
            benchmark::DoNotOptimize(left.data());
        }
    } else {
        auto voice = soundscapes::makeEventVoice(name, params);
        voice->prepare({kFs, block});
        voice->reset(1, 2);
        engine::Random rng(3);
        voice->start(rng);
        for (auto _ : state) {
            if (voice->process(left.data(), block) < block) voice->start(rng);
            benchmark::DoNotOptimize(left.data());
        }
    }
    state.counters["rtf"] = benchmark::Counter(
        static_cast<double>(state.iterations()) * block / kFs, benchmark::Counter::kIsRate);
}

void registerGenerators() {
    for (const auto& g : soundscapes::generatorCatalogue())
        benchmark::RegisterBenchmark(("generator/" + g.name).c_str(), generator, g.name)
            ->MinTime(1.0);
}

} // namespace

// Long runs so that the rare events (rooster, cuckoo, cows) are part of the measurement.
BENCHMARK(allFive)->Arg(256)->Arg(1024)->MinTime(20.0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(one, beach_summer, std::string("beach_summer"))->Arg(512)->MinTime(5.0);
BENCHMARK_CAPTURE(one, farm_courtyard, std::string("farm_courtyard"))->Arg(512)->MinTime(5.0);
BENCHMARK_CAPTURE(one, ski_slope, std::string("ski_slope"))->Arg(512)->MinTime(5.0);
BENCHMARK_CAPTURE(one, forest, std::string("forest"))->Arg(512)->MinTime(5.0);
BENCHMARK_CAPTURE(one, park_fall, std::string("park_fall"))->Arg(512)->MinTime(5.0);

int main(int argc, char** argv) {
    registerGenerators();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
