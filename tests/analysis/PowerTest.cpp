// SPDX-License-Identifier: GPL-3.0-or-later
// Monte-Carlo power (analysis/power/Power.h). Where the design reduces to two independent
// proportions (one answer per participant, no participant variability) the simulated power of
// the uncorrected chi-square test must agree with its exact power, computed in R by enumerating
// both binomials (tests/analysis/data/power_reference.R); pwr::pwr.2p.test's arcsine
// approximation is quoted beside it.
#include "analysis/power/Power.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace underfoot::analysis;

namespace {

/// Two groups, `answers` answers per participant, probabilities p1 / p2 on the logit scale
/// shifted per participant by N(0, sd).
StudySimulator twoGroups(double p1, double p2, int answers, double sd) {
    return [=](int perGroup, std::uint64_t seed) {
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> normal(0.0, 1.0);
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        std::vector<SimulatedAnswer> out;
        int participant = 0;
        for (int g = 0; g < 2; ++g)
            for (int i = 0; i < perGroup; ++i, ++participant) {
                const double p = g == 0 ? p1 : p2;
                const double eta = std::log(p / (1 - p)) + sd * normal(rng);
                const double q = 1 / (1 + std::exp(-eta));
                for (int k = 0; k < answers; ++k)
                    out.push_back({participant, g, -1, uniform(rng) < q});
            }
        return out;
    };
}

} // namespace

TEST(Power, ReducesToTheTwoProportionTest) {
    struct Case {
        double p1, p2;
        int n;
        double exact, pwr;
    };
    // Rscript tests/analysis/data/power_reference.R
    const Case cases[] = {{0.8, 0.6, 40, 0.4968888887, 0.5069666789},
                          {0.7, 0.5, 60, 0.6176884208, 0.6156361215},
                          {0.9, 0.7, 30, 0.4994868696, 0.5150493293}};
    for (const auto& c : cases) {
        PowerOptions o;
        o.participantsPerGroup = {c.n};
        o.simulations = 4000;
        o.seed = 7;
        o.yates = false;
        o.mixedModel = false;
        o.confLevel = 0.999;
        const auto curve = simulatePower(twoGroups(c.p1, c.p2, 1, 0.0), 2, o);
        ASSERT_EQ(curve.points.size(), 1u);
        const auto& e = curve.points[0].classic;
        EXPECT_LE(e.clopperPearson.lower, c.exact) << c.p1 << " " << c.p2 << " " << e.power;
        EXPECT_GE(e.clopperPearson.upper, c.exact) << c.p1 << " " << c.p2 << " " << e.power;
        EXPECT_NEAR(e.power, c.pwr, 0.035); // the arcsine approximation is close, not exact
    }
}

TEST(Power, ResultsDoNotDependOnTheNumberOfThreads) {
    PowerOptions o;
    o.participantsPerGroup = {6, 10};
    o.simulations = 12;
    o.seed = 3;
    o.threads = 1;
    const auto sim = twoGroups(0.75, 0.55, 4, 0.8);
    const auto one = simulatePower(sim, 2, o);
    o.threads = 3;
    const auto three = simulatePower(sim, 2, o);
    ASSERT_EQ(one.points.size(), three.points.size());
    for (std::size_t i = 0; i < one.points.size(); ++i) {
        EXPECT_EQ(one.points[i].classic.significant, three.points[i].classic.significant);
        EXPECT_EQ(one.points[i].mixed.significant, three.points[i].mixed.significant);
        EXPECT_EQ(one.points[i].mixedSingular, three.points[i].mixedSingular);
    }
}

TEST(Power, GrowsWithGroupSizeAndFindsTheSmallestSizeReachingTheTarget) {
    PowerOptions o;
    o.participantsPerGroup = {40, 5, 80};
    o.simulations = 300;
    o.mixedModel = false;
    const auto curve = simulatePower(twoGroups(0.8, 0.5, 2, 0.0), 2, o);
    ASSERT_EQ(curve.points.size(), 3u);
    EXPECT_LT(curve.points[1].classic.power, curve.points[0].classic.power);
    EXPECT_LT(curve.points[0].classic.power, curve.points[2].classic.power);
    EXPECT_GT(curve.points[2].classic.power, 0.8);
    EXPECT_LT(curve.points[1].classic.power, 0.8);
    EXPECT_EQ(curve.smallestClassic, curve.points[0].classic.power >= 0.8 ? 40 : 80);
    EXPECT_EQ(curve.smallestMixed, -1);
}

TEST(Power, RejectsImpossibleRequests) {
    PowerOptions o;
    o.simulations = 0;
    EXPECT_THROW(simulatePower(twoGroups(0.5, 0.5, 1, 0), 2, o), std::invalid_argument);
    o.simulations = 1;
    EXPECT_THROW(simulatePower(twoGroups(0.5, 0.5, 1, 0), 1, o), std::invalid_argument);
}
