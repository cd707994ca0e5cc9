// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/wading/WadingLatency.h"

#include "engine/dsp/Denormals.h"
#include "engine/wading/Gait.h"
#include "engine/wading/WadingScene.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace underfoot::engine {

WadingLatencyReport measureWadingLatency(const WadingOptions& o, int blockSize, double stepDps) {
    validateWadingOptions(o);
    if (blockSize < 1 || blockSize > 8192)
        throw std::invalid_argument("latency: block size must be in [1, 8192]");
    WadingScene scene;
    scene.configure(loadWadingPreset(o.depth), parseWadingAlgorithm(o.algorithm),
                    parseGyroFilter(o.filter));
    scene.prepare({o.sampleRateHz, blockSize});
    scene.reset(o.seed);
    const double fs = o.sampleRateHz;
    const auto total = static_cast<std::size_t>(std::llround(1.8 * fs));
    const std::size_t b = static_cast<std::size_t>(blockSize);
    // The step's frame (at 0.2 s) arrives one sample after the start of a block.
    const std::size_t blockOfStep = static_cast<std::size_t>(std::llround(0.2 * fs)) / b + 1;
    const std::size_t arrival = blockOfStep * b + 1;
    const double frameSamples = fs / kGaitFrameRateHz;
    std::vector<float> l(b), r(b), mono;
    mono.reserve(total + b);
    GaitFrame still{}, step{};
    step.angularVelocityDps.fill(stepDps);
    double nextFrameSample = 0; // frames keep arriving every 10 ms, relative to the step's arrival
    const double firstFrame =
        static_cast<double>(arrival) -
        std::floor(static_cast<double>(arrival) / frameSamples) * frameSamples;
    nextFrameSample = firstFrame;
    ScopedFlushDenormals ftz;
    for (std::size_t start = 0; start < total; start += b) {
        // Frames that arrived during the previous block are handed over now (live path).
        while (nextFrameSample < static_cast<double>(start)) {
            const bool after = nextFrameSample >= static_cast<double>(arrival) - 0.5;
            scene.pushFrame(after ? step : still);
            nextFrameSample += frameSamples;
        }
        scene.process(nullptr, 0, l.data(), r.data(), static_cast<int>(b));
        for (std::size_t i = 0; i < b; ++i) mono.push_back(0.5f * (l[i] + r[i]));
    }
    WadingLatencyReport rep;
    rep.blockMs = 1000.0 * static_cast<double>(b) / fs;
    auto ms = [&](std::size_t sample) {
        return 1000.0 * (static_cast<double>(sample) - static_cast<double>(arrival)) / fs;
    };
    const double audible = std::pow(10.0, -60.0 / 20.0);
    bool changed = false, heard = false;
    for (std::size_t i = 0; i < mono.size(); ++i) {
        if (!changed && mono[i] != 0.0f) changed = true, rep.firstChangeMs = ms(i);
        if (!heard && std::fabs(mono[i]) > audible) heard = true, rep.firstAudibleMs = ms(i);
    }
    if (!changed) rep.firstChangeMs = rep.firstAudibleMs = -1;
    if (!heard) rep.firstAudibleMs = -1;
    // Settled level 1.0-1.5 s after the step; first 5 ms window within 6 dB of it.
    const auto win = static_cast<std::size_t>(std::llround(0.005 * fs));
    auto rms = [&](std::size_t from, std::size_t len) {
        double s = 0;
        for (std::size_t i = from; i < from + len && i < mono.size(); ++i)
            s += double(mono[i]) * mono[i];
        return std::sqrt(s / static_cast<double>(len));
    };
    const double settled =
        rms(arrival + static_cast<std::size_t>(fs), static_cast<std::size_t>(0.5 * fs));
    rep.withinSixDbMs = -1;
    for (std::size_t w = arrival; w + win < mono.size(); w += win / 5) {
        if (rms(w, win) >= settled * 0.5) {
            rep.withinSixDbMs = ms(w + win);
            break;
        }
    }
    const auto& lp = scene.control().lowpass(Limb::LeftThigh);
    rep.groupDelayDcMs = 1000.0 * lp.groupDelaySeconds(kGaitFrameRateHz, 0.0);
    rep.groupDelay1HzMs = 1000.0 * lp.groupDelaySeconds(kGaitFrameRateHz, 1.0);
    rep.rightGroupDelayDcMs =
        1000.0 * scene.control().lowpass(Limb::RightThigh).groupDelaySeconds(kGaitFrameRateHz, 0.0);
    return rep;
}

} // namespace underfoot::engine
