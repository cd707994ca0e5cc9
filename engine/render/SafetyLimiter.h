// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A transparent safety limiter for the output of the offline renderer and the live engine.
///
/// It never acts on a signal whose peaks stay below the ceiling (gain exactly 1: the samples
/// pass bit for bit, so renders stay byte-identical), and it never lets a sample through above
/// the ceiling: when a sample (any channel) would exceed it, the gain drops at once to exactly
/// what brings it to the ceiling (zero latency: no look-ahead on the live path), then recovers
/// exponentially with the release time constant. It counts the samples it touched and the
/// deepest reduction so that the caller can report that it acted. process() does not allocate,
/// lock, log or throw (audio thread).
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace underfoot::engine {

struct LimiterReport {
    std::int64_t samplesLimited = 0; ///< frames whose gain was below 1
    double maxReductionDb = 0;       ///< deepest gain reduction, dB (>= 0)
    bool acted() const noexcept { return samplesLimited > 0; }
};

class SafetyLimiter {
  public:
    /// Ceiling in dBFS (default -0.3: inter-sample headroom for 24-bit PCM files) and release
    /// time constant in seconds.
    void prepare(double sampleRateHz, double ceilingDb = -0.3,
                 double releaseSeconds = 0.05) noexcept {
        ceiling_ = std::pow(10.0, ceilingDb / 20.0);
        release_ = 1.0 - std::exp(-1.0 / (std::max(releaseSeconds, 1e-4) * sampleRateHz));
        reset();
    }
    void reset() noexcept {
        gain_ = 1.0;
        report_ = {};
    }
    /// Limits n frames in place; with both channels the gain is linked (right may be null).
    void process(float* left, float* right, int n) noexcept {
        for (int i = 0; i < n; ++i) {
            if (gain_ < 1.0) {
                gain_ += (1.0 - gain_) * release_;
                if (gain_ > 1.0 - 1e-9) gain_ = 1.0;
            }
            const double peak =
                std::max(std::fabs(double(left[i])), right ? std::fabs(double(right[i])) : 0.0);
            if (peak * gain_ > ceiling_) gain_ = ceiling_ / peak;
            if (gain_ < 1.0) {
                // Rounding to float must not push the sample back above the ceiling.
                left[i] = clampToCeiling(double(left[i]) * gain_);
                if (right) right[i] = clampToCeiling(double(right[i]) * gain_);
                ++report_.samplesLimited;
                report_.maxReductionDb =
                    std::max(report_.maxReductionDb, -20.0 * std::log10(gain_));
            }
        }
    }
    const LimiterReport& report() const noexcept { return report_; }
    double ceiling() const noexcept { return ceiling_; }

  private:
    float clampToCeiling(double v) const noexcept {
        auto f = static_cast<float>(v);
        const auto c = static_cast<float>(ceiling_);
        return f > c ? c : (f < -c ? -c : f);
    }
    double ceiling_ = 1.0, release_ = 1.0, gain_ = 1.0;
    LimiterReport report_;
};

/// The offline renderers' output stage: left and right limited independently, exactly as the
/// live engine limits each device output on its own, so that a render and what the live path
/// played stay sample-identical even when the limiter acts.
class StereoSafetyLimiter {
  public:
    void prepare(double sampleRateHz) noexcept {
        left_.prepare(sampleRateHz);
        right_.prepare(sampleRateHz);
    }
    void process(float* left, float* right, int n) noexcept {
        left_.process(left, nullptr, n);
        right_.process(right, nullptr, n);
    }
    LimiterReport report() const noexcept {
        LimiterReport r;
        r.samplesLimited = left_.report().samplesLimited + right_.report().samplesLimited;
        r.maxReductionDb = std::max(left_.report().maxReductionDb, right_.report().maxReductionDb);
        return r;
    }

  private:
    SafetyLimiter left_, right_;
};

} // namespace underfoot::engine
