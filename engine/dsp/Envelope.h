// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// One-pole smoothing and attack/release envelope followers.
///
/// Both followers implement `e[n] = x[n] + g (e[n-1] - x[n])` (equivalently
/// `e[n] = (1-g) x[n] + g e[n-1]`), with g chosen per sample from the attack or release
/// coefficient depending on whether the input rises above the envelope. This is Cook's
/// non-linear one-pole GRF extractor (PhISM, 1997; TVCG 2011 §3) when fed |x|, and the wading
/// control's envelope follower (gait paper §3) with `g = exp(ln(0.01) / (t_ms * fs / 1000))`,
/// i.e. the envelope covers 99 % of a step in t_ms. A time of 0 ms gives g = 0 (instant).
#include "engine/dsp/ProcessSpec.h"

namespace underfoot::engine {

/// Coefficient reaching 99 % of a step in `timeMs` (0 => instantaneous).
inline double envelopeCoefficient99(double timeMs, double sampleRateHz) noexcept {
    if (!(timeMs > 0.0)) return 0.0;
    return std::exp(std::log(0.01) / (timeMs * sampleRateHz * 0.001));
}

/// Coefficient of a one-pole low-pass with time constant tau (63 % of a step).
inline double onePoleCoefficientTau(double tauSeconds, double sampleRateHz) noexcept {
    if (!(tauSeconds > 0.0)) return 0.0;
    return std::exp(-1.0 / (tauSeconds * sampleRateHz));
}

class OnePole {
  public:
    void setCoefficient(double g) noexcept { g_ = g; }
    void setTimeConstant(double tauSeconds, double sampleRateHz) noexcept {
        g_ = onePoleCoefficientTau(tauSeconds, sampleRateHz);
    }
    void reset(double value = 0.0) noexcept { y_ = value; }
    double processSample(double x) noexcept {
        y_ = x + g_ * (y_ - x);
        return y_;
    }
    double value() const noexcept { return y_; }

  private:
    double g_ = 0.0, y_ = 0.0;
};

class EnvelopeFollower {
  public:
    /// Sets the coefficients directly (Cook's b_up, b_down in [0, 1)).
    void setCoefficients(double attackG, double releaseG) noexcept {
        attack_ = attackG;
        release_ = releaseG;
    }
    /// Sets attack and release as 99 % times in milliseconds (gait paper convention).
    void setTimesMs(double attackMs, double releaseMs, double sampleRateHz) noexcept {
        attack_ = envelopeCoefficient99(attackMs, sampleRateHz);
        release_ = envelopeCoefficient99(releaseMs, sampleRateHz);
    }
    void reset(double value = 0.0) noexcept { e_ = value; }
    double processSample(double x) noexcept {
        const double g = (x > e_) ? attack_ : release_;
        e_ = snapToZero(x + g * (e_ - x));
        return e_;
    }
    double value() const noexcept { return e_; }
    double attackCoefficient() const noexcept { return attack_; }
    double releaseCoefficient() const noexcept { return release_; }

  private:
    double attack_ = 0.0, release_ = 0.0, e_ = 0.0;
};

} // namespace underfoot::engine
