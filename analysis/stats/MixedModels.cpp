// SPDX-License-Identifier: GPL-3.0-or-later
// Mixed-effects models with one random intercept per participant (see MixedModels.h).
#include "analysis/stats/MixedModels.h"

#include "analysis/stats/Numerics.h"

#include <Eigen/Dense>
#include <boost/math/tools/minima.hpp>
#include <fmt/format.h>
#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string_view>

namespace underfoot::analysis {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using numerics::dbl;
using numerics::kNaN;

// ------------------------------------------------------------------------------ design

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
             double delta = 1e-4) {
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

// ------------------------------------------------------------------------------ logistic

/// Deviance (-2 log-likelihood) of the logistic model with a random intercept b = theta * u,
/// u ~ N(0, 1), integrated per participant by the Laplace approximation (nAGQ = 1) or adaptive
/// Gauss-Hermite quadrature centred at the conditional mode (nAGQ > 1).
// Source: Bates, Maechler, Bolker & Walker (2015), lme4, J. Stat. Softw. 67(1) (Laplace,
// PIRLS); Pinheiro & Bates (1995), J. Comput. Graph. Stat. 4(1) (adaptive Gauss-Hermite).
class LogisticDeviance {
  public:
    LogisticDeviance(const Design& design, int nAGQ)
        : d_(design), u_(static_cast<std::size_t>(design.nGroups), 0.0) {
        if (nAGQ > 1) gaussHermiteRule(nAGQ, nodes_, weights_);
        for (double w : weights_) logWeights_.push_back(std::log(w));
        // Observations of one participant with the same fixed-effects row share their linear
        // predictor: summed as binomial counts (the same likelihood, far fewer terms).
        cells_.resize(design.members.size());
        for (std::size_t g = 0; g < design.members.size(); ++g) {
            auto& cells = cells_[g];
            for (int i : design.members[g]) {
                // a participant has few distinct rows: a linear search, no allocation
                std::size_t c = 0;
                while (c < cells.size() && design.X.row(cells[c].row) != design.X.row(i)) ++c;
                if (c == cells.size()) cells.push_back({i, 0.0, 0.0});
                cells[c].n += 1;
                cells[c].successes += design.y(i);
            }
        }
    }

    double operator()(const std::vector<double>& par) {
        const double theta = par[0];
        VectorXd beta(d_.X.cols());
        for (Eigen::Index j = 0; j < beta.size(); ++j)
            beta(j) = par[static_cast<std::size_t>(j) + 1];
        const VectorXd offset = d_.X * beta;
        double dev = 0;
        for (std::size_t g = 0; g < d_.members.size(); ++g) dev += groupDeviance(g, theta, offset);
        return dev;
    }

    /// Laplace deviance (nAGQ = 1) and its analytic gradient in (theta, beta): per participant
    /// D = 2 g(u^) + log g''(u^) with g'(u^) = 0, differentiated through u^ by the implicit
    /// function theorem (du^/dpsi = -g_upsi / g_uu). Used by the power simulations' optimiser.
    double laplaceGradient(const std::vector<double>& par, std::vector<double>& grad) {
        const double theta = par[0];
        const auto p = d_.X.cols();
        beta_.resize(p);
        for (Eigen::Index j = 0; j < p; ++j) beta_(j) = par[static_cast<std::size_t>(j) + 1];
        offset_.noalias() = d_.X * beta_;
        grad.assign(par.size(), 0.0);
        gBeta_.resize(p), wx_.resize(p), tx_.resize(p);
        double dev = 0;
        for (std::size_t g = 0; g < cells_.size(); ++g) {
            const double u = conditionalMode(g, theta, offset_);
            u_[g] = u;
            double value = 0.5 * u * u, sr = 0, sw = 0, st = 0;
            gBeta_.setZero(), wx_.setZero(), tx_.setZero();
            for (const Cell& c : cells_[g]) {
                const double eta = offset_(c.row) + theta * u;
                const double e = std::exp(-std::fabs(eta));
                const double mu = eta >= 0 ? 1.0 / (1.0 + e) : e / (1.0 + e);
                const double failures = c.n - c.successes;
                value += c.successes * std::max(-eta, 0.0) + failures * std::max(eta, 0.0) +
                         c.n * std::log1p(e);
                const double r = c.n * mu - c.successes;
                const double w = c.n * e / ((1.0 + e) * (1.0 + e));
                const double t = w * (1.0 - 2.0 * mu);
                sr += r, sw += w, st += t;
                const auto x = d_.X.row(c.row);
                gBeta_.noalias() += r * x.transpose();
                wx_.noalias() += w * x.transpose();
                tx_.noalias() += t * x.transpose();
            }
            const double d2 = theta * theta * sw + 1.0;
            dev += 2.0 * value + std::log(d2);
            const double d2u = theta * theta * theta * st; // d g''/du
            // theta: dg/dtheta = u sr; d g''/dtheta = 2 theta sw + theta^2 u st;
            // g_utheta = sr + theta u sw
            const double duTheta = -(sr + theta * u * sw) / d2;
            grad[0] +=
                2.0 * u * sr + (2.0 * theta * sw + theta * theta * u * st + d2u * duTheta) / d2;
            for (Eigen::Index j = 0; j < p; ++j) {
                const double duBeta = -theta * wx_(j) / d2;
                grad[static_cast<std::size_t>(j) + 1] +=
                    2.0 * gBeta_(j) + (theta * theta * tx_(j) + d2u * duBeta) / d2;
            }
        }
        return dev;
    }

    /// lme4's fallback covariance of the fixed effects, RX^-1 RX^-T: the inverse of the Schur
    /// complement X'WX - X'WZ L (L'Z'WZL + I)^-1 L'Z'WX at the conditional modes.
    MatrixXd rxVcov(const std::vector<double>& par) {
        (*this)(par); // conditional modes at par
        const double theta = par[0];
        const auto p = d_.X.cols();
        VectorXd beta(p);
        for (Eigen::Index j = 0; j < p; ++j) beta(j) = par[static_cast<std::size_t>(j) + 1];
        const VectorXd offset = d_.X * beta;
        MatrixXd info = MatrixXd::Zero(p, p);
        for (std::size_t g = 0; g < cells_.size(); ++g) {
            VectorXd s = VectorXd::Zero(p);
            double wsum = 0;
            for (const Cell& c : cells_[g]) {
                const double mu = 1.0 / (1.0 + std::exp(-(offset(c.row) + theta * u_[g])));
                const double w = c.n * mu * (1 - mu);
                const VectorXd x = d_.X.row(c.row).transpose();
                info += w * x * x.transpose();
                s += w * x;
                wsum += w;
            }
            info -= theta * theta / (1.0 + theta * theta * wsum) * s * s.transpose();
        }
        return info.inverse();
    }

  private:
    /// g(u) = -log p(y | u) + u^2 / 2 (one exp and one log1p per cell); `d2` (optional) gets
    /// g''(u).
    double value(std::size_t g, double theta, const VectorXd& offset, double u,
                 double* d2 = nullptr) const {
        double v = 0.5 * u * u, s2 = 0;
        for (const Cell& c : cells_[g]) {
            const double eta = offset(c.row) + theta * u;
            const double e =
                std::exp(-std::fabs(eta)); // softplus(+-eta) = max(+-eta, 0) + log1p(e)
            const double failures = c.n - c.successes;
            v += c.successes * std::max(-eta, 0.0) + failures * std::max(eta, 0.0) +
                 c.n * std::log1p(e);
            if (d2) s2 += c.n * e / ((1.0 + e) * (1.0 + e));
        }
        if (d2) *d2 = theta * theta * s2 + 1.0;
        return v;
    }

    /// g'(u) and g''(u) (one exp per cell, no logarithm).
    void derivatives(std::size_t g, double theta, const VectorXd& offset, double u, double& d1,
                     double& d2) const {
        double s1 = 0, s2 = 0;
        for (const Cell& c : cells_[g]) {
            const double eta = offset(c.row) + theta * u;
            const double e = std::exp(-std::fabs(eta));
            const double mu = eta >= 0 ? 1.0 / (1.0 + e) : e / (1.0 + e);
            s1 += c.n * mu - c.successes;
            s2 += c.n * e / ((1.0 + e) * (1.0 + e));
        }
        d1 = theta * s1 + u;
        d2 = theta * theta * s2 + 1.0;
    }

    /// Conditional mode of u: g is strictly convex (g'' >= 1), so g' has one root, found by
    /// Newton's method kept inside the bracket of the root (bisection when a step leaves it or
    /// does not halve the previous one, as Numerical Recipes' rtsafe). Derivatives only: the
    /// value (logarithms) is computed once, at the mode.
    double conditionalMode(std::size_t g, double theta, const VectorXd& offset) const {
        double u = std::isfinite(u_[g]) ? u_[g] : 0.0;
        double lo = -numerics::kInf, hi = numerics::kInf, previous = numerics::kInf;
        for (int it = 0; it < 200; ++it) {
            double d1 = 0, d2 = 1;
            derivatives(g, theta, offset, u, d1, d2);
            if (d1 == 0) break;
            (d1 > 0 ? hi : lo) = u;
            double next = u - d1 / d2;
            const bool inside = next > lo && next < hi;
            const bool bounded = std::isfinite(lo) && std::isfinite(hi);
            const bool newton =
                !bounded || (inside && std::fabs(next - u) <= 0.5 * std::fabs(previous));
            if (!newton) next = 0.5 * (lo + hi);
            const double step = next - u;
            previous = step;
            u = next;
            // stop on a small Newton step only (quadratic convergence: u is then exact to
            // rounding, which the finite-difference Hessian of the deviance needs)
            if (newton && std::fabs(step) < 1e-11 * (1 + std::fabs(u))) break;
        }
        return u;
    }

    double groupDeviance(std::size_t g, double theta, const VectorXd& offset) {
        const double u = conditionalMode(g, theta, offset);
        u_[g] = u;
        double d2 = 1;
        const double value0 = value(g, theta, offset, u, &d2);
        if (nodes_.empty()) return 2 * value0 + std::log(d2);
        const double s = 1.0 / std::sqrt(d2);
        terms_.resize(nodes_.size());
        double top = -numerics::kInf;
        for (std::size_t k = 0; k < nodes_.size(); ++k) {
            const double gk = value(g, theta, offset, u + s * nodes_[k]);
            terms_[k] = -gk + 0.5 * nodes_[k] * nodes_[k] + logWeights_[k];
            top = std::max(top, terms_[k]);
        }
        double sum = 0;
        for (double t : terms_) sum += std::exp(t - top);
        return -2.0 * (std::log(s) + top + std::log(sum));
    }

    struct Cell {
        int row = 0; ///< an observation with this fixed-effects row
        double n = 0, successes = 0;
    };
    const Design& d_;
    std::vector<double> u_;
    std::vector<double> nodes_, weights_, logWeights_;
    std::vector<double> terms_;                ///< scratch of the quadrature sum
    VectorXd beta_, offset_, gBeta_, wx_, tx_; ///< scratch of laplaceGradient
    std::vector<std::vector<Cell>> cells_;
};

/// Logistic regression without random effect (R's glm IRLS), used as the starting point.
VectorXd glmStart(const Design& d) {
    const auto p = d.X.cols();
    VectorXd beta = VectorXd::Zero(p);
    for (int it = 0; it < 25; ++it) {
        const VectorXd eta = d.X * beta;
        VectorXd w(eta.size()), z(eta.size());
        for (Eigen::Index i = 0; i < eta.size(); ++i) {
            const double mu = 1.0 / (1.0 + std::exp(-eta(i)));
            const double v = std::max(mu * (1 - mu), 1e-10);
            w(i) = v;
            z(i) = eta(i) + (d.y(i) - mu) / v;
        }
        const MatrixXd xtw = d.X.transpose() * w.asDiagonal();
        const VectorXd next = (xtw * d.X).ldlt().solve(xtw * z);
        if (!next.allFinite()) break;
        const double change = (next - beta).norm();
        beta = next;
        if (change < 1e-10 * (1 + beta.norm())) break;
    }
    for (Eigen::Index j = 0; j < p; ++j) beta(j) = std::clamp(beta(j), -20.0, 20.0);
    return beta;
}

struct Optimum {
    std::vector<double> x;
    double value = kNaN;
    bool converged = true;
    std::string message;
};

/// Minimises f with NLopt's BOBYQA (bounds: theta >= 0), then restarts from the optimum with a
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

/// Minimises the Laplace deviance with its analytic gradient (NLopt's L-BFGS): the optimum
/// BOBYQA reaches, in a fraction of the deviance evaluations. Used where only the optimum is
/// needed (power simulations, the reduced model of the LRT); the full model keeps BOBYQA, whose
/// tight optimum the finite-difference Hessian (SEs) needs. The deviance is even in theta and
/// theta = 0 is always a stationary point, so theta is left unbounded (a bound would let the
/// line search stop on it) and |theta| returned.
Optimum minimiseLaplace(LogisticDeviance& deviance, std::vector<double> x) {
    Optimum out;
    struct Ctx {
        LogisticDeviance* deviance;
        std::vector<double> scratch;
    } ctx{&deviance, {}};
    auto thunk = [](const std::vector<double>& v, std::vector<double>& grad, void* data) {
        auto* c = static_cast<Ctx*>(data);
        const double r = c->deviance->laplaceGradient(v, grad.empty() ? c->scratch : grad);
        return std::isfinite(r) ? r : 1e300;
    };
    nlopt::opt opt(nlopt::LD_LBFGS, static_cast<unsigned>(x.size()));
    opt.set_min_objective(thunk, &ctx);
    opt.set_ftol_rel(1e-15);
    opt.set_xtol_rel(1e-10);
    opt.set_maxeval(5000);
    double value = 0;
    try {
        const auto status = opt.optimize(x, value);
        if (status == nlopt::MAXEVAL_REACHED) {
            out.converged = false;
            out.message = "maximum number of function evaluations exceeded";
        }
    } catch (const nlopt::roundoff_limited&) { // converged as far as rounding allows
    } catch (const std::exception& e) {
        out.converged = false;
        out.message = e.what();
    }
    x[0] = std::fabs(x[0]);
    out.x = x;
    out.value = deviance(x);
    return out;
}

/// lme4's convergence checks (checkConv): scaled gradient and Hessian eigenvalues.
void checkConvergence(const VectorXd& gradient, const MatrixXd& hessian, bool atBoundary,
                      std::vector<std::string>& warnings) {
    VectorXd g = gradient;
    MatrixXd h = hessian;
    if (atBoundary) { // lme4 drops boundary parameters from the checks
        g = gradient.tail(gradient.size() - 1);
        h = hessian.bottomRightCorner(hessian.rows() - 1, hessian.cols() - 1);
    }
    if (g.size() == 0) return;
    Eigen::LLT<MatrixXd> llt(h);
    if (llt.info() != Eigen::Success) {
        warnings.emplace_back("unable to evaluate scaled gradient");
    } else {
        const VectorXd scaled = llt.matrixU().solve(g);
        double worst = 0;
        Eigen::Index which = 0;
        for (Eigen::Index i = 0; i < g.size(); ++i) {
            const double m = std::min(std::fabs(scaled(i)), std::fabs(g(i)));
            if (m > worst) worst = m, which = i;
        }
        if (worst > 0.002)
            warnings.push_back(fmt::format(
                "Model failed to converge with max|grad| = {:.6g} (tol = 0.002, component {})",
                worst, which + 1));
    }
    Eigen::SelfAdjointEigenSolver<MatrixXd> eig(h);
    const auto ev = eig.eigenvalues();
    int negative = 0;
    for (Eigen::Index i = 0; i < ev.size(); ++i) negative += ev(i) < -1e-6 ? 1 : 0;
    if (negative > 0)
        warnings.push_back(fmt::format(
            "Model failed to converge: degenerate  Hessian with {} negative eigenvalues",
            negative));
    else if (ev.maxCoeff() > 0 && ev.minCoeff() / ev.maxCoeff() < 1e-6)
        warnings.emplace_back("Model is nearly unidentifiable: very large eigenvalue\n - Rescale "
                              "variables?");
}

/// Participants or conditions whose answers are all 0 or all 1 (quasi-complete separation).
void separationWarnings(const Design& d, std::vector<std::string>& warnings) {
    std::vector<std::string> separated;
    for (Eigen::Index c = 1; c < d.X.cols(); ++c) {
        double n = 0, s = 0;
        for (Eigen::Index i = 0; i < d.X.rows(); ++i)
            if (d.X(i, c) != 0) n += 1, s += d.y(i);
        if (n > 0 && (s == 0 || s == n))
            separated.push_back(d.names[static_cast<std::size_t>(c)] + " = 1");
    }
    { // the reference cell (every dummy 0)
        double n = 0, s = 0;
        for (Eigen::Index i = 0; i < d.X.rows(); ++i)
            if (d.X.row(i).tail(d.X.cols() - 1).isZero()) n += 1, s += d.y(i);
        if (n > 0 && (s == 0 || s == n)) separated.emplace_back("the reference levels");
    }
    double total = d.y.sum();
    if (total == 0 || total == dbl(d.y.size()))
        warnings.emplace_back(fmt::format(
            "complete separation: every answer is {} (the fixed effects are not identified)",
            total == 0 ? 0 : 1));
    else if (!separated.empty())
        warnings.push_back(fmt::format(
            "quasi-complete separation: every answer is the same where {} (its estimate "
            "diverges and its Wald test is meaningless; use the likelihood-ratio test)",
            fmt::join(separated, ", ")));
}

struct LogisticFit {
    Optimum opt;
    std::vector<std::string> warnings;
    MatrixXd vcov;
    bool vcovOk = false;
};

LogisticFit fitLogistic(const Design& d, int nAGQ, bool derivatives) {
    LogisticFit fit;
    LogisticDeviance deviance(d, nAGQ);
    const VectorXd start = glmStart(d);
    std::vector<double> x{1.0};
    for (Eigen::Index j = 0; j < start.size(); ++j) x.push_back(start(j));
    std::vector<double> lower(x.size(), -numerics::kInf);
    lower[0] = 0.0;
    std::function<double(const std::vector<double>&)> f = [&](const std::vector<double>& v) {
        return deviance(v);
    };
    fit.opt = !derivatives && nAGQ == 1 ? minimiseLaplace(deviance, x) : minimise(f, x, lower, 0.2);
    if (fit.opt.x[0] > 0) { // a flat deviance near the boundary: the optimum is theta = 0
        auto x0 = fit.opt.x;
        x0[0] = 0.0;
        const double f0 = f(x0);
        if (f0 <= fit.opt.value + 1e-9) fit.opt.x = x0, fit.opt.value = f0;
    }
    if (!fit.opt.converged) fit.warnings.push_back("convergence failure: " + fit.opt.message);
    if (!derivatives) return fit;
    VectorXd gradient;
    MatrixXd hessian;
    deriv12(f, fit.opt.x, fit.opt.value, gradient, hessian);
    const bool boundary = fit.opt.x[0] < 1e-4;
    checkConvergence(gradient, hessian, boundary, fit.warnings);
    MatrixXd inverse;
    const auto p = d.X.cols();
    if (invertPositiveDefinite(hessian, inverse)) {
        fit.vcov = 2.0 * inverse.bottomRightCorner(p, p); // lme4's calc.vcov.hess
    } else {
        fit.warnings.emplace_back(
            "variance-covariance matrix computed from finite-difference Hessian is\nnot "
            "positive definite or contains NA values: falling back to var-cov estimated from RX");
        fit.vcov = deviance.rxVcov(fit.opt.x);
    }
    fit.vcovOk = fit.vcov.allFinite();
    return fit;
}

} // namespace

namespace {

/// Records the design's size in `r`; false (with R's message in r.error) when R would stop.
bool describeDesign(const Design& d, MixedModelResult& r) {
    r.nObs = dbl(d.y.size());
    r.nGroups = d.nGroups;
    r.error = d.error;
    return d.error.empty();
}

} // namespace

const FixedEffect* MixedModelResult::coefficient(const std::string& name) const {
    for (const auto& f : fixed)
        if (f.name == name) return &f;
    return nullptr;
}

void gaussHermiteRule(int points, std::vector<double>& nodes, std::vector<double>& weights) {
    // Golub-Welsch: eigenvalues of the Jacobi matrix of the probabilists' Hermite polynomials.
    nodes.assign(static_cast<std::size_t>(points), 0.0);
    weights.assign(static_cast<std::size_t>(points), 1.0);
    if (points <= 1) return;
    MatrixXd j = MatrixXd::Zero(points, points);
    for (int k = 1; k < points; ++k) j(k - 1, k) = j(k, k - 1) = std::sqrt(static_cast<double>(k));
    Eigen::SelfAdjointEigenSolver<MatrixXd> eig(j);
    for (int k = 0; k < points; ++k) {
        nodes[static_cast<std::size_t>(k)] = eig.eigenvalues()(k);
        const double v = eig.eigenvectors()(0, k);
        weights[static_cast<std::size_t>(k)] = v * v;
    }
    if (points % 2 == 1) nodes[static_cast<std::size_t>(points / 2)] = 0.0;
}

MixedModelResult fitLogisticMixedModel(const MixedModelData& data, int nAGQ, bool standardErrors) {
    MixedModelResult r;
    r.nAGQ = nAGQ;
    r.statisticName = "z";
    r.formula = std::string("y ~ condition") + (data.surface.empty() ? "" : " + surface") +
                " + (1 | participant)";
    r.method = nAGQ == 1 ? "Generalized linear mixed model fit by maximum likelihood (Laplace "
                           "Approximation) [glmerMod], family: binomial (logit)"
                         : fmt::format("Generalized linear mixed model fit by maximum likelihood "
                                       "(Adaptive Gauss-Hermite Quadrature, nAGQ = {}) [glmerMod], "
                                       "family: binomial (logit)",
                                       nAGQ);
    if (nAGQ < 1 || nAGQ > 25) {
        r.error = "nAGQ must be between 1 and 25";
        return r;
    }
    Design d = buildDesign(data, true);
    if (!describeDesign(d, r)) return r;
    for (Eigen::Index i = 0; i < d.y.size(); ++i)
        if (d.y(i) != 0.0 && d.y(i) != 1.0) {
            r.error = fmt::format("y[{}] = {}: the logistic model needs 0 (not correct) or 1 "
                                  "(correct)",
                                  i, d.y(i));
            return r;
        }
    if (d.y.minCoeff() == d.y.maxCoeff()) {
        r.error = fmt::format("Response is constant (every answer is {})", d.y(0));
        return r;
    }
    r.warnings = d.warnings;
    separationWarnings(d, r.warnings);
    LogisticFit fit = fitLogistic(d, nAGQ, standardErrors);
    const double theta = fit.opt.x[0];
    r.randomVariance = theta * theta;
    r.deviance = fit.opt.value;
    r.logLik = -0.5 * fit.opt.value;
    r.aic = fit.opt.value + 2.0 * dbl(d.X.cols() + 1);
    for (Eigen::Index j = 0; j < d.X.cols(); ++j) {
        FixedEffect e;
        e.name = d.names[static_cast<std::size_t>(j)];
        e.estimate = fit.opt.x[static_cast<std::size_t>(j) + 1];
        if (fit.vcovOk && fit.vcov(j, j) > 0) {
            e.se = std::sqrt(fit.vcov(j, j));
            e.statistic = e.estimate / e.se;
            e.p = 2.0 * numerics::pnorm(-std::fabs(e.statistic));
        }
        r.fixed.push_back(e);
    }
    if (theta < 1e-4) r.warnings.emplace_back("boundary (singular) fit: see help('isSingular')");
    for (auto& w : fit.warnings) r.warnings.push_back(std::move(w));
    if (d.conditionColumns > 0) {
        Design reduced = buildDesign(data, false);
        if (reduced.error.empty()) {
            const LogisticFit fit0 = fitLogistic(reduced, nAGQ, false);
            r.lrt.statistic = std::max(0.0, fit0.opt.value - fit.opt.value);
            r.lrt.df = d.conditionColumns;
            r.lrt.p = numerics::pchisq(r.lrt.statistic, r.lrt.df, false);
        }
    }
    return r;
}

// ------------------------------------------------------------------------------ linear

namespace {

/// Profiled (RE)ML deviance of y = X beta + b[participant] + e with b ~ N(0, theta^2 sigma^2),
/// e ~ N(0, sigma^2), through per-participant sums (V = I + theta^2 Z Z', Woodbury).
// Source: Bates, Maechler, Bolker & Walker (2015), lme4, J. Stat. Softw. 67(1), eqs. 34, 41.
class LinearProfile {
  public:
    explicit LinearProfile(const Design& d) : d_(d) {
        const auto p = d.X.cols();
        xtx_ = d.X.transpose() * d.X;
        xty_ = d.X.transpose() * d.y;
        yty_ = d.y.squaredNorm();
        for (const auto& members : d.members) {
            VectorXd s = VectorXd::Zero(p);
            double t = 0;
            for (int i : members) s += d.X.row(i).transpose(), t += d.y(i);
            sums_.push_back(s);
            ysums_.push_back(t);
            sizes_.push_back(dbl(members.size()));
        }
    }

    struct Eval {
        double ldL2 = 0, ldRX2 = 0, pwrss = 0;
        MatrixXd xvx; ///< X' V^-1 X
        VectorXd beta;
        bool ok = true;
    };

    Eval evaluate(double theta) const {
        Eval e;
        const double t2 = theta * theta;
        e.xvx = xtx_;
        VectorXd xvy = xty_;
        double yvy = yty_;
        for (std::size_t g = 0; g < sums_.size(); ++g) {
            const double c = t2 / (1.0 + sizes_[g] * t2);
            e.xvx.noalias() -= c * sums_[g] * sums_[g].transpose();
            xvy -= c * ysums_[g] * sums_[g];
            yvy -= c * ysums_[g] * ysums_[g];
            e.ldL2 += std::log1p(sizes_[g] * t2);
        }
        Eigen::LLT<MatrixXd> llt(e.xvx);
        if (llt.info() != Eigen::Success) {
            e.ok = false;
            return e;
        }
        e.beta = llt.solve(xvy);
        e.pwrss = std::max(yvy - e.beta.dot(xvy), 0.0);
        e.ldRX2 = 0;
        const MatrixXd l = llt.matrixL();
        for (Eigen::Index i = 0; i < l.rows(); ++i) e.ldRX2 += 2.0 * std::log(l(i, i));
        return e;
    }

    double n() const { return dbl(d_.y.size()); }
    double p() const { return dbl(d_.X.cols()); }

    /// Profiled deviance (REML criterion when reml).
    double deviance(double theta, bool reml) const {
        const Eval e = evaluate(theta);
        if (!e.ok) return numerics::kInf;
        const double dof = reml ? n() - p() : n();
        const double twoPi = 2.0 * std::numbers::pi;
        return e.ldL2 + (reml ? e.ldRX2 : 0.0) + dof * (1.0 + std::log(twoPi * e.pwrss / dof));
    }

    /// REML deviance with sigma not profiled (lmerTest's devfun_vp).
    double devianceVp(double theta, double sigma) const {
        const Eval e = evaluate(theta);
        const double s2 = sigma * sigma;
        return e.ldL2 + e.ldRX2 + (n() - p()) * std::log(2.0 * std::numbers::pi * s2) +
               e.pwrss / s2;
    }

  private:
    const Design& d_;
    MatrixXd xtx_;
    VectorXd xty_;
    double yty_ = 0;
    std::vector<VectorXd> sums_;
    std::vector<double> ysums_, sizes_;
};

/// Minimises the profiled deviance over theta >= 0: a log-spaced scan, then Brent's method
/// (Boost.Math) in the best bracket.
double optimiseTheta(const LinearProfile& profile, bool reml) {
    std::vector<double> grid{0.0};
    for (double t = 1e-3; t < 2e3; t *= 1.25) grid.push_back(t);
    std::size_t best = 0;
    double bestValue = numerics::kInf;
    for (std::size_t i = 0; i < grid.size(); ++i) {
        const double v = profile.deviance(grid[i], reml);
        if (v < bestValue) bestValue = v, best = i;
    }
    const double lo = best == 0 ? 0.0 : grid[best - 1];
    const double hi = best + 1 < grid.size() ? grid[best + 1] : grid[best] * 2;
    boost::uintmax_t iterations = 500;
    const auto [theta, value] = boost::math::tools::brent_find_minima(
        [&](double t) { return profile.deviance(t, reml); }, lo, hi, 50, iterations);
    if (best == 0 && profile.deviance(0.0, reml) <= value) return 0.0;
    return theta;
}

/// Second derivative data of a smooth function of two variables by central differences with
/// one Richardson extrapolation step (accurate to about 1e-9 relative here).
double richardson(const std::function<double(double)>& f, double h) {
    const double d1 = (f(h) - f(-h)) / (2 * h);
    const double d2 = (f(h / 2) - f(-h / 2)) / h;
    return (4 * d2 - d1) / 3;
}

} // namespace

MixedModelResult fitLinearMixedModel(const MixedModelData& data) {
    MixedModelResult r;
    r.statisticName = "t";
    r.formula = std::string("y ~ condition") + (data.surface.empty() ? "" : " + surface") +
                " + (1 | participant)";
    r.method = "Linear mixed model fit by REML. t-tests use Satterthwaite's method "
               "[lmerModLmerTest]";
    Design d = buildDesign(data, true);
    if (!describeDesign(d, r)) return r;
    if (d.nGroups >= d.y.size()) {
        r.error = "number of levels of each grouping factor must be < number of observations "
                  "(problems: participant)";
        return r;
    }
    if (d.y.minCoeff() == d.y.maxCoeff()) {
        r.error = "the response is constant: no variance to estimate (R's lmer stops with \"not "
                  "a positive definite matrix\")";
        return r;
    }
    r.warnings = d.warnings;
    const LinearProfile profile(d);
    const double theta = optimiseTheta(profile, true);
    const auto e = profile.evaluate(theta);
    const double n = profile.n(), p = profile.p();
    const double sigma2 = e.pwrss / (n - p);
    const double sigma = std::sqrt(sigma2);
    r.residualVariance = sigma2;
    r.randomVariance = theta * theta * sigma2;
    r.deviance = profile.deviance(theta, true);
    r.logLik = -0.5 * r.deviance;
    r.aic = r.deviance + 2.0 * (p + 2.0);
    const MatrixXd unscaled = e.xvx.inverse();
    // Satterthwaite df as lmerTest (Kuznetsova, Brockhoff & Christensen 2017, J. Stat. Softw.
    // 82(13); Satterthwaite 1946): df = 2 (L'CL)^2 / (g' A g), A = 2 H^-1 of the REML deviance
    // in (theta, sigma), g = gradient of L'CL in (theta, sigma).
    const double hT = 1e-4 * std::max(theta, 1e-2), hS = 1e-4 * sigma;
    auto dev = [&](double t, double s) { return profile.devianceVp(t, s); };
    MatrixXd h(2, 2);
    h(0, 0) = richardson(
        [&](double a) {
            return (dev(theta + a + hT, sigma) - dev(theta + a - hT, sigma)) / (2 * hT);
        },
        hT);
    h(1, 1) = richardson(
        [&](double a) {
            return (dev(theta, sigma + a + hS) - dev(theta, sigma + a - hS)) / (2 * hS);
        },
        hS);
    h(0, 1) = h(1, 0) = richardson(
        [&](double a) {
            return (dev(theta + a, sigma + hS) - dev(theta + a, sigma - hS)) / (2 * hS);
        },
        hT);
    // pseudo-inverse as lmerTest (eigenvalues below tolerance dropped)
    Eigen::SelfAdjointEigenSolver<MatrixXd> eig(h);
    MatrixXd a = MatrixXd::Zero(2, 2);
    const double tol = 1e-8 * std::max(1.0, eig.eigenvalues().cwiseAbs().maxCoeff());
    int negative = 0;
    for (int k = 0; k < 2; ++k) {
        const double ev = eig.eigenvalues()(k);
        if (ev < -tol) ++negative;
        if (ev > tol) a += eig.eigenvectors().col(k) * eig.eigenvectors().col(k).transpose() / ev;
    }
    a *= 2.0;
    if (negative > 0)
        r.warnings.push_back(fmt::format(
            "Model failed to converge with {} negative eigenvalue{}: Satterthwaite df are "
            "unreliable",
            negative, negative == 1 ? "" : "s"));
    for (Eigen::Index j = 0; j < d.X.cols(); ++j) {
        FixedEffect f;
        f.name = d.names[static_cast<std::size_t>(j)];
        f.estimate = e.beta(j);
        const double var = sigma2 * unscaled(j, j);
        f.se = std::sqrt(var);
        f.statistic = f.estimate / f.se;
        auto cjj = [&](double t) { return profile.evaluate(t).xvx.inverse()(j, j); };
        VectorXd g(2);
        g(0) = sigma2 * richardson([&](double a2) { return cjj(theta + a2); }, hT);
        g(1) = 2.0 * sigma * unscaled(j, j);
        const double denom = g.dot(a * g);
        f.df = 2.0 * var * var / denom;
        f.p = 2.0 * numerics::pt(-std::fabs(f.statistic), f.df);
        r.fixed.push_back(f);
    }
    if (theta < 1e-4) r.warnings.emplace_back("boundary (singular) fit: see help('isSingular')");
    if (d.conditionColumns > 0) { // anova(): both refitted by ML
        Design reduced = buildDesign(data, false);
        if (reduced.error.empty()) {
            const LinearProfile profile0(reduced);
            const double dev1 = profile.deviance(optimiseTheta(profile, false), false);
            const double dev0 = profile0.deviance(optimiseTheta(profile0, false), false);
            r.lrt.statistic = std::max(0.0, dev0 - dev1);
            r.lrt.df = d.conditionColumns;
            r.lrt.p = numerics::pchisq(r.lrt.statistic, r.lrt.df, false);
        }
    }
    return r;
}

} // namespace underfoot::analysis
