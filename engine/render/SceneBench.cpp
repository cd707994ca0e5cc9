// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/SceneBench.h"

#include "engine/render/Renderer.h"
#include "engine/scene/LiveScene.h" // AmbienceSource

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <stdexcept>

namespace underfoot::engine {

namespace {
double cpuSeconds(BenchClock clock) noexcept {
    timespec ts{};
    clock_gettime(clock == BenchClock::Thread ? CLOCK_THREAD_CPUTIME_ID : CLOCK_PROCESS_CPUTIME_ID,
                  &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
} // namespace

BlockCostStats timeBlocks(std::size_t blocks, int repeats, int samplesPerBlock, double sampleRateHz,
                          const std::function<void()>& reset,
                          const std::function<void(std::size_t)>& block, BenchClock clock) {
    if (blocks == 0 || repeats < 1 || samplesPerBlock < 1 || !(sampleRateHz > 0))
        throw std::invalid_argument("timeBlocks: needs blocks, repeats, samples per block >= 1");
    using Clock = std::chrono::steady_clock;
    std::vector<double> best(blocks, 1e300);
    double fastestRun = 1e300;
    for (int r = 0; r < repeats; ++r) {
        reset();
        const double c0 = cpuSeconds(clock);
        for (std::size_t b = 0; b < blocks; ++b) {
            const auto t0 = Clock::now();
            block(b);
            const auto t1 = Clock::now();
            best[b] = std::min(best[b], std::chrono::duration<double, std::micro>(t1 - t0).count());
        }
        fastestRun = std::min(fastestRun, cpuSeconds(clock) - c0);
    }
    BlockCostStats s;
    s.blocks = blocks;
    s.repeats = repeats;
    const double samples = double(blocks) * samplesPerBlock;
    s.nsPerSample = 1e9 * fastestRun / samples;
    s.realTimeFactor = samples / sampleRateHz / std::max(fastestRun, 1e-12);
    double sum = 0;
    for (double v : best) sum += v;
    s.minimaNsPerSample = 1e3 * sum / samples;
    std::vector<double> sorted = best;
    std::sort(sorted.begin(), sorted.end());
    s.medianUs = sorted[sorted.size() / 2];
    s.p99Us = sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
    s.worstUs = sorted.back();
    return s;
}

SceneBenchResult measureScene(const SceneBenchSpec& spec) {
    if (spec.voices < 1 || spec.voices > 2)
        throw std::invalid_argument("measureScene: 1 or 2 voices (the walker's feet)");
    FootstepScene scene;
    SceneOptions options;
    options.voices = spec.voices;
    options.reverb = spec.reverb;
    options.impulseResponse = spec.impulseResponse;
    scene.build(spec.surface, options);
    const ProcessSpec ps{double(kBenchRateHz), kBenchBlock};
    scene.prepare(ps);
    if (spec.ambience) spec.ambience->prepare(ps);
    const GrfSignal grf = walkerGrf(WalkerParameters{}, spec.seconds, kBenchRateHz, spec.seed);
    const std::size_t blocks = grf.frames() / kBenchBlock;
    std::vector<float> l(kBenchBlock), r(kBenchBlock), al(kBenchBlock), ar(kBenchBlock);
    SceneBenchResult result;
    double checksum = 0;
    result.stats = timeBlocks(
        blocks, spec.repeats, kBenchBlock, kBenchRateHz,
        [&] {
            scene.reset(spec.seed);
            if (spec.ambience) spec.ambience->reset(spec.seed);
            checksum = 0;
        },
        [&](std::size_t b) {
            const float* g[2];
            for (int v = 0; v < spec.voices; ++v)
                g[v] = grf.channels[static_cast<std::size_t>(v)].data() + b * kBenchBlock;
            scene.process(g, l.data(), r.data(), kBenchBlock);
            if (spec.ambience) { // the live headphone mix: background at unity gain
                spec.ambience->process(al.data(), ar.data(), kBenchBlock);
                for (int i = 0; i < kBenchBlock; ++i) {
                    l[static_cast<std::size_t>(i)] += al[static_cast<std::size_t>(i)];
                    r[static_cast<std::size_t>(i)] += ar[static_cast<std::size_t>(i)];
                }
            }
            checksum += std::fabs(double(l[0])) + std::fabs(double(r[kBenchBlock - 1]));
        });
    result.hasReverb = scene.hasReverb();
    result.irLength = scene.reverbLength();
    result.checksum = checksum;
    return result;
}

} // namespace underfoot::engine
