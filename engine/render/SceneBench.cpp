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

SceneBlocks::SceneBlocks(const SceneBenchSpec& spec) : spec_(spec) {
    if (spec.voices < 1 || spec.voices > 2)
        throw std::invalid_argument("measureScene: 1 or 2 voices (the walker's feet)");
    SceneOptions options;
    options.voices = spec.voices;
    options.reverb = spec.reverb;
    options.impulseResponse = spec.impulseResponse;
    scene_.build(spec.surface, options);
    const ProcessSpec ps{double(kBenchRateHz), kBenchBlock};
    scene_.prepare(ps);
    if (spec.ambience) spec.ambience->prepare(ps);
    grf_ = walkerGrf(WalkerParameters{}, spec.seconds, kBenchRateHz, spec.seed);
    blocks_ = grf_.frames() / kBenchBlock;
    for (auto* v : {&l_, &r_, &al_, &ar_}) v->assign(kBenchBlock, 0.0f);
}

void SceneBlocks::reset() {
    scene_.reset(spec_.seed);
    if (spec_.ambience) spec_.ambience->reset(spec_.seed);
    checksum_ = 0;
}

void SceneBlocks::process(std::size_t b) noexcept {
    const float* g[2];
    for (int v = 0; v < spec_.voices; ++v)
        g[v] = grf_.channels[static_cast<std::size_t>(v)].data() + b * kBenchBlock;
    scene_.process(g, l_.data(), r_.data(), kBenchBlock);
    if (spec_.ambience) { // the live headphone mix: background at unity gain
        spec_.ambience->process(al_.data(), ar_.data(), kBenchBlock);
        for (std::size_t i = 0; i < std::size_t(kBenchBlock); ++i) {
            l_[i] += al_[i];
            r_[i] += ar_[i];
        }
    }
    checksum_ += std::fabs(double(l_[0])) + std::fabs(double(r_[kBenchBlock - 1]));
}

SceneBenchResult measureScene(const SceneBenchSpec& spec) {
    SceneBlocks scene(spec);
    SceneBenchResult result;
    result.stats = timeBlocks(
        scene.blocks(), spec.repeats, kBenchBlock, kBenchRateHz, [&] { scene.reset(); },
        [&](std::size_t b) { scene.process(b); });
    result.hasReverb = scene.hasReverb();
    result.irLength = scene.reverbLength();
    result.checksum = scene.checksum();
    return result;
}

} // namespace underfoot::engine
