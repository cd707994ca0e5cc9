// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Cumulative link mixed model for ratings, as R's ordinal::clmm fits
/// `clmm(y ~ condition (+ surface) + (1 | participant), link, threshold = "flexible", nAGQ)`:
/// P(Y <= j) = F(theta_j - x'beta - b), b ~ N(0, sigma^2) per participant, F the logistic,
/// normal or complementary log-log distribution. Maximum likelihood with the Laplace
/// approximation (nAGQ = 1) or adaptive Gauss-Hermite quadrature (nAGQ 2..25) at the conditional
/// modes; standard errors from the finite-difference Hessian of the negative log-likelihood in
/// (thresholds, beta, sigma), as clmm. No Qt.
// Sources: Christensen (2019), "A Tutorial on fitting Cumulative Link Mixed Models with clmm2
// from the ordinal Package" and the ordinal package reference (clmm: likelihood, Laplace and
// adaptive quadrature); Agresti (2010), Analysis of Ordinal Categorical Data, 2nd ed., ch. 10;
// Pinheiro & Bates (1995), J. Comput. Graph. Stat. 4(1) (adaptive Gauss-Hermite).
#include "analysis/stats/MixedModels.h"

#include <string>
#include <vector>

namespace underfoot::analysis {

enum class OrdinalLink { Logit, Probit, Cloglog };

/// The most response categories a fit takes (a 0..100 slider has 101); more is refused, as the
/// Hessian grows with their square.
inline constexpr std::size_t kMaxOrdinalCategories = 101;

/// "logit", "probit", "cloglog".
std::string toString(OrdinalLink link);
/// Parses a link name; false when unknown.
bool parseOrdinalLink(const std::string& text, OrdinalLink& link);

struct OrdinalOptions {
    OrdinalLink link = OrdinalLink::Logit;
    int nAGQ = 1; ///< 1 = Laplace, 2..25 adaptive Gauss-Hermite
    /// Categories of the scale in order (e.g. 1..7); empty = the values present. A category
    /// never used is dropped, as clmm drops unused levels of the response, with a warning.
    std::vector<double> categories;
    /// Without it the Hessian (SEs, Wald tests) is skipped: estimates, variance, logLik and LRT
    /// only (power simulations).
    bool standardErrors = true;
    bool likelihoodRatio = true; ///< also fit the model without the condition (LRT)
};

/// A fitted clmm: the fixed effects (no intercept: the thresholds take its place), thresholds
/// named "1|2", "2|3", ... after the categories used (statistic = z, p unused as in clmm's
/// summary), the participant variance, logLik, AIC and the LRT of the condition.
struct OrdinalMixedResult : MixedModelResult {
    std::vector<FixedEffect> thresholds;
    std::string link;
    std::vector<double> categories; ///< the categories used, in order
};

/// Fits the model; y holds the ratings (finite numbers, NaN = missing), ordered numerically.
OrdinalMixedResult fitOrdinalMixedModel(const MixedModelData& data,
                                        const OrdinalOptions& options = {});

} // namespace underfoot::analysis
