// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Mixed-effects models with one random intercept per participant, as lme4 / lmerTest fit them:
/// the logistic model `y ~ condition (+ surface) + (1 | participant)` by maximum likelihood
/// (Laplace approximation, nAGQ = 1, or adaptive Gauss-Hermite quadrature, nAGQ > 1) and the
/// linear model `y ~ condition (+ surface) + (1 | participant)` by REML with Satterthwaite
/// degrees of freedom. No Qt. Problems R reports as warnings (singular fit, separation,
/// non-convergence) are carried in `warnings`; where R stops, `error` holds the reason.
#include <limits>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// Long-format data of one model: one entry per observation in every vector.
struct MixedModelData {
    std::vector<double> y;                ///< 0/1 (logistic) or numeric (linear); NaN = missing
    std::vector<std::string> condition;   ///< fixed factor whose effect the LRT tests
    std::vector<std::string> participant; ///< grouping factor of the random intercept
    std::vector<std::string> surface;     ///< optional second fixed factor (empty = none)
    /// Level orders (first = reference level); empty = sorted as R's factor() sorts C-locale
    /// strings. Levels absent from the data are dropped.
    std::vector<std::string> conditionLevels;
    std::vector<std::string> surfaceLevels;
};

/// One fixed-effect coefficient (R's summary()$coefficients row).
struct FixedEffect {
    std::string name; ///< "(Intercept)", "conditionB", "surfacegravel", ...
    double estimate = std::numeric_limits<double>::quiet_NaN();
    double se = std::numeric_limits<double>::quiet_NaN();
    double statistic = std::numeric_limits<double>::quiet_NaN(); ///< Wald z or t
    double df = std::numeric_limits<double>::quiet_NaN(); ///< Satterthwaite df (linear) or NaN
    double p = std::numeric_limits<double>::quiet_NaN();
};

/// Likelihood-ratio test of the condition effect (R's anova(reduced, full)).
struct LikelihoodRatioTest {
    double statistic = std::numeric_limits<double>::quiet_NaN(); ///< Chisq
    double df = std::numeric_limits<double>::quiet_NaN();
    double p = std::numeric_limits<double>::quiet_NaN();
};

/// A fitted model.
struct MixedModelResult {
    std::string method;  ///< R's title, e.g. "Generalized linear mixed model fit by maximum ..."
    std::string formula; ///< e.g. "y ~ condition + (1 | participant)"
    std::vector<FixedEffect> fixed;
    std::string statisticName;                                          ///< "z" or "t"
    double randomVariance = std::numeric_limits<double>::quiet_NaN();   ///< participant intercept
    double residualVariance = std::numeric_limits<double>::quiet_NaN(); ///< linear model only
    double logLik = std::numeric_limits<double>::quiet_NaN(); ///< REML log-likelihood (linear)
    double aic = std::numeric_limits<double>::quiet_NaN();
    double deviance = std::numeric_limits<double>::quiet_NaN(); ///< -2 logLik (REML crit.)
    double nObs = 0;
    double nGroups = 0;
    int nAGQ = 1;
    LikelihoodRatioTest lrt; ///< NaN when the model has no condition term
    std::vector<std::string> warnings;
    std::string error; ///< non-empty when R would stop()

    [[nodiscard]] bool ok() const { return error.empty(); }
    /// The coefficient with this name, or nullptr.
    [[nodiscard]] const FixedEffect* coefficient(const std::string& name) const;
};

/// Logistic GLMM, lme4::glmer(y ~ condition (+ surface) + (1 | participant), family =
/// binomial, nAGQ = nAGQ). nAGQ in 1..25 (R's limit); y must be 0 or 1. Without
/// `standardErrors` the Hessian (SEs, Wald tests, convergence checks) is skipped: estimates,
/// variance, logLik and LRT only (power simulations).
MixedModelResult fitLogisticMixedModel(const MixedModelData& data, int nAGQ = 1,
                                       bool standardErrors = true);

/// One cell of a logistic mixed model given by integer codes (power simulations): the trials
/// and successes of one participant in one condition (and surface).
struct BinomialCell {
    int participant = 0; ///< 0-based codes; levels are ordered by their codes
    int condition = 0;
    int surface = -1; ///< -1: no surface factor
    double trials = 0;
    double successes = 0;
};

/// The likelihood-ratio test of the condition (R's anova(m0, m1)) of glmer(y ~ condition
/// (+ surface) + (1 | participant), binomial, nAGQ) fitted on cells: the optimum
/// fitLogisticMixedModel reaches on the same answers given one by one (levels ordered by their
/// codes), without strings, standard errors or warnings. Used by the power simulations.
struct LogisticLrt {
    double statistic = std::numeric_limits<double>::quiet_NaN();
    double df = std::numeric_limits<double>::quiet_NaN();
    double p = std::numeric_limits<double>::quiet_NaN();
    double randomVariance = std::numeric_limits<double>::quiet_NaN();
    std::string error; ///< non-empty where R would stop
};
LogisticLrt logisticLikelihoodRatio(const std::vector<BinomialCell>& cells, int nAGQ = 1);

/// Linear mixed model by REML, lmerTest::lmer(y ~ condition (+ surface) + (1 | participant));
/// the LRT refits both models by ML as R's anova() does.
MixedModelResult fitLinearMixedModel(const MixedModelData& data);

/// Nodes and weights of the Gauss-Hermite rule for the standard normal density (lme4::GHrule).
void gaussHermiteRule(int points, std::vector<double>& nodes, std::vector<double>& weights);

} // namespace underfoot::analysis
