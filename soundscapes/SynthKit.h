// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Small real-time building blocks shared by the procedural soundscape generators.
///
/// Everything here is allocation-free and noexcept once constructed; state is double.
/// - `Svf`: topology-preserving-transform state-variable filter (A. Simper, "Linear trapezoidal
///   integrated SVF", Cytomic 2013; V. Zavalishin, "The Art of VA Filter Design", ch. 4), cheap
///   to retune, so it is the filter of every modulated layer.
/// - `PinkNoise`: P. Kellet's "economy" three-pole pink filter (music-dsp archive, 1999),
///   within about 0.5 dB of -3 dB/octave above 40 Hz.
/// - `SawOsc`: naive sawtooth with a polyBLEP correction (V. Välimäki & A. Huovilainen,
/// "Antialiasing
///   oscillators in subtractive synthesis", IEEE SPM 2007) — the glottal-like source of calls.
/// - `SmoothRandom`: a random target drawn at a fixed interval and chased by a one-pole
///   smoother — the "slow modulation" of wind gusts, swells and pitch drift.
/// - `Resonator`: two-pole modal resonator (one mode of a struck object: `y = 2 r cos(w) y1 -
///   r^2 y2 + x`, r = exp(-1 / (tau fs))), normalised to unit peak gain at its frequency.
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"

#include <algorithm>
#include <cmath>

namespace underfoot::soundscapes {

using engine::kPi;
using engine::kTwoPi;

/// Topology-preserving state-variable filter with simultaneous low/band/high-pass outputs.
class Svf {
  public:
    struct Out {
        double low, band, high;
    };
    /// Sets cutoff (clamped to 10 Hz .. 0.45 fs) and Q (clamped to >= 0.05).
    void set(double sampleRateHz, double cutoffHz, double q) noexcept {
        const double fc = std::clamp(cutoffHz, 10.0, 0.45 * sampleRateHz);
        const double g = std::tan(kPi * fc / sampleRateHz);
        k_ = 1.0 / std::max(q, 0.05);
        a1_ = 1.0 / (1.0 + g * (g + k_));
        a2_ = g * a1_;
        a3_ = g * a2_;
    }
    void reset() noexcept { ic1_ = ic2_ = 0.0; }
    Out process(double x) noexcept {
        const double v3 = x - ic2_;
        const double v1 = a1_ * ic1_ + a2_ * v3;
        const double v2 = ic2_ + a2_ * ic1_ + a3_ * v3;
        ic1_ = 2.0 * v1 - ic1_;
        ic2_ = 2.0 * v2 - ic2_;
        return {v2, v1, x - k_ * v1 - v2};
    }
    /// Band-pass output scaled to unit gain at the centre (the raw band output peaks at Q).
    double bandNormalised(double x) noexcept { return process(x).band * k_; }
    /// Clears tiny state values (call once per block).
    void snap() noexcept {
        ic1_ = engine::snapToZero(ic1_);
        ic2_ = engine::snapToZero(ic2_);
    }

  private:
    double k_ = 1.0, a1_ = 0.0, a2_ = 0.0, a3_ = 0.0, ic1_ = 0.0, ic2_ = 0.0;
};

/// White noise of unit variance (uniform, so bounded by sqrt(3)).
inline double whiteNoise(engine::Random& rng) noexcept {
    return 1.7320508075688772 * rng.bipolar();
}

/// Pink noise with roughly unit variance.
class PinkNoise {
  public:
    void reset() noexcept { b0_ = b1_ = b2_ = 0.0; }
    double next(engine::Random& rng) noexcept { return process(whiteNoise(rng)); }
    /// Filters a given white sample (to share one noise source between layers).
    double process(double w) noexcept {
        b0_ = 0.99765 * b0_ + w * 0.0990460;
        b1_ = 0.96300 * b1_ + w * 0.2965164;
        b2_ = 0.57000 * b2_ + w * 1.0526913;
        return 0.2 * (b0_ + b1_ + b2_ + w * 0.1848);
    }

  private:
    double b0_ = 0, b1_ = 0, b2_ = 0;
};

/// Band-limited sawtooth in [-1, 1] (polyBLEP).
class SawOsc {
  public:
    void reset(double phase = 0.0) noexcept { phase_ = phase - std::floor(phase); }
    double next(double frequencyHz, double sampleRateHz) noexcept {
        const double dt = std::clamp(frequencyHz / sampleRateHz, 1e-6, 0.45);
        double y = 2.0 * phase_ - 1.0 - blep(phase_, dt);
        phase_ += dt;
        if (phase_ >= 1.0) phase_ -= 1.0;
        return y;
    }

  private:
    static double blep(double t, double dt) noexcept {
        if (t < dt) {
            t /= dt;
            return t + t - t * t - 1.0;
        }
        if (t > 1.0 - dt) {
            t = (t - 1.0) / dt;
            return t * t + t + t + 1.0;
        }
        return 0.0;
    }
    double phase_ = 0.0;
};

/// sin(2 pi phase): a parabola refined once (the classic "fast and accurate sine" of the
/// music-dsp archive, N. Capens 2006); |error| < 0.0011, harmonics below -60 dB. Several times
/// cheaper than std::sin, which matters for a dozen oscillators per sample.
inline double fastSin2Pi(double phase) noexcept {
    const double x = phase - std::floor(phase + 0.5); // [-0.5, 0.5)
    const double y = 8.0 * x - 16.0 * x * std::fabs(x);
    return 0.225 * (y * std::fabs(y) - y) + y;
}

/// Sine oscillator with a running phase (so that glides stay continuous), using fastSin2Pi.
class SineOsc {
  public:
    void reset(double phase = 0.0) noexcept { phase_ = phase - std::floor(phase); }
    double next(double frequencyHz, double sampleRateHz) noexcept {
        const double y = fastSin2Pi(phase_);
        phase_ += frequencyHz / sampleRateHz;
        if (phase_ >= 1.0) phase_ -= std::floor(phase_);
        return y;
    }
    double phase() const noexcept { return phase_; }

  private:
    double phase_ = 0.0;
};

/// A slowly wandering value in [0, 1]: new random target every `holdSeconds`, chased with a
/// one-pole of time constant `smoothSeconds`.
class SmoothRandom {
  public:
    void configure(double holdSeconds, double smoothSeconds, double sampleRateHz) noexcept {
        holdSamples_ = std::max(1, static_cast<int>(holdSeconds * sampleRateHz));
        g_ = std::exp(-1.0 / std::max(1.0, smoothSeconds * sampleRateHz));
    }
    void reset(engine::Random& rng) noexcept {
        value_ = target_ = rng.uniform();
        count_ = static_cast<int>(rng.uniform() * holdSamples_);
    }
    double next(engine::Random& rng) noexcept {
        if (--count_ <= 0) {
            // Hold times vary by +-50 % so that modulations of equal settings never lock.
            count_ = static_cast<int>(holdSamples_ * (0.5 + rng.uniform()));
            target_ = rng.uniform();
        }
        value_ = target_ + g_ * (value_ - target_);
        return value_;
    }
    double value() const noexcept { return value_; }

  private:
    int holdSamples_ = 1, count_ = 0;
    double g_ = 0.0, value_ = 0.0, target_ = 0.0;
};

/// One damped mode: rings at `frequencyHz` with 1/e decay time `decaySeconds`.
class Resonator {
  public:
    void set(double sampleRateHz, double frequencyHz, double decaySeconds) noexcept {
        const double f = std::clamp(frequencyHz, 10.0, 0.45 * sampleRateHz);
        const double w = kTwoPi * f / sampleRateHz;
        const double r = std::exp(-1.0 / (std::max(decaySeconds, 1e-4) * sampleRateHz));
        c1_ = 2.0 * r * std::cos(w);
        c2_ = -r * r;
        // Peak gain of 1 / (1 - 2r cos w z^-1 + r^2 z^-2) is about 1 / (2 (1 - r) sin w) for r
        // near 1.
        gain_ = 2.0 * (1.0 - r) * std::sin(w);
    }
    void reset() noexcept { y1_ = y2_ = 0.0; }
    double process(double x) noexcept {
        const double y = c1_ * y1_ + c2_ * y2_ + gain_ * x;
        y2_ = y1_;
        y1_ = y;
        return y;
    }
    void snap() noexcept {
        y1_ = engine::snapToZero(y1_);
        y2_ = engine::snapToZero(y2_);
    }

  private:
    double c1_ = 0, c2_ = 0, gain_ = 0, y1_ = 0, y2_ = 0;
};

/// Equal-power pan gains for a position in [-1 (left), 1 (right)].
inline void panGains(double pan, float& left, float& right) noexcept {
    const double a = (std::clamp(pan, -1.0, 1.0) + 1.0) * 0.25 * kPi;
    left = static_cast<float>(std::cos(a));
    right = static_cast<float>(std::sin(a));
}

/// Raised-cosine window value for position t in [0, 1] (0 outside).
inline double hann(double t) noexcept {
    if (t <= 0.0 || t >= 1.0) return 0.0;
    const double s = std::sin(kPi * t);
    return s * s;
}

/// Attack/decay envelope: linear rise over `attack`, exponential decay with `decay` after it.
inline double attackDecay(double tSeconds, double attackSeconds, double decaySeconds) noexcept {
    if (tSeconds < 0.0) return 0.0;
    if (tSeconds < attackSeconds) return tSeconds / attackSeconds;
    return std::exp(-(tSeconds - attackSeconds) / decaySeconds);
}

} // namespace underfoot::soundscapes
