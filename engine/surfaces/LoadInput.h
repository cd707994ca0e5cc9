// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The ground reaction force as the granular and liquid layers read it: one sanitising rule
/// and the sleeping layer's load tracking, shared so that both layers wake the same way, and
/// how a bed settles under a load held still.
#include "engine/surfaces/Preset.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

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

/// Settling under a held load (the "grains", "bubbles" and "friction" layers): a load held still
/// keeps the layer's load-driven events for `afterS`, then the bed has settled (grains stop
/// settling, the water around a still leg calms, sheared boards stop rubbing) and the events fade
/// with `tauS` until the load changes again. Standing still on gravel, snow, leaves, creaking
/// boards or in water is silent; a shift of the weight wakes them. Every walking stance (at
/// most 1.3 s, at 60 steps/min) is shorter than the hold, and while the load moves the factor is
/// exactly 1: walks render the samples they did without it.
class LoadSettling {
  public:
    /// Below this rate of change the load is held still. Quiet standing sways by some
    /// 0.05-0.2 kN/s; shifting the weight from one foot to the other, and every walking stance
    /// (5-20 kN/s at the heel and at the push-off), change it faster.
    static constexpr double kStillKnPerS = 0.5;
    /// Below this factor the settled bed is silent: the factor is cut to 0.
    static constexpr double kSilentFactor = 1e-4;

    struct Params {
        double afterS = 2.0; ///< how long a held load keeps the events at full rate
        double tauS = 0.5;   ///< time constant of their fade after that
    };
    /// Reads settle_after_s and settle_tau_s from a layer's table; `held` says in the help what
    /// holding still means for the layer.
    static Params read(PresetReader& r,
                       std::string_view held = "a load held still (changing by less than 0.5 "
                                               "kN/s)") {
        Params p;
        p.afterS = r.number("settle_after_s", p.afterS, 0.1, 3600.0, "s",
                            std::string(held) +
                                " keeps the load-driven events this long, then the bed has "
                                "settled and they fade out with settle_tau_s until the load "
                                "changes again (standing still is silent; longer than any "
                                "walking stance, 1.3 s at 60 steps/min)",
                            true);
        p.tauS = r.number("settle_tau_s", p.tauS, 0.01, 60.0, "s",
                          "time constant of the events' fade once the bed has settled", true);
        return p;
    }

    void prepare(const Params& p, double sampleRateHz) noexcept {
        hold_ = static_cast<std::int64_t>(std::ceil(p.afterS * sampleRateHz));
        decay_ = std::exp(-1.0 / (p.tauS * sampleRateHz));
    }
    /// The foot is off the ground (or the layer is reset): the next contact starts unsettled.
    void reset() noexcept {
        still_ = 0;
        factor_ = 1.0;
    }
    /// One sample in contact: `moving` while the load changes (for the grains and bubbles:
    /// faster than kStillKnPerS). Returns the factor on the layer's load-driven events (1 while
    /// the load moves and for afterS after, then fading to 0).
    [[gnu::always_inline]] double next(bool moving) noexcept {
        if (moving) {
            still_ = 0;
            factor_ = 1.0;
        } else if (++still_ > hold_) {
            factor_ = factor_ > kSilentFactor ? factor_ * decay_ : 0.0;
        }
        return factor_;
    }
    /// next() for the grains and bubbles: the load's smoothed rate of change in kN/s.
    [[gnu::always_inline]] double inContact(double derivativeKnPerS) noexcept {
        return next(std::fabs(derivativeKnPerS) > kStillKnPerS);
    }

  private:
    std::int64_t still_ = 0, hold_ = 96000;
    double factor_ = 1.0, decay_ = 0.0;
};

} // namespace underfoot::engine
