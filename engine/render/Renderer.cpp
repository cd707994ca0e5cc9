// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/Renderer.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <stdexcept>

namespace underfoot::engine {

double threadCpuSeconds() noexcept {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

GrfSignal walkerGrf(const WalkerParameters& walker, double seconds, double fs, std::uint64_t seed) {
    if (!(seconds > 0.0 && seconds <= 24 * 3600.0))
        throw std::invalid_argument(
            fmt::format("duration must be in (0, 86400] s, got {}", seconds));
    VirtualWalker w(walker);
    const int block = 512;
    w.prepare({fs, block});
    w.reset(seed);
    // The walker walks for `seconds` and then stops: every stance under way is completed, no
    // new step starts (a GRF cut mid-stance would be a step no foot made).
    const auto frames = static_cast<std::size_t>(std::llround(seconds * fs));
    const auto extra = static_cast<std::size_t>(std::llround(2.0 * w.strideSeconds() * fs));
    GrfSignal grf;
    grf.sampleRateHz = fs;
    grf.names = {"left", "right"};
    grf.channels.assign(2, std::vector<float>(frames + extra));
    for (std::size_t i = 0; i < frames + extra; i += block) {
        const int n = static_cast<int>(std::min<std::size_t>(block, frames + extra - i));
        w.process(grf.channels[0].data() + i, grf.channels[1].data() + i, n);
    }
    std::size_t end = frames;
    for (auto& c : grf.channels) {
        std::size_t k = frames;
        while (k < c.size() && c[k] > 0.0f) ++k; // finish the stance under way
        std::fill(c.begin() + static_cast<long>(k), c.end(), 0.0f);
        end = std::max(end, k + 1); // keep one sample of the swing: the signal ends at rest
    }
    for (auto& c : grf.channels) c.resize(end);
    return grf;
}

RenderResult renderSurface(const std::string& surface, const GrfSignal& grf,
                           const RenderOptions& options) {
    if (grf.channels.empty() || grf.frames() == 0)
        throw std::invalid_argument("the GRF has no samples");
    if (std::fabs(grf.sampleRateHz - options.sampleRateHz) > 1e-6)
        throw std::invalid_argument(
            fmt::format("the GRF is at {} Hz, the render at {} Hz: resample it first",
                        grf.sampleRateHz, options.sampleRateHz));
    SceneOptions sceneOptions = options.scene;
    sceneOptions.voices = static_cast<int>(grf.channels.size());
    FootstepScene scene;
    scene.build(surface, sceneOptions);
    scene.prepare({options.sampleRateHz, options.blockSize});
    scene.reset(options.seed);
    scene.setMeasureCost(true);

    const std::size_t frames =
        grf.frames() +
        static_cast<std::size_t>(std::llround(options.tailSeconds * options.sampleRateHz));
    RenderResult result;
    result.audio.sampleRateHz = options.sampleRateHz;
    result.audio.channels = 2;
    result.audio.samples.assign(frames * 2, 0.0f);
    const auto bs = static_cast<std::size_t>(options.blockSize);
    std::vector<std::vector<float>> in(grf.channels.size(), std::vector<float>(bs));
    std::vector<const float*> inPtr(grf.channels.size());
    std::vector<float> l(bs), r(bs);
    StereoSafetyLimiter limiter;
    limiter.prepare(options.sampleRateHz);
    const double t0 = threadCpuSeconds();
    for (std::size_t start = 0; start < frames; start += bs) {
        const std::size_t n = std::min(bs, frames - start);
        for (std::size_t c = 0; c < grf.channels.size(); ++c) {
            for (std::size_t i = 0; i < n; ++i) {
                const std::size_t k = start + i;
                in[c][i] = k < grf.frames() ? grf.channels[c][k] : 0.0f;
            }
            inPtr[c] = in[c].data();
        }
        scene.process(inPtr.data(), l.data(), r.data(), static_cast<int>(n));
        if (options.limit) limiter.process(l.data(), r.data(), static_cast<int>(n));
        for (std::size_t i = 0; i < n; ++i) {
            result.audio.samples[2 * (start + i)] = l[i];
            result.audio.samples[2 * (start + i) + 1] = r[i];
        }
    }
    result.cpuSeconds = threadCpuSeconds() - t0;
    result.realTimeFactor =
        (double(frames) / options.sampleRateHz) / std::max(result.cpuSeconds, 1e-9);
    result.cost = scene.cost();
    result.flushedDenormals = scene.flushedDenormals();
    result.limiter = limiter.report();
    for (float v : result.audio.samples)
        if (!std::isfinite(v))
            throw std::runtime_error("render produced a non-finite sample (engine bug)");
    return result;
}

} // namespace underfoot::engine
