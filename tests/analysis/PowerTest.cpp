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

namespace {

/// Each participant rates both conditions `ratings` times: bias N(0, sdBias) + effect (0 or
/// `effect`) + noise N(0, sdNoise).
RatingStudySimulator pairedRatings(double effect, double sdBias, double sdNoise, int ratings) {
    return [=](int participants, std::uint64_t seed) {
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> normal(0.0, 1.0);
        std::vector<SimulatedRating> out;
        for (int i = 0; i < participants; ++i) {
            const double bias = sdBias * normal(rng);
            for (int c = 0; c < 2; ++c)
                for (int k = 0; k < ratings; ++k)
                    out.push_back({i, c, bias + (c == 1 ? effect : 0.0) + sdNoise * normal(rng)});
        }
        return out;
    };
}

} // namespace

TEST(Power, RatingPowerReducesToThePairedTTest) {
    // Rscript tests/analysis/data/power_reference.R (pwr 1.3):
    // pwr.t.test(n = n, d = 0.6 / sqrt(2), sig.level = 0.05, type = "paired")$power
    const std::pair<int, double> cases[] = {
        {12, 0.2691122802}, {20, 0.4370760233}, {40, 0.7443290134}};
    PowerOptions o;
    o.simulations = 1500;
    o.seed = 11;
    o.confLevel = 0.999;
    o.ordinalModel = false; // continuous ratings: no categories for the clmm
    o.participantsPerGroup.clear();
    for (const auto& [n, exact] : cases) o.participantsPerGroup.push_back(n);
    const auto curve = simulateRatingPower(pairedRatings(0.6, 1.0, 1.0, 1), o);
    ASSERT_EQ(curve.points.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        const auto& pt = curve.points[i];
        const double exact = cases[i].second;
        EXPECT_LE(pt.classic.clopperPearson.lower, exact) << pt.participantsPerGroup;
        EXPECT_GE(pt.classic.clopperPearson.upper, exact) << pt.participantsPerGroup;
        // one rating per condition: the random-intercept model is the paired t-test whenever
        // the participant variance is estimated positive (singular fits use 2n - 2 df instead)
        EXPECT_NEAR(pt.mixed.power, pt.classic.power, 0.03) << pt.participantsPerGroup;
        EXPECT_EQ(pt.mixedFailures, 0);
    }
    EXPECT_EQ(curve.smallestClassic, -1); // 0.744 at 40 < 0.8
}

TEST(Power, RatingPowerOfRepeatedRatingsGrowsWithParticipants) {
    PowerOptions o;
    o.participantsPerGroup = {30, 6};
    o.simulations = 200;
    o.seed = 5;
    const auto curve = simulateRatingPower(pairedRatings(0.8, 1.5, 1.3, 2), o);
    ASSERT_EQ(curve.points.size(), 2u);
    EXPECT_LT(curve.points[1].classic.power, curve.points[0].classic.power);
    EXPECT_LT(curve.points[1].mixed.power, curve.points[0].mixed.power);
    EXPECT_GT(curve.points[0].mixed.power, 0.8);
    EXPECT_EQ(curve.smallestMixed, 30);
}

namespace {

/// Ratings 1..7 of a latent logistic variable (participant intercept SD 1) cut at 1.5, 2.5,
/// ..., 6.5 around 4: a proportional-odds model with log odds ratio `logOr` for condition 1.
RatingStudySimulator ordinalRatings(double logOr, int ratings) {
    return [=](int participants, std::uint64_t seed) {
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> normal;
        std::uniform_real_distribution<double> uniform(1e-12, 1.0 - 1e-12);
        std::vector<SimulatedRating> out;
        for (int i = 0; i < participants; ++i) {
            const double bias = normal(rng);
            for (int c = 0; c < 2; ++c)
                for (int k = 0; k < ratings; ++k) {
                    const double u = uniform(rng);
                    const double latent =
                        4.0 + bias + (c == 1 ? logOr : 0.0) + std::log(u / (1 - u));
                    out.push_back({i, c, std::clamp(std::round(latent), 1.0, 7.0)});
                }
        }
        return out;
    };
}

} // namespace

TEST(Power, OrdinalRatingPowerHoldsItsLevelAndGrowsWithParticipants) {
    PowerOptions o;
    o.participantsPerGroup = {24};
    o.simulations = 300;
    o.seed = 7;
    o.confLevel = 0.999;
    const auto null = simulateRatingPower(ordinalRatings(0.0, 3), o);
    ASSERT_TRUE(null.ordinal);
    // no effect: the clmm's LRT rejects at its level (Monte-Carlo interval covers 0.05)
    EXPECT_LE(null.points[0].ordinal.clopperPearson.lower, 0.05);
    EXPECT_GE(null.points[0].ordinal.clopperPearson.upper, 0.05);
    EXPECT_EQ(null.points[0].ordinalFailures, 0);
    o.participantsPerGroup = {6, 24};
    o.simulations = 150;
    const auto curve = simulateRatingPower(ordinalRatings(1.0, 3), o);
    EXPECT_LT(curve.points[0].ordinal.power, curve.points[1].ordinal.power);
    EXPECT_GT(curve.points[1].ordinal.power, 0.8);
    EXPECT_EQ(curve.smallestOrdinal, 24);
}
