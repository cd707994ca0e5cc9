// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Internal to the mixed models (MixedModels.cpp, OrdinalMixed.cpp): the fixed-effects design of
/// `~ condition (+ surface)` with treatment contrasts as R's model.matrix, rank-deficient
/// columns dropped as lme4's chkRank.drop.cols, the grouping by participant, and the optimiser
/// and finite-difference helpers both fits use. Not part of the analysis API.
#include "analysis/stats/MixedModels.h"

#include <Eigen/Dense>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace underfoot::analysis::mixed {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// Fixed-effects design matrix, response and grouping of one model.
struct Design {
    MatrixXd X;
    std::vector<std::string> names;
    VectorXd y;
    std::vector<int> group; ///< 0-based participant index per observation
    int nGroups = 0;
    std::vector<std::vector<int>> members; ///< observations of each participant
    int conditionColumns = 0;              ///< condition dummies kept in X
    std::vector<std::string> warnings;
    std::string error;
};

/// Level order of a factor: `order` first (levels absent from the data dropped), the other
/// values after it, sorted; empty `order` = sorted as R's factor() sorts C-locale strings.
std::vector<std::string> levelsOf(const std::vector<std::string>& values,
                                  const std::vector<std::string>& order);

/// Builds X for `~ condition (+ surface)` (treatment contrasts, as R's model.matrix), drops
/// rows with a missing value (R's na.omit) and aliased columns (lme4's chkRank.drop.cols).
Design buildDesign(const MixedModelData& data, bool withCondition);

/// Records the design's size in `r`; false (with R's message in r.error) when R would stop.
bool describeDesign(const Design& d, MixedModelResult& r);

/// Symmetric matrix inverse; false when not positive definite.
bool invertPositiveDefinite(const MatrixXd& h, MatrixXd& inverse);

/// Gradient and Hessian by central differences, as lme4's deriv12 (delta = 1e-4).
void deriv12(const std::function<double(const std::vector<double>&)>& f,
             const std::vector<double>& x, double fx, VectorXd& gradient, MatrixXd& hessian,
             double delta = 1e-4);

struct Optimum {
    std::vector<double> x;
    double value = std::numeric_limits<double>::quiet_NaN();
    bool converged = true;
    std::string message;
};

/// Minimises f with NLopt's BOBYQA (bounds `lower`), then restarts from the optimum with a
/// small step until the value stops improving, so the optimum is reached tightly.
Optimum minimise(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x,
                 const std::vector<double>& lower, double step);

} // namespace underfoot::analysis::mixed
