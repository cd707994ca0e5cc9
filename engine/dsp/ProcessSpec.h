// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// What a DSP block needs to know before it runs: the only place where it may allocate is
/// `prepare(const ProcessSpec&)`; `reset()` clears state; `process(...) noexcept` runs on the
/// audio thread without allocating, locking, logging or throwing.
#include <cmath>
#include <cstdint>

namespace underfoot::engine {

struct ProcessSpec {
    double sampleRateHz = 48000.0; ///< output sample rate
    int maxBlockSize = 512;        ///< largest block passed to process()
};

/// True when v is a finite number (not NaN, not +-Inf).
inline bool isFinite(double v) noexcept {
    return std::isfinite(v);
}

/// Returns 0 for values so small that they would become denormal in feedback state
/// (the "zap gremlins" idea of SuperCollider; JUCE calls it snapToZero).
inline double snapToZero(double v) noexcept {
    return (std::fabs(v) < 1e-30) ? 0.0 : v;
}

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kGravity = 9.80665; ///< standard gravity, m/s^2

/// Linear gain from decibels.
inline double dbToGain(double db) noexcept {
    return std::pow(10.0, db / 20.0);
}

} // namespace underfoot::engine
