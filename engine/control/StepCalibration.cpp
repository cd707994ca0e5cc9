// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/StepCalibration.h"

#include "base/TomlReader.h"

#include <fmt/core.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace underfoot::engine {

namespace {

/// Percentile by linear interpolation between order statistics (R's type 7).
double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const double h = (static_cast<double>(v.size()) - 1) * p;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

} // namespace

StepCalibrationResult calibrateSteps(const std::vector<ShoeFrame>& recording,
                                     const StepCalibrationOptions& o) {
    const auto span =
        static_cast<std::size_t>(std::lround(o.derivativeSpanMs * o.frameRateHz / 1000));
    if (span < 1 || !std::isfinite(o.frameRateHz) || o.frameRateHz <= 0)
        throw CalibrationError("calibration: expected a frame rate > 0 and a derivative span of "
                               "at least one frame");
    const auto minFrames = static_cast<std::size_t>(3 * o.frameRateHz);
    if (recording.size() < minFrames)
        throw CalibrationError(fmt::format(
            "calibration: expected at least 3 s of frames ({}), got {} frames; record longer",
            minFrames, recording.size()));
    StepCalibrationResult result;
    StepThresholds& t = result.thresholds;
    t.participant = o.participant;
    t.frameRateHz = o.frameRateHz;
    t.derivativeSpanMs = o.derivativeSpanMs;
    t.refractoryMs = o.refractoryMs;
    t.releaseHoldMs = o.releaseHoldMs;
    const double perSecond = o.frameRateHz / static_cast<double>(span);
    std::string errors;
    for (std::size_t s = 0; s < kShoeSensorCount; ++s) {
        const std::string name(shoeSensorName(s));
        std::vector<double> x(recording.size());
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = recording[i].raw[s];
        SensorCalibrationStats& st = result.stats[s];
        st.restLevel = percentile(x, 0.05);
        st.peakLevel = percentile(x, 0.99);
        const double range = st.peakLevel - st.restLevel;
        if (range < o.minRangeUnits) {
            errors += fmt::format("\n  {}: pressure range only {:.0f} units (rest {:.0f}, peak "
                                  "{:.0f}), expected at least {:.0f}: no steps seen; check the "
                                  "sensor's wiring and that the participant walked",
                                  name, range, st.restLevel, st.peakLevel, o.minRangeUnits);
            continue;
        }
        std::vector<double> d(x.size(), 0.0);
        for (std::size_t i = span; i < x.size(); ++i) d[i] = (x[i] - x[i - span]) * perSecond;
        // Derivative noise at rest: frames inside a run of at least 2 x 30 frames below
        // rest + 0.1 range, 30 frames away from both ends (so no rise or fall is included).
        std::vector<double> restNoise;
        const double quiet = st.restLevel + 0.1 * range;
        constexpr std::size_t margin = 30;
        for (std::size_t i = 0; i < x.size();) {
            if (x[i] >= quiet) {
                ++i;
                continue;
            }
            std::size_t end = i;
            while (end < x.size() && x[end] < quiet) ++end;
            for (std::size_t k = std::max(i + margin, span); k + margin < end; ++k)
                restNoise.push_back(std::fabs(d[k]));
            i = end;
        }
        st.noiseDerivativePerS = percentile(restNoise, 0.999);
        // Strikes: from below low to above mid; derivative peak over the rise.
        const double low = st.restLevel + 0.2 * range, mid = st.restLevel + 0.5 * range;
        std::vector<double> peaks;
        bool below = false;
        std::size_t riseStart = 0;
        for (std::size_t i = span; i < x.size(); ++i) {
            if (x[i] < low) {
                below = true;
                riseStart = i;
            } else if (below && x[i] >= mid) {
                below = false;
                double peak = 0;
                const std::size_t end = std::min(x.size(), i + span + 1);
                for (std::size_t k = riseStart; k < end; ++k) peak = std::max(peak, d[k]);
                peaks.push_back(peak);
            }
        }
        st.strikes = peaks.size();
        if (peaks.size() < o.minStrikes) {
            errors += fmt::format("\n  {}: {} foot strike{} found, expected at least {}; walk "
                                  "longer (about 20 s of normal walking)",
                                  name, peaks.size(), peaks.size() == 1 ? "" : "s", o.minStrikes);
            continue;
        }
        st.strikePeakMedianPerS = percentile(peaks, 0.5);
        st.strikePeakP10PerS = percentile(peaks, 0.1);
        StepSensorThresholds& th = t.sensors[s];
        th.restLevel = st.restLevel;
        th.peakLevel = st.peakLevel;
        const double fromStrikes = 0.35 * st.strikePeakP10PerS;
        const double fromNoise = 2 * st.noiseDerivativePerS;
        th.onsetDerivativePerS = std::max({fromStrikes, fromNoise, 1.0});
        if (fromNoise > 0.5 * st.strikePeakP10PerS)
            result.warnings.push_back(fmt::format(
                "{}: strikes barely above the noise (10th percentile strike derivative {:.0f}/s, "
                "noise {:.0f}/s); soft strikes may be missed",
                name, st.strikePeakP10PerS, st.noiseDerivativePerS));
        th.contactLevel = st.restLevel + 0.08 * range;
        th.releaseLevel = st.restLevel + 0.25 * range;
        th.referenceDerivativePerS = std::max(st.strikePeakMedianPerS, th.onsetDerivativePerS);
    }
    if (!errors.empty()) throw CalibrationError("calibration failed:" + errors);
    t.validate();
    return result;
}

void saveStepThresholds(const std::string& path, const StepThresholds& t,
                        const StepCalibrationResult* measured) {
    t.validate();
    toml::table root;
    root.insert("format", "underfoot-step-thresholds");
    root.insert("version", 1);
    root.insert("participant", t.participant);
    root.insert("frame_rate_hz", t.frameRateHz);
    root.insert("derivative_span_ms", t.derivativeSpanMs);
    root.insert("refractory_ms", t.refractoryMs);
    root.insert("release_hold_ms", t.releaseHoldMs);
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        const StepSensorThresholds& s = t.sensors[i];
        toml::table sensor;
        sensor.insert("rest_level", s.restLevel);
        sensor.insert("peak_level", s.peakLevel);
        sensor.insert("onset_derivative_per_s", s.onsetDerivativePerS);
        sensor.insert("contact_level", s.contactLevel);
        sensor.insert("release_level", s.releaseLevel);
        sensor.insert("reference_derivative_per_s", s.referenceDerivativePerS);
        if (measured) {
            const SensorCalibrationStats& m = measured->stats[i];
            toml::table stats;
            stats.insert("strikes", static_cast<std::int64_t>(m.strikes));
            stats.insert("noise_derivative_per_s", m.noiseDerivativePerS);
            stats.insert("strike_peak_median_per_s", m.strikePeakMedianPerS);
            stats.insert("strike_peak_p10_per_s", m.strikePeakP10PerS);
            sensor.insert("measured", std::move(stats));
        }
        root.insert(std::string(shoeSensorName(i)), std::move(sensor));
    }
    std::ofstream out(path);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
    out << "# Step-detection thresholds (underfoot sensors calibrate; docs/reference/sensors.md)\n"
        << "# levels in raw ADC units 0..1023, derivatives in units per second\n"
        << root << "\n";
    if (!out) throw std::runtime_error(fmt::format("{}: write failed", path));
}

StepThresholds loadStepThresholds(const std::string& path) {
    const toml::table root = base::parseTomlFile(path, "a readable step-thresholds file");
    // Unknown keys (a typo would silently keep a default) with the shared check.
    base::TomlReader keys(path, base::TomlReader::Mode::Throw);
    std::vector<std::string> top = {
        "format",        "version",        "participant", "frame_rate_hz", "derivative_span_ms",
        "refractory_ms", "release_hold_ms"};
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) top.emplace_back(shoeSensorName(i));
    keys.checkKeys(root, top, "a step-thresholds file");
    auto where = [&](const toml::node* n) {
        if (!n) return path;
        return fmt::format("{}:{}:{}", path, n->source().begin.line, n->source().begin.column);
    };
    auto number = [&](const toml::table& table, std::string_view key, std::string_view section,
                      double& out) {
        const toml::node* n = table.get(key);
        const auto v = n ? n->value<double>() : std::nullopt;
        if (!v || !std::isfinite(*v))
            throw std::runtime_error(fmt::format("{}: {}{}: expected a finite number{}",
                                                 where(n ? n : nullptr), section, key,
                                                 n ? "" : " (missing)"));
        out = *v;
    };
    const auto format = root["format"].value<std::string>();
    if (format != "underfoot-step-thresholds")
        throw std::runtime_error(fmt::format("{}: format: expected \"underfoot-step-thresholds\"",
                                             where(root.get("format"))));
    // as_integer, not value<int64_t>: toml++ casts a float such as 1e300 to int64_t unchecked
    // (undefined behaviour; the pattern fuzz_live_meters found).
    const auto* version = root["version"].as_integer();
    if (!version || version->get() != 1)
        throw std::runtime_error(
            fmt::format("{}: version: expected 1", where(root.get("version"))));
    StepThresholds t;
    t.participant = root["participant"].value_or(std::string{});
    number(root, "frame_rate_hz", "", t.frameRateHz);
    number(root, "derivative_span_ms", "", t.derivativeSpanMs);
    number(root, "refractory_ms", "", t.refractoryMs);
    number(root, "release_hold_ms", "", t.releaseHoldMs);
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        const std::string name(shoeSensorName(i));
        const toml::table* sensor = root[name].as_table();
        if (!sensor)
            throw std::runtime_error(
                fmt::format("{}: expected a table [{}] with the sensor's thresholds", path, name));
        const std::string section = "[" + name + "] ";
        keys.checkKeys(*sensor,
                       {"rest_level", "peak_level", "onset_derivative_per_s", "contact_level",
                        "release_level", "reference_derivative_per_s", "measured"},
                       "[" + name + "]");
        StepSensorThresholds& s = t.sensors[i];
        number(*sensor, "rest_level", section, s.restLevel);
        number(*sensor, "peak_level", section, s.peakLevel);
        number(*sensor, "onset_derivative_per_s", section, s.onsetDerivativePerS);
        number(*sensor, "contact_level", section, s.contactLevel);
        number(*sensor, "release_level", section, s.releaseLevel);
        number(*sensor, "reference_derivative_per_s", section, s.referenceDerivativePerS);
    }
    try {
        t.validate();
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(fmt::format("{}: {}", path, e.what()));
    }
    return t;
}

} // namespace underfoot::engine
