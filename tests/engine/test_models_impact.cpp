// SPDX-License-Identifier: GPL-3.0-or-later
// Hunt–Crossley impact: analytic contact time and restitution, passivity, hard cases.
#include "engine/dsp/Random.h"
#include "engine/models/Impact.h"

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kRigidMass = 1e12; // a floor mode so heavy that the floor does not move

HuntCrossleyImpact makeImpact(const ImpactParams& p, double fs, std::vector<Mode> modes = {}) {
    if (modes.empty()) modes = {{200.0, 0.05, kRigidMass}};
    HuntCrossleyImpact impact;
    impact.configure(p, modes, {std::vector<double>(modes.size(), 1.0)});
    impact.prepare({fs, 256});
    return impact;
}

// Runs until the exciter has left the floor (or maxSeconds); returns false if it never left.
bool runUntilRebound(HuntCrossleyImpact& impact, double fs, double maxSeconds,
                     double* maxEnergyRatio = nullptr, double e0 = 0) {
    std::vector<float> out(64);
    const int blocks = static_cast<int>(maxSeconds * fs / 64) + 1;
    bool touched = false;
    for (int b = 0; b < blocks; ++b) {
        impact.process(nullptr, out.data(), 64);
        for (float v : out)
            if (!std::isfinite(v)) return false;
        if (maxEnergyRatio) *maxEnergyRatio = std::max(*maxEnergyRatio, impact.totalEnergy() / e0);
        touched |= impact.stats().solvedSamples > 0;
        if (touched && impact.compression() <= 0 && impact.lastContactForce() == 0.0) return true;
    }
    return false;
}

// Analytic contact duration of an elastic (mu = 0) Hunt–Crossley contact against a rigid wall:
// t_c = 2 (c_max / v) * int_0^1 du / sqrt(1 - u^(a+1)),  c_max = ((a+1) m v^2 / (2k))^(1/(a+1)).
double analyticContactTime(double k, double a, double m, double v) {
    const double cmax = std::pow((a + 1) * m * v * v / (2 * k), 1.0 / (a + 1));
    // int_0^1 (1-u^p)^(-1/2) du = B(1/p, 1/2) / p with p = a + 1.
    const double p = a + 1;
    const double beta = std::tgamma(1.0 / p) * std::tgamma(0.5) / std::tgamma(1.0 / p + 0.5);
    return 2.0 * cmax / v * beta / p;
}

// Analytic rebound speed for Hunt–Crossley against a rigid wall (Marhefka & Orin 1999):
// m v dv / (1 + mu v) = -k c^a dc integrates to G(v_out) = G(v_in), G(v) = v/mu - ln(1+mu v)/mu^2.
double analyticReboundSpeed(double mu, double vin) {
    auto G = [mu](double v) { return v / mu - std::log1p(mu * v) / (mu * mu); };
    const double target = G(vin);
    auto f = [&](double vout) { return G(-vout) - target; }; // rebound velocity is negative
    std::uintmax_t iters = 200;
    const auto r = boost::math::tools::bisect(f, 1e-12, std::min(vin, 1.0 / mu * (1 - 1e-12)),
                                              boost::math::tools::eps_tolerance<double>(50), iters);
    return 0.5 * (r.first + r.second);
}
} // namespace

TEST(HuntCrossleyImpact, ElasticContactTimeMatchesTheAnalyticSolution) {
    for (const double alpha : {1.0, 1.5, 2.0, 3.0}) {
        ImpactParams p;
        p.stiffness = 1e6;
        p.alpha = alpha;
        p.dissipation = 0.0;
        p.exciterMassKg = 0.1;
        const double fs = 192000.0, v = 1.0;
        auto impact = makeImpact(p, fs);
        impact.strike(v);
        ASSERT_TRUE(runUntilRebound(impact, fs, 1.0));
        const double expected = analyticContactTime(p.stiffness, alpha, p.exciterMassKg, v);
        EXPECT_NEAR(impact.stats().contactTimeSeconds, expected, 2.0 / fs) << alpha;
        // Elastic: the exciter leaves as fast as it came.
        EXPECT_NEAR(-impact.stats().outgoingVelocity / v, 1.0, 2e-3) << alpha;
    }
}

TEST(HuntCrossleyImpact, RestitutionMatchesHuntCrossleyTheory) {
    for (const double mu : {0.05, 0.2, 0.5}) {
        for (const double v : {0.5, 2.0}) {
            ImpactParams p;
            p.stiffness = 1e7;
            p.alpha = 1.5;
            p.dissipation = mu;
            p.exciterMassKg = 0.2;
            const double fs = 96000.0;
            auto impact = makeImpact(p, fs);
            impact.strike(v);
            ASSERT_TRUE(runUntilRebound(impact, fs, 1.0));
            const double e = -impact.stats().outgoingVelocity / v;
            EXPECT_NEAR(e, analyticReboundSpeed(mu, v) / v, 5e-3) << mu << " " << v;
            EXPECT_GT(e, 0.0);
            EXPECT_LT(e, 1.0);
        }
    }
}

TEST(HuntCrossleyImpact, ContactForceNeverPullsAndStrikeStaysPassive) {
    ImpactParams p;
    p.stiffness = 5e7;
    p.alpha = 1.5;
    p.dissipation = 0.3;
    p.exciterMassKg = 0.05;
    const double fs = 48000.0;
    auto impact = makeImpact(p, fs, {{180.0, 0.2, 0.5}, {930.0, 0.1, 0.2}, {2400.0, 0.05, 0.1}});
    impact.strike(1.5);
    const double e0 = impact.totalEnergy();
    std::vector<float> out(64);
    for (int b = 0; b < 2000; ++b) {
        impact.process(nullptr, out.data(), 64);
        ASSERT_GE(impact.lastContactForce(), 0.0);
        // No energy gain without input (a margin of 1e-9 J for rounding).
        ASSERT_LE(impact.totalEnergy(), e0 * (1 + 1e-6)) << b;
    }
}

TEST(HuntCrossleyImpact, HardCasesStayFiniteBoundedAndPassive) {
    // Stiffness 1e5..1e11, alpha up to 3, velocities up to 10 m/s, masses down to 1e-4 kg, at
    // 22.05..192 kHz: the exciter must come back with at most the speed it came with.
    Random rng(2024);
    int cases = 0;
    for (const double k : {1e5, 1e7, 1e9, 1e11}) {
        for (const double alpha : {1.0, 1.5, 3.0}) {
            for (const double m : {1e-4, 1e-2, 1.0}) {
                for (const double v : {0.01, 1.0, 10.0}) {
                    const double fs = (cases % 3 == 0)   ? 22050.0
                                      : (cases % 3 == 1) ? 48000.0
                                                         : 192000.0;
                    ImpactParams p;
                    p.stiffness = k;
                    p.alpha = alpha;
                    p.dissipation = rng.uniform(0.0, 1.0);
                    p.exciterMassKg = m;
                    auto impact = makeImpact(
                        p, fs, {{150.0, 0.3, 1.0}, {1200.0, 0.1, 0.3}, {30000.0, 0.02, 0.1}});
                    impact.strike(v);
                    const double e0 = impact.totalEnergy();
                    double maxRatio = 0;
                    ASSERT_TRUE(runUntilRebound(impact, fs, 2.0, &maxRatio, e0))
                        << "k=" << k << " a=" << alpha << " m=" << m << " v=" << v << " fs=" << fs;
                    EXPECT_LE(maxRatio, 1.0 + 1e-6)
                        << "k=" << k << " a=" << alpha << " m=" << m << " v=" << v << " fs=" << fs;
                    // The exciter leaves with at most the kinetic energy it came with (the floor
                    // keeps some): |v_out| <= v_in for the exciter itself.
                    EXPECT_LE(std::fabs(impact.exciterVelocity()), v * (1 + 1e-6));
                    ++cases;
                }
            }
        }
    }
    EXPECT_EQ(cases, 108);
}

TEST(HuntCrossleyImpact, SleepsAfterDecayAndCostsNothingWhileAsleep) {
    ImpactParams p;
    auto impact = makeImpact(p, 48000.0, {{300.0, 0.05, 0.5}});
    EXPECT_TRUE(impact.isSleeping());
    impact.strike(0.5);
    EXPECT_FALSE(impact.isSleeping());
    std::vector<float> out(64);
    int blocks = 0;
    while (!impact.isSleeping() && blocks < 48000) {
        impact.process(nullptr, out.data(), 64);
        ++blocks;
    }
    EXPECT_TRUE(impact.isSleeping());
    // A 50 ms T60 reaches -200 dB re its start within ~0.2 s.
    EXPECT_LT(blocks * 64 / 48000.0, 0.5);
    impact.process(nullptr, out.data(), 64);
    for (float v : out) EXPECT_EQ(v, 0.0f);
}
