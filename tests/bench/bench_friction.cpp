// SPDX-License-Identifier: GPL-3.0-or-later
// Time of the friction's per-sample kernel (ElastoPlasticFriction::processSample) on the inputs
// the creaking_wood preset's friction layer gives it along a walk: ns per solved
// sample. The kernel's cost in time is set by its chain of dependent operations (each sample's
// solve starts from the last one's state), which instruction counts do not show; this measures
// it. The steady drag of `underfoot bench --only friction-creak` mostly slides fully; along a walk
// most samples are in the raised sine between stick and slip (the longer chain).
//
// The inputs are recorded once: the virtual walker's left foot (seed 7, 12 s) through the
// shipped creaking_wood preset's friction layer, read from engine/data/surfaces/creaking_wood.toml
// by the layer's own reader and driven by its own FrictionDrive (engine/surfaces/FrictionDrive.h),
// keeping the samples the layer solves (the others sleep). The benchmark then replays them into a
// fresh friction model.
// Run: build/tests/bench/bench_friction (counter "per sample": time per solved sample).
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Denormals.h"
#include "engine/models/Friction.h"
#include "engine/surfaces/FrictionDrive.h"
#include "engine/surfaces/Surface.h"

#include <benchmark/benchmark.h>

#include <stdexcept>
#include <string>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

// creaking_wood.toml's friction layer as shipped (not configureCreakScenario of
// engine/render/AccuracyCost.h: that one keeps the values of the time, sigma3 0.05 and a
// 2.65 kHz top mode, so that its figures stay comparable with the Sound Design Toolkit's)
const FrictionLayerSettings& creak() {
    static const FrictionLayerSettings settings = [] {
        const std::string file = surfacesDirectory() + "/creaking_wood.toml";
        const toml::table root = toml::parse_file(file);
        const toml::array* layers = root["layer"].as_array();
        for (std::size_t i = 0; layers && i < layers->size(); ++i) {
            const toml::table* t = layers->get(i)->as_table();
            if (!t || (*t)["type"].value_or(std::string()) != "friction") continue;
            PresetReader reader(file, *t, "layer[" + std::to_string(i) + "]", nullptr);
            return readFrictionLayer(reader, AccuracyOptions{});
        }
        throw std::runtime_error(file + ": expected a [[layer]] with type = \"friction\"");
    }();
    return settings;
}

void configureCreak(ElastoPlasticFriction& f) {
    f.configure(creak().model, creak().modes, {creak().gains});
    f.prepare(kFs);
    f.reset(7);
}

const std::vector<FrictionDrive::Input>& walkDrive() {
    static const std::vector<FrictionDrive::Input> drive = [] {
        VirtualWalker walker;
        walker.prepare({kFs, 256});
        walker.reset(7);
        std::vector<float> left(static_cast<std::size_t>(12 * kFs)), right(left.size());
        walker.process(left.data(), right.data(), static_cast<int>(left.size()));
        ElastoPlasticFriction f;
        configureCreak(f);
        FrictionDrive layer;
        layer.configure(creak().drive);
        layer.prepare(kFs);
        layer.reset();
        std::vector<FrictionDrive::Input> d;
        FrictionDrive::Input in;
        for (float g : left) { // (as FrictionLayer::processSpan)
            if (!layer.next(g, f, in)) continue;
            d.push_back(in);
            layer.settle(
                f.processSample(in.normal, 0.0, in.anchor, in.anchorVelocity, in.roughness), in, f);
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
        for (const FrictionDrive::Input& d : drive) {
            if (d.unloaded) f.relax();
            sum += f.processSample(d.normal, 0.0, d.anchor, d.anchorVelocity, d.roughness);
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
