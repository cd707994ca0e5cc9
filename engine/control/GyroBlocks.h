// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reusable control blocks for gyroscope (angular-velocity) data, after the wading chain of the
/// gait sonification paper (the wading study, §3.3 and §6.1; docs/explanation/studies.md). Each
/// block processes one control sample at a time at the sensor frame rate (100 Hz in the paper); all
/// are noexcept and allocation-free after prepare().
///
///  - GyroLowpass: 2nd-order Butterworth low-pass (RBJ biquad, Q = 1/sqrt(2); the paper quotes
///    "Q-factor of 0.7") at 5 Hz or 0.8 Hz, with an optional make-up gain (the 0.8 Hz variant
///    "followed by a gain factor to compensate for the resulting amplitude decrease", §5).
///  - normaliseForward(): forward rotation 0..100 deg/s -> 0..1; backward rotation pinned to 0,
///    above the range pinned to 1 (§3.3).
///  - sumClamped(): left + right summed (only one limb swings forward at a time), kept in 0..1
///    ("C1–C3 were also constrained to a 0–1 range", §6.2).
///  - GyroEnvelope: attack/release follower, eq. (1)–(5): g = exp(ln(0.01) / (t_ms fs 0.001)),
///    env[t] = x[t] + g (env[t-1] - x[t]), attack coefficient when x[t] > env[t-1].
///  - powerShape(): y = x^k on [0, 1], k in [0.35, 6] (eq. 6).
///  - ControlDelay: a fixed delay in control samples (the 150 ms splash delay).
///  - ControlRamp: linear interpolation of a control to audio rate over one frame period (the
///    hold/resampler between 100 Hz frames and the audio-rate gains).
#include "engine/dsp/Biquad.h"
#include "engine/dsp/Envelope.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace underfoot::engine {

/// Forward rotation normalised to 0..1: x / rangeDps clamped to [0, 1] (NaN gives 0).
inline double normaliseForward(double angularVelocityDps, double rangeDps = 100.0) noexcept {
    const double v = angularVelocityDps / rangeDps;
    if (!(v > 0.0)) return 0.0;
    return v < 1.0 ? v : 1.0;
}

/// Weighted sum of two 0..1 controls, clamped to [0, 1].
inline double sumClamped(double a, double b, double weightA = 1.0, double weightB = 1.0) noexcept {
    const double s = weightA * a + weightB * b;
    if (!(s > 0.0)) return 0.0;
    return s < 1.0 ? s : 1.0;
}

/// y = x^k for x clamped to [0, 1] (eq. 6 of the paper; k = 1 is the identity).
inline double powerShape(double x, double k) noexcept {
    if (!(x > 0.0)) return 0.0;
    if (x >= 1.0) return 1.0;
    return k == 1.0 ? x : std::pow(x, k);
}

/// Linear gain of a fader mapped from a 0..1 control onto [minDb, maxDb] ("scaled and positively
/// mapped to the fader control", §6.2).
inline double faderDb(double control, double minDb, double maxDb) noexcept {
    return minDb + (maxDb - minDb) * std::clamp(control, 0.0, 1.0);
}

/// 2nd-order Butterworth low-pass for gyroscope data at the frame rate.
class GyroLowpass {
  public:
    /// Designs the filter (cutoff below frameRate / 2) with a make-up gain (1 = none).
    void design(double frameRateHz, double cutoffHz, double makeUpGain = 1.0);
    void reset() noexcept { biquad_.reset(); }
    double processSample(double x) noexcept { return gain_ * biquad_.processSample(x); }
    double cutoffHz() const noexcept { return cutoffHz_; }
    double makeUpGain() const noexcept { return gain_; }
    const BiquadCoefficients& coefficients() const noexcept { return biquad_.coefficients(); }
    /// Group delay at `frequencyHz` in seconds (numerical derivative of the phase).
    double groupDelaySeconds(double frameRateHz, double frequencyHz) const noexcept;

  private:
    Biquad biquad_;
    double cutoffHz_ = 5.0, gain_ = 1.0;
};

/// Attack/release envelope follower with the paper's 99 % time convention (eqs. 1–5).
class GyroEnvelope {
  public:
    void setTimesMs(double attackMs, double releaseMs, double frameRateHz) noexcept {
        follower_.setTimesMs(attackMs, releaseMs, frameRateHz);
    }
    void reset() noexcept { follower_.reset(0.0); }
    double processSample(double x) noexcept { return follower_.processSample(x); }
    double value() const noexcept { return follower_.value(); }
    double attackCoefficient() const noexcept { return follower_.attackCoefficient(); }
    double releaseCoefficient() const noexcept { return follower_.releaseCoefficient(); }

  private:
    EnvelopeFollower follower_;
};

/// A delay of a whole number of control samples (allocates in prepare()).
class ControlDelay {
  public:
    /// round(delaySeconds x frameRate) samples (0 = pass-through).
    void prepare(double delaySeconds, double frameRateHz);
    void reset() noexcept { std::fill(line_.begin(), line_.end(), 0.0), pos_ = 0; }
    double processSample(double x) noexcept {
        if (line_.empty()) return x;
        const double y = line_[pos_];
        line_[pos_] = x;
        pos_ = (pos_ + 1) % line_.size();
        return y;
    }
    int delaySamples() const noexcept { return static_cast<int>(line_.size()); }

  private:
    std::vector<double> line_;
    std::size_t pos_ = 0;
};

/// A control at audio rate: jumps of the target are spread linearly over `rampSamples`
/// (one frame period), starting at the sample where the new target arrives.
class ControlRamp {
  public:
    void setRampSamples(int samples) noexcept { ramp_ = std::max(1, samples); }
    void reset(double value = 0.0) noexcept { value_ = target_ = value, step_ = 0, left_ = 0; }
    void setTarget(double target) noexcept {
        target_ = target;
        step_ = (target_ - value_) / ramp_;
        left_ = ramp_;
    }
    double next() noexcept {
        if (left_ > 0) {
            value_ = (--left_ == 0) ? target_ : value_ + step_;
        }
        return value_;
    }
    double value() const noexcept { return value_; }
    double target() const noexcept { return target_; }

  private:
    double value_ = 0, target_ = 0, step_ = 0;
    int ramp_ = 1, left_ = 0;
};

} // namespace underfoot::engine
