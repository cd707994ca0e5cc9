// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The ground reaction force as the granular and liquid layers read it: one sanitising rule
/// and the sleeping layer's load tracking, shared so that both layers wake the same way.
#include <algorithm>

namespace underfoot::engine {

/// GRF beyond this is clamped (no human produces it).
inline constexpr double kLayerMaxForceN = 1e5;

/// GRF sample -> newtons, with NaN/Inf/negative read as 0 (no contact).
inline double sanitizeForce(float v) noexcept {
    const double f = static_cast<double>(v);
    if (!(f > 0.0)) return 0.0;
    return std::min(f, kLayerMaxForceN);
}

/// While a layer sleeps: tracks the load's smoothed derivative (dF/dt in kN/s through the
/// one-pole of coefficient g, as the awake layer does) up to the first sample whose load is
/// above the contact threshold, so that a landing's rise is the same wherever the layer wakes.
/// Returns that sample's index, or n when no sample of the n is in contact.
inline int trackLoadUntilContact(const float* grf, int n, double thresholdN, double toKnPerS,
                                 double g, double& previousF, double& derivative) noexcept {
    int first = 0;
    for (; first < n; ++first) {
        const double f = sanitizeForce(grf[first]);
        if (f > thresholdN) break;
        const double raw = (f - previousF) * toKnPerS;
        previousF = f;
        derivative = raw + g * (derivative - raw);
    }
    return first;
}

} // namespace underfoot::engine
