// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/Biquad.h"

#include <complex>
#include <stdexcept>

namespace underfoot::engine {
namespace {
BiquadCoefficients normalise(double b0, double b1, double b2, double a0, double a1, double a2) {
    return {b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0};
}
double omega(double fs, double f) {
    return kTwoPi * f / fs;
}
} // namespace

BiquadCoefficients BiquadCoefficients::lowpass(double fs, double fc, double q) {
    const double w = omega(fs, fc), cw = std::cos(w), alpha = std::sin(w) / (2 * q);
    return normalise((1 - cw) / 2, 1 - cw, (1 - cw) / 2, 1 + alpha, -2 * cw, 1 - alpha);
}
BiquadCoefficients BiquadCoefficients::highpass(double fs, double fc, double q) {
    const double w = omega(fs, fc), cw = std::cos(w), alpha = std::sin(w) / (2 * q);
    return normalise((1 + cw) / 2, -(1 + cw), (1 + cw) / 2, 1 + alpha, -2 * cw, 1 - alpha);
}
BiquadCoefficients BiquadCoefficients::bandpass(double fs, double f0, double q) {
    const double w = omega(fs, f0), cw = std::cos(w), alpha = std::sin(w) / (2 * q);
    return normalise(alpha, 0, -alpha, 1 + alpha, -2 * cw, 1 - alpha);
}
BiquadCoefficients BiquadCoefficients::peaking(double fs, double f0, double q, double gainDb) {
    const double A = std::pow(10.0, gainDb / 40.0);
    const double w = omega(fs, f0), cw = std::cos(w), alpha = std::sin(w) / (2 * q);
    return normalise(1 + alpha * A, -2 * cw, 1 - alpha * A, 1 + alpha / A, -2 * cw, 1 - alpha / A);
}
BiquadCoefficients BiquadCoefficients::lowShelf(double fs, double f0, double gainDb) {
    const double A = std::pow(10.0, gainDb / 40.0);
    const double w = omega(fs, f0), cw = std::cos(w);
    const double alpha = std::sin(w) / 2 * std::sqrt(2.0); // shelf slope S = 1
    const double sa = 2 * std::sqrt(A) * alpha;
    return normalise(A * ((A + 1) - (A - 1) * cw + sa), 2 * A * ((A - 1) - (A + 1) * cw),
                     A * ((A + 1) - (A - 1) * cw - sa), (A + 1) + (A - 1) * cw + sa,
                     -2 * ((A - 1) + (A + 1) * cw), (A + 1) + (A - 1) * cw - sa);
}
BiquadCoefficients BiquadCoefficients::highShelf(double fs, double f0, double gainDb) {
    const double A = std::pow(10.0, gainDb / 40.0);
    const double w = omega(fs, f0), cw = std::cos(w);
    const double alpha = std::sin(w) / 2 * std::sqrt(2.0);
    const double sa = 2 * std::sqrt(A) * alpha;
    return normalise(A * ((A + 1) + (A - 1) * cw + sa), -2 * A * ((A - 1) + (A + 1) * cw),
                     A * ((A + 1) + (A - 1) * cw - sa), (A + 1) - (A - 1) * cw + sa,
                     2 * ((A - 1) - (A + 1) * cw), (A + 1) - (A - 1) * cw - sa);
}
BiquadCoefficients BiquadCoefficients::lowpass1(double fs, double fc) {
    const double k = std::tan(kPi * fc / fs);
    return normalise(k, k, 0, 1 + k, k - 1, 0);
}
BiquadCoefficients BiquadCoefficients::highpass1(double fs, double fc) {
    const double k = std::tan(kPi * fc / fs);
    return normalise(1, -1, 0, 1 + k, k - 1, 0);
}

double BiquadCoefficients::magnitudeAt(double fs, double f) const {
    const std::complex<double> z1 = std::polar(1.0, -omega(fs, f));
    const std::complex<double> z2 = z1 * z1;
    return std::abs((b0 + b1 * z1 + b2 * z2) / (1.0 + a1 * z1 + a2 * z2));
}

void Butterworth::appendSections(FilterType type, int order, double fs, double fc) {
    const bool low = type == FilterType::Lowpass;
    for (int k = 0; k < order / 2; ++k) {
        // Pole k of the analogue prototype lies at angle pi (N - 2k - 1) / (2N) from the negative
        // real axis; its section's Q is 1 / (2 cos(angle)).
        const double q = 1.0 / (2.0 * std::cos(kPi * (order - 2.0 * k - 1.0) / (2.0 * order)));
        sections_.emplace_back(low ? BiquadCoefficients::lowpass(fs, fc, q)
                                   : BiquadCoefficients::highpass(fs, fc, q));
    }
    if (order % 2 == 1)
        sections_.emplace_back(low ? BiquadCoefficients::lowpass1(fs, fc)
                                   : BiquadCoefficients::highpass1(fs, fc));
}

void Butterworth::design(FilterType type, int order, double fs, double fc, double upperHz) {
    if (order < 1 || order > 16) throw std::invalid_argument("Butterworth order must be 1..16");
    if (!(fc > 0.0 && fc < fs / 2))
        throw std::invalid_argument("Butterworth cutoff must lie between 0 and Nyquist");
    sections_.clear();
    if (type == FilterType::Bandpass) {
        if (!(upperHz > fc && upperHz < fs / 2))
            throw std::invalid_argument("Butterworth band-pass upper edge must lie above the lower "
                                        "edge and below Nyquist");
        appendSections(FilterType::Highpass, order, fs, fc);
        appendSections(FilterType::Lowpass, order, fs, upperHz);
    } else {
        appendSections(type, order, fs, fc);
    }
}

void Butterworth::reset() noexcept {
    for (auto& s : sections_) s.reset();
}

double Butterworth::magnitudeAt(double fs, double f) const {
    double m = 1.0;
    for (const auto& s : sections_) m *= s.coefficients().magnitudeAt(fs, f);
    return m;
}

} // namespace underfoot::engine
