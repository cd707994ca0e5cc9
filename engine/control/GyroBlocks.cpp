// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/GyroBlocks.h"

#include <complex>
#include <stdexcept>
#include <string>

namespace underfoot::engine {

void GyroLowpass::design(double frameRateHz, double cutoffHz, double makeUpGain) {
    if (!(frameRateHz > 0) || !std::isfinite(frameRateHz))
        throw std::invalid_argument("GyroLowpass: frame rate must be a positive number");
    if (!(cutoffHz > 0) || !(cutoffHz < 0.5 * frameRateHz))
        throw std::invalid_argument("GyroLowpass: cutoff " + std::to_string(cutoffHz) +
                                    " Hz must lie in (0, frame rate / 2)");
    if (!(makeUpGain > 0) || !std::isfinite(makeUpGain))
        throw std::invalid_argument("GyroLowpass: make-up gain must be a positive number");
    biquad_.setCoefficients(BiquadCoefficients::lowpass(frameRateHz, cutoffHz, std::sqrt(0.5)));
    biquad_.reset();
    cutoffHz_ = cutoffHz;
    gain_ = makeUpGain;
}

double GyroLowpass::groupDelaySeconds(double frameRateHz, double frequencyHz) const noexcept {
    const auto& c = biquad_.coefficients();
    auto phase = [&](double f) {
        const std::complex<double> z1 = std::polar(1.0, -kTwoPi * f / frameRateHz);
        const std::complex<double> h =
            (c.b0 + c.b1 * z1 + c.b2 * z1 * z1) / (1.0 + c.a1 * z1 + c.a2 * z1 * z1);
        return std::arg(h);
    };
    const double df = 1e-4 * frameRateHz;
    const double f0 = std::max(frequencyHz, df);
    double dphi = phase(f0 + df) - phase(f0 - df);
    while (dphi > kPi) dphi -= kTwoPi;
    while (dphi < -kPi) dphi += kTwoPi;
    return -dphi / (kTwoPi * 2.0 * df);
}

void ControlDelay::prepare(double delaySeconds, double frameRateHz) {
    if (!(delaySeconds >= 0) || !std::isfinite(delaySeconds) || !(frameRateHz > 0))
        throw std::invalid_argument("ControlDelay: delay must be a finite number >= 0 s");
    line_.assign(static_cast<std::size_t>(std::llround(delaySeconds * frameRateHz)), 0.0);
    pos_ = 0;
}

} // namespace underfoot::engine
