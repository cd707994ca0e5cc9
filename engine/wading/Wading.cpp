// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/wading/Wading.h"

#include "engine/dsp/Denormals.h"
#include "engine/wading/Gait.h"
#include "engine/wading/WadingScene.h"

#include <fmt/core.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace underfoot::engine {

namespace {
double parseNumber(const std::string& key, const std::string& value, const char* expected) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(v) ||
        errno == ERANGE)
        throw WadingOptionError(
            fmt::format("wading parameter {} = \"{}\": expected {}", key, value, expected));
    return v;
}
} // namespace

void validateWadingOptions(const WadingOptions& o) {
    if (o.depth.empty())
        throw WadingOptionError("wading option depth: expected shallow, deep or a preset path");
    if (o.algorithm != "v1" && o.algorithm != "v2")
        throw WadingOptionError(
            fmt::format("wading option algorithm = \"{}\": expected v1 or v2", o.algorithm));
    try {
        parseGyroFilter(o.filter);
    } catch (const std::invalid_argument& e) {
        throw WadingOptionError(fmt::format("wading option {}", e.what()));
    }
    if (!std::isfinite(o.cadenceStepsPerMin) ||
        (o.cadenceStepsPerMin != 0 && (o.cadenceStepsPerMin < 10 || o.cadenceStepsPerMin > 160)))
        throw WadingOptionError(
            fmt::format("wading option cadence = {}: expected 0 (standing) or [10, 160] steps/min",
                        o.cadenceStepsPerMin));
    if (!std::isfinite(o.strideM) || (o.strideM != 0 && (o.strideM < 0.2 || o.strideM > 2.5)))
        throw WadingOptionError(fmt::format(
            "wading option stride = {} m: expected [0.2, 2.5] m or 0 (from the cadence)",
            o.strideM));
    if (!std::isfinite(o.sampleRateHz) || o.sampleRateHz < 8000 || o.sampleRateHz > 384000)
        throw WadingOptionError(fmt::format(
            "wading option sample rate = {} Hz: expected [8000, 384000] Hz", o.sampleRateHz));
}

WadingOptions wadingOptionsFromParameters(const std::map<std::string, std::string>& params) {
    WadingOptions o;
    for (const auto& [key, value] : params) {
        if (key == "depth") {
            if (value != "shallow" && value != "deep")
                throw WadingOptionError(fmt::format(
                    "wading parameter depth = \"{}\": expected shallow or deep", value));
            o.depth = value;
        } else if (key == "algorithm") {
            if (value != "v1" && value != "v2")
                throw WadingOptionError(
                    fmt::format("wading parameter algorithm = \"{}\": expected v1 or v2", value));
            o.algorithm = value;
        } else if (key == "filter") {
            if (value != "butterworth_5hz" && value != "butterworth_0_8hz" && value != "asymmetric")
                throw WadingOptionError(
                    fmt::format("wading parameter filter = \"{}\": expected butterworth_5hz, "
                                "butterworth_0_8hz or asymmetric",
                                value));
            o.filter = value;
        } else if (key == "cadence") {
            if (value == "slow")
                o.cadenceStepsPerMin = kSlowCadence;
            else if (value == "normal" || value == "medium")
                o.cadenceStepsPerMin = kNormalCadence;
            else if (value == "fast")
                o.cadenceStepsPerMin = kFastCadence;
            else if (value == "standing")
                o.cadenceStepsPerMin = 0;
            else
                o.cadenceStepsPerMin = parseNumber(
                    key, value,
                    "slow (27), normal (63), fast (118), standing (0) or steps per minute");
        } else if (key == "stride_m" || key == "stride") {
            o.strideM =
                parseNumber(key, value, "a stride in metres, [0.2, 2.5], or 0 (from the cadence)");
        } else if (key == "seed") {
            char* end = nullptr;
            errno = 0;
            const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
            if (value.empty() || value[0] == '-' || end != value.c_str() + value.size() ||
                errno == ERANGE)
                throw WadingOptionError(fmt::format(
                    "wading parameter seed = \"{}\": expected a non-negative integer", value));
            o.seed = v;
        } else if (key == "sample_rate_hz") {
            o.sampleRateHz = parseNumber(key, value, "a sample rate in Hz");
        } else {
            throw WadingOptionError(fmt::format(
                "unknown wading parameter \"{}\": expected depth, algorithm, filter, cadence, "
                "stride_m, seed or sample_rate_hz",
                key));
        }
    }
    validateWadingOptions(o);
    return o;
}

namespace {
AudioBuffer renderFrames(const WadingOptions& o, const std::vector<GaitFrame>& gait,
                         std::size_t totalSamples, LimiterReport* report) {
    validateWadingOptions(o);
    const WadingPreset preset = loadWadingPreset(o.depth);
    WadingScene scene;
    scene.configure(preset, parseWadingAlgorithm(o.algorithm), parseGyroFilter(o.filter));
    constexpr int kBlock = 256;
    scene.prepare({o.sampleRateHz, kBlock});
    scene.reset(o.seed);
    AudioBuffer out;
    out.sampleRateHz = o.sampleRateHz;
    out.channels = 2;
    out.samples.assign(totalSamples * 2, 0.0f);
    StereoSafetyLimiter limiter; // the output stage of every offline render
    limiter.prepare(o.sampleRateHz);
    std::vector<float> l(kBlock), r(kBlock);
    std::vector<TimedGaitFrame> events;
    events.reserve(kBlock);
    ScopedFlushDenormals ftz;
    std::size_t next = 0;
    for (std::size_t start = 0; start < totalSamples; start += kBlock) {
        const int n = static_cast<int>(std::min<std::size_t>(kBlock, totalSamples - start));
        events.clear();
        // Frame k (at k / 100 s) takes effect at the sample where it arrives.
        while (next < gait.size()) {
            const auto at = static_cast<std::size_t>(
                std::llround(static_cast<double>(next) / kGaitFrameRateHz * o.sampleRateHz));
            if (at >= start + static_cast<std::size_t>(n)) break;
            events.push_back({static_cast<int>(at - std::min(at, start)), gait[next]});
            ++next;
        }
        scene.process(events.data(), static_cast<int>(events.size()), l.data(), r.data(), n);
        limiter.process(l.data(), r.data(), n);
        for (int i = 0; i < n; ++i) {
            out.samples[2 * (start + static_cast<std::size_t>(i))] = l[static_cast<std::size_t>(i)];
            out.samples[2 * (start + static_cast<std::size_t>(i)) + 1] =
                r[static_cast<std::size_t>(i)];
        }
    }
    if (report) *report = limiter.report();
    return out;
}
} // namespace

AudioBuffer renderWading(const WadingOptions& options, double seconds, LimiterReport* limiter) {
    validateWadingOptions(options);
    if (!std::isfinite(seconds) || seconds <= 0 || seconds > 3600)
        throw WadingOptionError(
            fmt::format("wading duration {} s: expected (0, 3600] seconds", seconds));
    VirtualGaitParameters p;
    p.cadenceStepsPerMin = options.cadenceStepsPerMin;
    p.strideM = options.strideM;
    const auto gait = virtualGait(p, seconds, options.seed);
    return renderFrames(options, gait,
                        static_cast<std::size_t>(std::llround(seconds * options.sampleRateHz)),
                        limiter);
}

AudioBuffer renderWading(const WadingOptions& options, const std::vector<GaitFrame>& gait,
                         LimiterReport* limiter) {
    if (gait.empty()) throw WadingOptionError("wading: the gait recording has no frames");
    const double seconds = static_cast<double>(gait.size()) / kGaitFrameRateHz;
    return renderFrames(options, gait,
                        static_cast<std::size_t>(std::llround(seconds * options.sampleRateHz)),
                        limiter);
}

WadingDepthContrast measureDepthContrast(WadingOptions options, double seconds) {
    WadingDepthContrast c;
    options.depth = "shallow";
    c.shallow = computeFeatures(renderWading(options, seconds));
    options.depth = "deep";
    c.deep = computeFeatures(renderWading(options, seconds));
    return c;
}

} // namespace underfoot::engine
