// SPDX-License-Identifier: GPL-3.0-or-later
// The grains model's noise excitation with an attack (`noise_attack_ratio`;
// docs/decisions/noise-voiced-aggregates.md): a burst's power rises over its attack and decays
// with its time constant, and an attack that reaches the decay is refused.
#include "engine/models/Aggregate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;
} // namespace

TEST(NoiseVoicedSurfaces, NoiseBurstRisesOverItsAttackAndDecaysAfter) {
    // One burst: power E (exp(-2t / tau) - exp(-2t / r)), tau = 8 ms, r = 2 ms: it peaks at
    // t* = r tau ln(tau / r) / (2 (tau - r)) = 1.85 ms. Without an attack it starts at its peak.
    auto rms = [](const std::vector<float>& x, double from, double to) {
        double e = 0;
        int n = 0;
        for (auto i = static_cast<std::size_t>(from * kFs); i < static_cast<std::size_t>(to * kFs);
             ++i, ++n)
            e += static_cast<double>(x[i]) * x[i];
        return std::sqrt(e / n);
    };
    for (double attackMs : {0.0, 2.0}) {
        AggregateParameters p;
        p.excitation = AggregateParameters::Excitation::Noise;
        p.noiseDecayMs = 8.0;
        p.noiseAttackMs = attackMs;
        AggregateModel m;
        m.configure(p);
        m.prepare(kFs, 4000);
        m.reset(3);
        std::vector<float> rate(4800, 0.0f), scale(4800, 0.0f), out(4800, 0.0f);
        m.trigger(1.0);
        m.process(rate.data(), scale.data(), out.data(), 4800);
        const double first = rms(out, 0.0, 0.0003), peak = rms(out, 0.0015, 0.0025),
                     late = rms(out, 0.020, 0.024);
        if (attackMs > 0) {
            EXPECT_LT(first, 0.5 * peak); // it rises ...
        } else {
            EXPECT_GT(first, 0.9 * peak); // ... or starts at once
        }
        // ... and decays with tau: 20 ms later about exp(-20 / 8) = -21.7 dB.
        EXPECT_LT(late, 0.2 * peak);
        EXPECT_GT(late, 0.02 * peak);
    }
    AggregateParameters bad;
    bad.excitation = AggregateParameters::Excitation::Noise;
    bad.noiseDecayMs = 2.0;
    bad.noiseAttackMs = 2.0; // not below the decay
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}
