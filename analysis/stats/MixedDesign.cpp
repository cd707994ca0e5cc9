// SPDX-License-Identifier: GPL-3.0-or-later
// Design matrices and optimiser helpers shared by the mixed models (see MixedDesign.h).
#include "analysis/stats/MixedDesign.h"

#include "analysis/stats/Numerics.h"

#include <fmt/format.h>
#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string_view>

namespace underfoot::analysis::mixed {

using numerics::dbl;

// ------------------------------------------------------------------------------ design

std::vector<std::string> levelsOf(const std::vector<std::string>& values,
                                  const std::vector<std::string>& order) {
    std::vector<std::string> present(values);
    std::sort(present.begin(), present.end());
    present.erase(std::unique(present.begin(), present.end()), present.end());
    if (order.empty()) return present;
    std::vector<std::string> out;
    for (const auto& l : order)
        if (std::binary_search(present.begin(), present.end(), l) &&
            std::find(out.begin(), out.end(), l) == out.end())
            out.push_back(l);
    for (const auto& l : present) // values not named in the order follow, sorted
        if (std::find(out.begin(), out.end(), l) == out.end()) out.push_back(l);
    return out;
}

/// Builds X for `~ condition (+ surface)` (treatment contrasts, as R's model.matrix), drops
/// rows with a missing value (R's na.omit) and aliased columns (lme4's chkRank.drop.cols).
Design buildDesign(const MixedModelData& data, bool withCondition) {
    Design d;
    const std::size_t n = data.y.size();
    const bool hasSurface = !data.surface.empty();
    if (data.condition.size() != n || data.participant.size() != n ||
        (hasSurface && data.surface.size() != n)) {
        d.error = fmt::format(
            "y, condition, participant{} must have the same length ({}, {}, {}{})",
            hasSurface ? ", surface" : "", n, data.condition.size(), data.participant.size(),
            hasSurface ? fmt::format(", {}", data.surface.size()) : "");
        return d;
    }
    std::vector<std::size_t> rows;
    for (std::size_t i = 0; i < n; ++i) {
        if (std::isinf(data.y[i])) {
            d.error = fmt::format("y[{}] is infinite (only finite values or missing)", i);
            return d;
        }
        if (std::isnan(data.y[i]) || data.condition[i].empty() || data.participant[i].empty() ||
            (hasSurface && data.surface[i].empty()))
            continue;
        rows.push_back(i);
    }
    if (rows.empty()) {
        d.error = "no complete observations (0 (non-NA) cases)";
        return d;
    }
    auto pick = [&](const std::vector<std::string>& v) {
        std::vector<std::string> out;
        out.reserve(rows.size());
        for (auto r : rows) out.push_back(v[r]);
        return out;
    };
    const auto cond = pick(data.condition);
    const auto part = pick(data.participant);
    const auto surf = hasSurface ? pick(data.surface) : std::vector<std::string>{};
    const auto condLevels = levelsOf(cond, data.conditionLevels);
    const auto surfLevels =
        hasSurface ? levelsOf(surf, data.surfaceLevels) : std::vector<std::string>{};
    const auto partLevels = levelsOf(part, {});
    if (withCondition && condLevels.size() < 2) {
        d.error = "contrasts can be applied only to factors with 2 or more levels (condition has "
                  "one level)";
        return d;
    }
    if (hasSurface && surfLevels.size() < 2) {
        d.error = "contrasts can be applied only to factors with 2 or more levels (surface has "
                  "one level)";
        return d;
    }
    const std::size_t m = rows.size();
    // candidate columns: intercept, condition dummies, surface dummies
    std::vector<VectorXd> columns;
    std::vector<std::string> names;
    std::vector<bool> isCondition;
    columns.push_back(VectorXd::Ones(static_cast<Eigen::Index>(m)));
    names.emplace_back("(Intercept)");
    isCondition.push_back(false);
    auto addFactor = [&](const std::vector<std::string>& v, const std::vector<std::string>& levels,
                         const std::string& prefix, bool condition) {
        std::map<std::string_view, std::size_t> levelOf; // one lookup per row
        for (std::size_t l = 0; l < levels.size(); ++l) levelOf.emplace(levels[l], l);
        const std::size_t first = columns.size();
        for (std::size_t l = 1; l < levels.size(); ++l) {
            columns.push_back(VectorXd::Zero(static_cast<Eigen::Index>(m)));
            names.push_back(prefix + levels[l]);
            isCondition.push_back(condition);
        }
        for (std::size_t i = 0; i < m; ++i)
            if (const std::size_t l = levelOf.at(v[i]); l > 0)
                columns[first + l - 1](static_cast<Eigen::Index>(i)) = 1.0;
    };
    if (withCondition) addFactor(cond, condLevels, "condition", true);
    if (hasSurface) addFactor(surf, surfLevels, "surface", false);
    // keep a column when it is not (numerically) in the span of the kept ones
    std::vector<VectorXd> basis;
    std::vector<std::size_t> kept;
    for (std::size_t c = 0; c < columns.size(); ++c) {
        VectorXd r = columns[c];
        const double norm0 = r.norm();
        for (int pass = 0; pass < 2; ++pass)
            for (const auto& q : basis) r -= q * q.dot(r);
        if (norm0 > 0 && r.norm() > 1e-7 * norm0) {
            basis.push_back(r / r.norm());
            kept.push_back(c);
        }
    }
    const std::size_t dropped = columns.size() - kept.size();
    if (dropped > 0)
        d.warnings.push_back(
            fmt::format("fixed-effect model matrix is rank deficient so dropping {} column{} / "
                        "coefficient{}",
                        dropped, dropped == 1 ? "" : "s", dropped == 1 ? "" : "s"));
    d.X.resize(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(kept.size()));
    for (std::size_t k = 0; k < kept.size(); ++k) {
        d.X.col(static_cast<Eigen::Index>(k)) = columns[kept[k]];
        d.names.push_back(names[kept[k]]);
        if (isCondition[kept[k]]) ++d.conditionColumns;
    }
    d.y.resize(static_cast<Eigen::Index>(m));
    for (std::size_t i = 0; i < m; ++i) d.y(static_cast<Eigen::Index>(i)) = data.y[rows[i]];
    std::map<std::string, int> index;
    for (std::size_t g = 0; g < partLevels.size(); ++g) index[partLevels[g]] = static_cast<int>(g);
    d.nGroups = static_cast<int>(partLevels.size());
    d.members.resize(partLevels.size());
    for (std::size_t i = 0; i < m; ++i) {
        const int g = index[part[i]];
        d.group.push_back(g);
        d.members[static_cast<std::size_t>(g)].push_back(static_cast<int>(i));
    }
    if (d.nGroups < 2) {
        d.error = "grouping factors must have > 1 sampled level (participant has one level)";
        return d;
    }
    return d;
}

/// Symmetric matrix inverse through the eigen decomposition; fails (returns false) when not
/// positive definite.
bool invertPositiveDefinite(const MatrixXd& h, MatrixXd& inverse) {
    Eigen::LDLT<MatrixXd> ldlt(h);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
    const auto d = ldlt.vectorD();
    for (Eigen::Index i = 0; i < d.size(); ++i)
        if (!(d(i) > 0)) return false;
    inverse = ldlt.solve(MatrixXd::Identity(h.rows(), h.cols()));
    return true;
}

/// Gradient and Hessian by central differences, as lme4's deriv12 (delta = 1e-4).
void deriv12(const std::function<double(const std::vector<double>&)>& f,
             const std::vector<double>& x, double fx, VectorXd& gradient, MatrixXd& hessian,
             double delta) {
    const auto k = static_cast<Eigen::Index>(x.size());
    gradient.resize(k);
    hessian.resize(k, k);
    for (Eigen::Index i = 0; i < k; ++i) {
        auto xa = x, xs = x;
        xa[static_cast<std::size_t>(i)] += delta;
        xs[static_cast<std::size_t>(i)] -= delta;
        const double fa = f(xa), fs = f(xs);
        hessian(i, i) = (fa - 2 * fx + fs) / (delta * delta);
        gradient(i) = (fa - fs) / (2 * delta);
        for (Eigen::Index j = 0; j < i; ++j) {
            auto xaa = x, xas = x, xsa = x, xss = x;
            const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
            xaa[ui] += delta, xaa[uj] += delta;
            xas[ui] += delta, xas[uj] -= delta;
            xsa[ui] -= delta, xsa[uj] += delta;
            xss[ui] -= delta, xss[uj] -= delta;
            hessian(i, j) = hessian(j, i) =
                (f(xaa) - f(xas) - f(xsa) + f(xss)) / (4 * delta * delta);
        }
    }
}

/// Minimises f with NLopt's BOBYQA (bounds `lower`), then restarts from the optimum with a
/// small step until the value stops improving, so the optimum is reached tightly.
Optimum minimise(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x,
                 const std::vector<double>& lower, double step) {
    Optimum out;
    struct Ctx {
        const std::function<double(const std::vector<double>&)>* f;
    } ctx{&f};
    auto thunk = [](const std::vector<double>& v, std::vector<double>&, void* data) {
        const double r = (*static_cast<Ctx*>(data)->f)(v);
        return std::isfinite(r) ? r : 1e300;
    };
    double best = f(x);
    for (int round = 0; round < 4; ++round) {
        nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(x.size()));
        opt.set_lower_bounds(lower);
        opt.set_min_objective(thunk, &ctx);
        opt.set_xtol_rel(1e-10);
        opt.set_ftol_abs(1e-12);
        opt.set_maxeval(20000);
        opt.set_initial_step(round == 0 ? step : step * 0.01);
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::max(x[i], lower[i]);
        double value = best;
        try {
            const auto status = opt.optimize(x, value);
            if (status == nlopt::MAXEVAL_REACHED) {
                out.converged = false;
                out.message = "maximum number of function evaluations exceeded";
            }
        } catch (const std::exception& e) {
            out.converged = false;
            out.message = e.what();
        }
        const bool improved = value < best - 1e-9;
        best = std::min(best, value);
        if (!improved && round > 0) break;
    }
    out.x = x;
    out.value = f(x);
    return out;
}

/// Records the design's size in `r`; false (with R's message in r.error) when R would stop.
bool describeDesign(const Design& d, MixedModelResult& r) {
    r.nObs = dbl(d.y.size());
    r.nGroups = d.nGroups;
    r.error = d.error;
    return d.error.empty();
}

} // namespace underfoot::analysis::mixed
