// SPDX-License-Identifier: GPL-3.0-or-later
// The optimum-only GLMM fit of the power simulations (fitLogisticMixedModel(d, 1, false):
// Laplace deviance minimised with its analytic gradient by L-BFGS) must reach the optimum of the
// full fit (BOBYQA with restarts, checked against R in MixedModelsTest.cpp): same log-likelihood,
// estimates, variance and likelihood-ratio test, on simulated studies of the power command's
// shape (groups, surfaces, repeated answers, participant variability), including singular fits.
#include "analysis/stats/MixedModels.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace underfoot::analysis;

namespace {

MixedModelData simulate(std::uint64_t seed, int groups, int perGroup, int surfaces, int reps,
                        double sd) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    MixedModelData d;
    int participant = 0;
    for (int g = 0; g < groups; ++g)
        for (int i = 0; i < perGroup; ++i, ++participant) {
            const double ability = sd * normal(rng);
            for (int s = 0; s < surfaces; ++s)
                for (int r = 0; r < reps; ++r) {
                    const double eta = 0.3 + 0.5 * g - 0.4 * s + ability;
                    d.y.push_back(uniform(rng) < 1 / (1 + std::exp(-eta)) ? 1.0 : 0.0);
                    d.condition.push_back(fmt::format("g{}", g));
                    d.participant.push_back(fmt::format("p{:03d}", participant));
                    if (surfaces > 1) d.surface.push_back(fmt::format("s{}", s));
                }
        }
    return d;
}

} // namespace

TEST(MixedModelsFastPath, ReachesTheOptimumOfTheFullFit) {
    int singular = 0;
    for (std::uint64_t seed = 1; seed <= 24; ++seed) {
        const int groups = 2 + static_cast<int>(seed % 2);
        const int perGroup = 5 + static_cast<int>(seed % 4) * 5;
        const int surfaces = seed % 3 == 0 ? 1 : 4;
        const double sd = seed % 4 == 0 ? 0.0 : 0.9;
        const auto d = simulate(seed, groups, perGroup, surfaces, 2, sd);
        SCOPED_TRACE(fmt::format("seed {}: {} groups x {} participants, {} surface(s), sd {}", seed,
                                 groups, perGroup, surfaces, sd));
        const auto full = fitLogisticMixedModel(d, 1, true);
        const auto fast = fitLogisticMixedModel(d, 1, false);
        ASSERT_TRUE(full.ok()) << full.error;
        ASSERT_TRUE(fast.ok()) << fast.error;
        EXPECT_NEAR(fast.logLik, full.logLik, 1e-7 * std::fabs(full.logLik));
        EXPECT_NEAR(fast.lrt.statistic, full.lrt.statistic, 1e-5 + 1e-5 * full.lrt.statistic);
        EXPECT_NEAR(fast.lrt.p, full.lrt.p, 1e-4 * full.lrt.p + 1e-12);
        EXPECT_NEAR(fast.randomVariance, full.randomVariance, 1e-4 * full.randomVariance + 1e-6);
        ASSERT_EQ(fast.fixed.size(), full.fixed.size());
        for (std::size_t j = 0; j < full.fixed.size(); ++j)
            EXPECT_NEAR(fast.fixed[j].estimate, full.fixed[j].estimate,
                        1e-4 * std::fabs(full.fixed[j].estimate) + 1e-5)
                << full.fixed[j].name;
        singular += full.randomVariance < 1e-8 ? 1 : 0;
    }
    EXPECT_GT(singular, 0) << "no singular fit among the cases: the boundary is not exercised";
}
