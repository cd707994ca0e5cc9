// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/StepDetector.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

void StepThresholds::validate() const {
    auto positive = [](double v, std::string_view what) {
        if (!std::isfinite(v) || v <= 0)
            throw std::invalid_argument(
                fmt::format("{}: expected a finite number > 0, got {}", what, v));
    };
    positive(frameRateHz, "frame_rate_hz");
    positive(derivativeSpanMs, "derivative_span_ms");
    if (derivativeSpanMs * frameRateHz / 1000.0 > 63)
        throw std::invalid_argument(
            fmt::format("derivative_span_ms: expected at most 63 frames, got {} ms at {} Hz",
                        derivativeSpanMs, frameRateHz));
    if (!std::isfinite(refractoryMs) || refractoryMs < 0)
        throw std::invalid_argument(
            fmt::format("refractory_ms: expected a finite number >= 0, got {}", refractoryMs));
    if (!std::isfinite(releaseHoldMs) || releaseHoldMs < 0)
        throw std::invalid_argument(
            fmt::format("release_hold_ms: expected a finite number >= 0, got {}", releaseHoldMs));
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        const StepSensorThresholds& s = sensors[i];
        const std::string name(shoeSensorName(i));
        for (double v : {s.restLevel, s.peakLevel, s.contactLevel, s.releaseLevel})
            if (!std::isfinite(v) || v < 0 || v > 65535)
                throw std::invalid_argument(
                    fmt::format("{}: expected levels in 0..65535, got {}", name, v));
        positive(s.onsetDerivativePerS, name + ".onset_derivative_per_s");
        positive(s.referenceDerivativePerS, name + ".reference_derivative_per_s");
        if (!(s.releaseLevel > s.contactLevel))
            throw std::invalid_argument(
                fmt::format("{}: expected release_level ({}) above contact_level ({})", name,
                            s.releaseLevel, s.contactLevel));
        if (!(s.peakLevel > s.restLevel))
            throw std::invalid_argument(
                fmt::format("{}: expected peak_level ({}) above rest_level ({})", name, s.peakLevel,
                            s.restLevel));
    }
}

StepDetector::StepDetector(const StepThresholds& thresholds) : thresholds_(thresholds) {
    thresholds_.validate();
    const double framesPerMs = thresholds_.frameRateHz / 1000.0;
    span_ = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::lround(thresholds_.derivativeSpanMs * framesPerMs)), 1,
        kMaxSpan - 1);
    releaseHoldFrames_ =
        static_cast<std::uint32_t>(std::lround(thresholds_.releaseHoldMs * framesPerMs));
    refractoryFrames_ =
        static_cast<std::uint64_t>(std::llround(thresholds_.refractoryMs * framesPerMs));
    reset();
}

void StepDetector::reset() noexcept {
    head_ = 0;
    for (SensorState& s : state_) s = SensorState{};
}

std::size_t StepDetector::process(const ShoeFrame& frame, Events& out) noexcept {
    std::size_t count = 0;
    head_ = (head_ + 1) % kMaxSpan;
    const double perSecond = thresholds_.frameRateHz / static_cast<double>(span_);
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        SensorState& s = state_[i];
        const StepSensorThresholds& t = thresholds_.sensors[i];
        const std::uint16_t x = frame.raw[i];
        s.history[head_] = x;
        if (s.filled < span_ + 1) ++s.filled;
        if (s.framesSinceStep < ~std::uint64_t{0}) ++s.framesSinceStep;
        const double level = x;
        // Re-arm only after a release held for releaseHoldMs.
        if (level < t.releaseLevel) {
            if (s.framesBelowRelease < 0xffffffffu) ++s.framesBelowRelease;
            if (s.framesBelowRelease >= releaseHoldFrames_) s.armed = true;
        } else {
            s.framesBelowRelease = 0;
        }
        if (s.filled <= span_) {
            s.derivative = 0;
            continue;
        }
        const std::uint16_t past = s.history[(head_ + kMaxSpan - span_) % kMaxSpan];
        s.derivative = (level - static_cast<double>(past)) * perSecond;
        if (s.armed && s.derivative > t.onsetDerivativePerS && level >= t.contactLevel &&
            s.framesSinceStep >= refractoryFrames_) {
            StepEvent& e = out[count++];
            e.timeS = frame.timeS;
            e.deviceMs = frame.deviceMs;
            e.frameIndex = frame.index;
            e.foot = shoeSensorFoot(i);
            e.part = shoeSensorPart(i);
            e.derivativePerS = static_cast<float>(s.derivative);
            e.strength =
                static_cast<float>(std::clamp(s.derivative / t.referenceDerivativePerS, 0.0, 1.0));
            e.pressure = x;
            s.armed = false;
            s.framesBelowRelease = 0;
            s.framesSinceStep = 0;
        }
    }
    return count;
}

} // namespace underfoot::engine
