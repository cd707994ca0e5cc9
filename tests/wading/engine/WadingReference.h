// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// An independent, straightforward implementation of the paper's v2 control chain (seed 004:
/// §3.3 Butterworth 2nd order, 0..100 deg/s normalisation, L+R sum; §6.1 eqs. (1)-(6); §6.2
/// C1-C3, the 150 ms delay, the fader ranges of the deep preset), written from the equations for
/// the tests. It uses nothing from the engine but GaitFrame: the low-pass is designed from the
/// analogue prototype by the bilinear transform with pre-warping and run in direct form I.
#include "engine/control/GyroFrame.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <vector>

namespace underfoot::test::wading {
using underfoot::engine::GaitFrame;

struct RefLowpass {
    double b0, b1, b2, a1, a2, gain;
    double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
    RefLowpass(double fs, double fc, double g) : gain(g) {
        const double k = std::tan(M_PI * fc / fs);
        const double norm = 1.0 + std::sqrt(2.0) * k + k * k;
        b0 = k * k / norm;
        b1 = 2 * b0;
        b2 = b0;
        a1 = 2 * (k * k - 1) / norm;
        a2 = (1 - std::sqrt(2.0) * k + k * k) / norm;
    }
    double operator()(double x) {
        const double y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
        x2 = x1, x1 = x, y2 = y1, y1 = y;
        return gain * y;
    }
};

struct RefEnvelope {
    double ga, gr, env = 0;
    RefEnvelope(double attackMs, double releaseMs, double fs) {
        const double tc = std::log(0.01);
        ga = attackMs > 0 ? std::exp(tc / (attackMs * fs * 0.001)) : 0.0; // exp(-inf) = 0
        gr = std::exp(tc / (releaseMs * fs * 0.001));
    }
    double operator()(double x) {
        env = x > env ? x + ga * (env - x) : x + gr * (env - x);
        return env;
    }
};

inline double norm100(double w) {
    return std::min(std::max(w / 100.0, 0.0), 1.0);
}

struct RefV2 {
    std::vector<RefLowpass> lp;
    RefEnvelope e1{0, 890, 100}, e2{0, 2230, 100}, e3{0, 890, 100};
    RefEnvelope s1l{0, 890, 100}, s1r{0, 890, 100}, s2l{0, 2230, 100}, s2r{0, 2230, 100},
        s3l{0, 890, 100}, s3r{0, 890, 100};
    std::deque<double> d{std::deque<double>(15, 0.0)}, dl{std::deque<double>(15, 0.0)},
        dr{std::deque<double>(15, 0.0)};
    explicit RefV2(double cutL = 5, double cutR = 5, double gainL = 1, double gainR = 1) {
        lp = {RefLowpass(100, cutL, gainL), RefLowpass(100, cutR, gainR),
              RefLowpass(100, cutL, gainL), RefLowpass(100, cutR, gainR)};
    }
    static double delay(std::deque<double>& q, double x) {
        q.push_back(x);
        const double y = q.front();
        q.pop_front();
        return y;
    }
    static double fader(double c, double lo, double hi) {
        const double g = std::pow(10.0, (lo + (hi - lo) * c) / 20.0);
        return c > 0 ? g * std::min(1.0, c / 0.02) : 0.0;
    }
    // Returns c1, c2, c3, then gains [layer][side].
    std::array<double, 9> step(const GaitFrame& f) {
        double n[4];
        for (int i = 0; i < 4; ++i) n[i] = norm100(lp[i](f.angularVelocityDps[i]));
        const double thigh = std::min(n[0] + n[1], 1.0), shank = std::min(n[2] + n[3], 1.0);
        const double c1 = std::pow(e1(thigh), 1.93);
        const double c2 = std::pow(e2(shank), 2.56);
        const double c3 = e3(delay(d, shank));
        const double a1 = s1l(n[0]), b1 = s1r(n[1]);
        const double a2 = s2l(n[2]), b2 = s2r(n[3]);
        const double a3 = s3l(delay(dl, n[2])), b3 = s3r(delay(dr, n[3]));
        auto share = [](double a, double b) { return a + b > 0 ? a / (a + b) : 0.5; };
        const double g1 = fader(c1, -33, 0), g2 = fader(c2, -38, -5), g3 = fader(c3, -40, 5);
        const double h1 = share(a1, b1), h2 = share(a2, b2), h3 = share(a3, b3);
        return {c1,
                c2,
                c3,
                g1 * std::sqrt(h1),
                g1 * std::sqrt(1 - h1),
                g2 * std::sqrt(h2),
                g2 * std::sqrt(1 - h2),
                g3 * std::sqrt(h3),
                g3 * std::sqrt(1 - h3)};
    }
};

} // namespace underfoot::test::wading
