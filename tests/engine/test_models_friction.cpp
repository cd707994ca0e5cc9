// SPDX-License-Identifier: GPL-3.0-or-later
// Elasto-plastic friction: stick, slip, Coulomb level, stability for very stiff bristles.
#include "engine/models/Friction.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace underfoot::engine;

namespace {
ElastoPlasticFriction makeFriction(double sigma0, double fs, double sigma1 = -1.0) {
    FrictionParams p;
    p.sigma0 = sigma0;
    // Critical-ish bristle damping for the rubbing mass: sigma1 ~ 2 sqrt(sigma0 m).
    p.sigma1 = sigma1 >= 0 ? sigma1 : 2.0 * std::sqrt(sigma0 * p.exciterMassKg);
    p.sigma2 = 0.4;
    p.sigma3 = 0.0;
    ElastoPlasticFriction f;
    f.configure(p, {{300.0, 0.05, 0.5}, {900.0, 0.04, 0.3}, {2500.0, 0.02, 0.2}},
                {{1.0, 0.8, 0.5}});
    f.prepare(fs);
    return f;
}
} // namespace

TEST(ElastoPlasticFriction, SticksBelowTheBreakAwayForceAndSlidesAboveIt) {
    const double fs = 48000.0, normal = 100.0; // f_s = 60 N, f_c = 30 N
    auto f = makeFriction(1e5, fs);
    for (int i = 0; i < 48000; ++i) f.processSample(normal, 20.0); // below f_c: stuck
    EXPECT_LT(std::fabs(f.exciterVelocity()), 1e-3);
    EXPECT_NEAR(f.frictionForce(), 20.0, 0.5); // the bristles carry the whole push
    auto g = makeFriction(1e5, fs);
    for (int i = 0; i < 24000; ++i) g.processSample(normal, 80.0); // above f_s: slides, accelerates
    EXPECT_GT(g.exciterVelocity(), 1.0);
    // While sliding fast the friction force approaches Coulomb's f_c plus the viscous term.
    EXPECT_NEAR(g.frictionForce(), 30.0 + 0.4 * g.relativeVelocity(), 3.0);
}

TEST(ElastoPlasticFriction, StaysFiniteAndBoundedForBristleStiffnessUpTo1e8) {
    // The Sound Design Toolkit's forward Euler blows up above sigma0 ~ 5e7; backward Euler does
    // not.
    for (const double fs : {22050.0, 48000.0, 192000.0}) {
        for (const double sigma0 : {1e3, 1e5, 1e7, 5e7, 1e8}) {
            auto f = makeFriction(sigma0, fs);
            double maxForce = 0, maxElastic = 0;
            for (int i = 0; i < static_cast<int>(fs); ++i) {
                // Alternating push: stick, slip, reversal.
                const double t = i / fs;
                const double drive = 70.0 * std::sin(kTwoPi * 3.0 * t);
                const double y = f.processSample(100.0, drive);
                ASSERT_TRUE(std::isfinite(y)) << sigma0 << " " << fs;
                maxForce = std::max(maxForce, std::fabs(f.frictionForce()));
                maxElastic = std::max(maxElastic, std::fabs(sigma0 * f.bristle()));
            }
            // The elastic bristle force never exceeds the static friction level f_s = 60 N (the
            // model's defining property), and the total force (with the bristle damping
            // sigma1 z', large for stiff bristles) stays of the order of the forces applied.
            EXPECT_LT(maxElastic, 60.0 * 1.01) << "sigma0=" << sigma0 << " fs=" << fs;
            EXPECT_LT(maxForce, 300.0) << "sigma0=" << sigma0 << " fs=" << fs;
        }
    }
}

TEST(ElastoPlasticFriction, NoLoadMeansNoFrictionAndRelaxedBristles) {
    auto f = makeFriction(1e6, 48000.0);
    for (int i = 0; i < 1000; ++i) f.processSample(100.0, 20.0);
    EXPECT_GT(std::fabs(f.bristle()), 0.0);
    for (int i = 0; i < 1000; ++i) f.processSample(0.0, 0.0);
    EXPECT_EQ(f.bristle(), 0.0);
    EXPECT_NEAR(f.frictionForce(), 0.0, 1e-9);
}

TEST(ElastoPlasticFriction, StickSlipUnderASteadyDragMakesAPeriodicCreak) {
    // A rubbing mass dragged through a spring at constant speed sticks and slips periodically:
    // the friction force saw-tooths between ~f_s and below f_c.
    const double fs = 48000.0;
    auto f = makeFriction(2e5, fs, 50.0);
    double anchor = 0.0;
    int slips = 0;
    bool sliding = false;
    for (int i = 0; i < 48000; ++i) {
        anchor += 0.02 / fs;
        const double drive =
            5e5 * (anchor - f.exciterPosition()) + 2.0 * (0.02 - f.exciterVelocity());
        f.processSample(50.0, drive);
        const bool nowSliding = std::fabs(f.relativeVelocity()) > 0.01;
        if (nowSliding && !sliding) ++slips;
        sliding = nowSliding;
    }
    // Period ~ (f_s - f_c) / (k v) = 15 N / (5e5 N/m * 0.02 m/s) = 1.5 ms -> hundreds per second.
    EXPECT_GT(slips, 100);
    EXPECT_LT(slips, 2000);
}
