// SPDX-License-Identifier: GPL-3.0-or-later
// The matrix pencil modal estimate on sums of damped sinusoids with known answers.
#include "realism/Modal.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace underfoot::realism;

namespace {
struct Truth {
    double f, sigma, a, phi;
};

std::vector<double> dampedSum(const std::vector<Truth>& modes, double fs, int n, double noise,
                              unsigned seed) {
    std::mt19937 g(seed);
    std::normal_distribution<double> w(0.0, noise);
    std::vector<double> x(std::size_t(n), 0.0);
    for (int i = 0; i < n; ++i) {
        const double t = i / fs;
        for (const auto& m : modes)
            x[std::size_t(i)] +=
                m.a * std::exp(-m.sigma * t) * std::cos(2 * std::numbers::pi * m.f * t + m.phi);
        if (noise > 0) x[std::size_t(i)] += w(g);
    }
    return x;
}

const Mode& nearest(const std::vector<Mode>& est, double f) {
    return *std::min_element(est.begin(), est.end(), [f](const Mode& a, const Mode& b) {
        return std::fabs(a.frequencyHz - f) < std::fabs(b.frequencyHz - f);
    });
}
} // namespace

TEST(RealismModal, RecoversThreeDampedModesExactly) {
    const double fs = 48000;
    // A wooden plank-like strike: three modes, one close pair 60 Hz apart (about 2 FFT bins of a
    // 1536-point window: a spectral peak picker would merge them).
    const std::vector<Truth> truth = {
        {523.0, 40.0, 1.0, 0.3}, {1710.0, 90.0, 0.5, -1.1}, {1770.0, 120.0, 0.35, 2.0}};
    ModalOptions o;
    o.modes = 3;
    o.extraOrder = 2;
    const auto est = matrixPencilModes(dampedSum(truth, fs, 1536, 0.0, 1), fs, o);
    ASSERT_EQ(est.size(), 3u);
    EXPECT_NEAR(est[0].frequencyHz, 523.0, 0.01); // strongest first
    for (const auto& t : truth) {
        const auto& m = nearest(est, t.f);
        EXPECT_NEAR(m.frequencyHz, t.f, 0.01) << t.f;
        EXPECT_NEAR(m.decayPerS, t.sigma, 0.01) << t.f;
        EXPECT_NEAR(m.t60S, std::log(1000.0) / t.sigma, 1e-3) << t.f;
        EXPECT_NEAR(m.amplitude, t.a, 1e-4) << t.f;
        EXPECT_NEAR(std::remainder(m.phase - t.phi, 2 * std::numbers::pi), 0.0, 1e-4) << t.f;
    }
}

TEST(RealismModal, StaysCloseWithNoiseAndDropsOutOfBandModes) {
    const double fs = 48000;
    const std::vector<Truth> truth = {
        {880.0, 30.0, 1.0, 0.0}, {2450.0, 150.0, 0.6, 1.0}, {6100.0, 400.0, 0.4, -0.5}};
    ModalOptions o;
    o.modes = 3;
    o.extraOrder = 12; // extra poles absorb the noise
    const auto est = matrixPencilModes(dampedSum(truth, fs, 1536, 0.01, 7), fs, o); // SNR ~ 34 dB
    ASSERT_EQ(est.size(), 3u);
    for (const auto& t : truth) {
        const auto& m = nearest(est, t.f);
        EXPECT_NEAR(m.frequencyHz, t.f, 0.002 * t.f) << t.f;
        EXPECT_NEAR(m.decayPerS, t.sigma, 0.1 * t.sigma) << t.f;
        EXPECT_NEAR(m.amplitude, t.a, 0.1 * t.a) << t.f;
    }
    o.maxHz = 3000; // the 6.1 kHz mode is out of band
    const auto band = matrixPencilModes(dampedSum(truth, fs, 1536, 0.01, 7), fs, o);
    for (const auto& m : band) EXPECT_LE(m.frequencyHz, 3000.0);
    EXPECT_NEAR(nearest(band, 880).frequencyHz, 880.0, 2.0);
}

TEST(RealismModal, RejectsBadInput) {
    EXPECT_THROW(matrixPencilModes(std::vector<double>(20, 0.1), 48000), std::invalid_argument);
    EXPECT_THROW(matrixPencilModes(std::vector<double>(1000, 0.1), 0), std::invalid_argument);
    auto x = dampedSum({{500, 20, 1, 0}}, 48000, 1000, 0, 1);
    x[10] = std::nan("");
    EXPECT_THROW(matrixPencilModes(x, 48000), std::invalid_argument);
}
