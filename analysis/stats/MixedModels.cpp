// SPDX-License-Identifier: GPL-3.0-or-later
// Mixed-effects models with one random intercept per participant (see MixedModels.h).
#include "analysis/stats/MixedModels.h"

#include "analysis/stats/MixedDesign.h"

#include "analysis/stats/Numerics.h"

#include <Eigen/Dense>
#include <fmt/format.h>
#include <nlopt.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string_view>

namespace underfoot::analysis {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using numerics::dbl;
using numerics::kNaN;
using namespace mixed;

// ------------------------------------------------------------------------------ logistic

/// Deviance (-2 log-likelihood) of the logistic model with a random intercept b = theta * u,
/// u ~ N(0, 1), integrated per participant by the Laplace approximation (nAGQ = 1) or adaptive
/// Gauss-Hermite quadrature centred at the conditional mode (nAGQ > 1).
// Source: Bates, Maechler, Bolker & Walker (2015), lme4, J. Stat. Softw. 67(1) (Laplace,
// PIRLS); Pinheiro & Bates (1995), J. Comput. Graph. Stat. 4(1) (adaptive Gauss-Hermite).
class LogisticDeviance {
  public:
    /// The cells of a design: observations of one participant with the same fixed-effects row
    /// are summed as binomial counts (the same likelihood, far fewer terms).
    LogisticDeviance(const Design& design, int nAGQ) : LogisticDeviance(nAGQ) {
        cells_.resize(design.members.size());
        std::vector<int> patternOf(static_cast<std::size_t>(design.y.size()), -1);
        std::vector<int> firstRow; // one observation per distinct row
        for (Eigen::Index i = 0; i < design.X.rows(); ++i) {
            std::size_t k = 0;
            while (k < firstRow.size() && design.X.row(firstRow[k]) != design.X.row(i)) ++k;
            if (k == firstRow.size()) firstRow.push_back(static_cast<int>(i));
            patternOf[static_cast<std::size_t>(i)] = static_cast<int>(k);
        }
        patterns_.resize(static_cast<Eigen::Index>(firstRow.size()), design.X.cols());
        for (std::size_t k = 0; k < firstRow.size(); ++k)
            patterns_.row(static_cast<Eigen::Index>(k)) = design.X.row(firstRow[k]);
        for (std::size_t g = 0; g < design.members.size(); ++g)
            for (int i : design.members[g])
                addCell(g, patternOf[static_cast<std::size_t>(i)], 1.0, design.y(i));
        u_.assign(cells_.size(), 0.0);
    }

    /// Cells given directly: `patterns` holds the distinct fixed-effects rows, `cells[g]` the
    /// (pattern, trials, successes) of participant g.
    LogisticDeviance(MatrixXd patterns, std::vector<std::vector<std::array<double, 3>>> cells,
                     int nAGQ)
        : LogisticDeviance(nAGQ) {
        patterns_ = std::move(patterns);
        cells_.resize(cells.size());
        for (std::size_t g = 0; g < cells.size(); ++g)
            for (const auto& c : cells[g]) addCell(g, static_cast<int>(c[0]), c[1], c[2]);
        u_.assign(cells_.size(), 0.0);
    }

    [[nodiscard]] Eigen::Index columns() const { return patterns_.cols(); }
    [[nodiscard]] bool laplace() const { return nodes_.empty(); }

    /// Logistic regression without random effect (R's glm IRLS on the counts per distinct
    /// row), the starting point of the fit.
    [[nodiscard]] VectorXd glmStart() const {
        const auto k = patterns_.rows(), p = patterns_.cols();
        VectorXd n = VectorXd::Zero(k), succ = VectorXd::Zero(k);
        for (const auto& cells : cells_)
            for (const Cell& c : cells) n(c.row) += c.n, succ(c.row) += c.successes;
        VectorXd beta = VectorXd::Zero(p);
        for (int it = 0; it < 25; ++it) {
            const VectorXd eta = patterns_ * beta;
            VectorXd w(k), z(k);
            for (Eigen::Index i = 0; i < k; ++i) {
                const double mu = 1.0 / (1.0 + std::exp(-eta(i)));
                const double v = std::max(mu * (1 - mu), 1e-10);
                w(i) = n(i) * v;
                z(i) = n(i) > 0 ? eta(i) + (succ(i) / n(i) - mu) / v : 0.0;
            }
            const MatrixXd xtw = patterns_.transpose() * w.asDiagonal();
            const VectorXd next = (xtw * patterns_).ldlt().solve(xtw * z);
            if (!next.allFinite()) break;
            const double change = (next - beta).norm();
            beta = next;
            if (change < 1e-10 * (1 + beta.norm())) break;
        }
        for (Eigen::Index j = 0; j < p; ++j) beta(j) = std::clamp(beta(j), -20.0, 20.0);
        return beta;
    }

    double operator()(const std::vector<double>& par) {
        const double theta = par[0];
        VectorXd beta(patterns_.cols());
        for (Eigen::Index j = 0; j < beta.size(); ++j)
            beta(j) = par[static_cast<std::size_t>(j) + 1];
        const VectorXd offset = patterns_ * beta;
        double dev = 0;
        for (std::size_t g = 0; g < cells_.size(); ++g) dev += groupDeviance(g, theta, offset);
        return dev;
    }

    /// Laplace deviance (nAGQ = 1) and its analytic gradient in (theta, beta): per participant
    /// D = 2 g(u^) + log g''(u^) with g'(u^) = 0, differentiated through u^ by the implicit
    /// function theorem (du^/dpsi = -g_upsi / g_uu). Used by the power simulations' optimiser.
    double laplaceGradient(const std::vector<double>& par, std::vector<double>& grad) {
        const double theta = par[0];
        const auto p = patterns_.cols();
        beta_.resize(p);
        for (Eigen::Index j = 0; j < p; ++j) beta_(j) = par[static_cast<std::size_t>(j) + 1];
        offset_.noalias() = patterns_ * beta_;
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
                const auto x = patterns_.row(c.row);
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
        const auto p = patterns_.cols();
        VectorXd beta(p);
        for (Eigen::Index j = 0; j < p; ++j) beta(j) = par[static_cast<std::size_t>(j) + 1];
        const VectorXd offset = patterns_ * beta;
        MatrixXd info = MatrixXd::Zero(p, p);
        for (std::size_t g = 0; g < cells_.size(); ++g) {
            VectorXd s = VectorXd::Zero(p);
            double wsum = 0;
            for (const Cell& c : cells_[g]) {
                const double mu = 1.0 / (1.0 + std::exp(-(offset(c.row) + theta * u_[g])));
                const double w = c.n * mu * (1 - mu);
                const VectorXd x = patterns_.row(c.row).transpose();
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
        int row = 0; ///< the index of its distinct fixed-effects row
        double n = 0, successes = 0;
    };

    explicit LogisticDeviance(int nAGQ) {
        if (nAGQ > 1) gaussHermiteRule(nAGQ, nodes_, weights_);
        for (double w : weights_) logWeights_.push_back(std::log(w));
    }

    void addCell(std::size_t g, int pattern, double n, double successes) {
        auto& cells = cells_[g];
        std::size_t c = 0;
        while (c < cells.size() && cells[c].row != pattern) ++c;
        if (c == cells.size()) cells.push_back({pattern, 0.0, 0.0});
        cells[c].n += n;
        cells[c].successes += successes;
    }

    MatrixXd patterns_; ///< distinct rows of the fixed-effects design
    std::vector<double> u_;
    std::vector<double> nodes_, weights_, logWeights_;
    std::vector<double> terms_;                ///< scratch of the quadrature sum
    VectorXd beta_, offset_, gBeta_, wx_, tx_; ///< scratch of laplaceGradient
    std::vector<std::vector<Cell>> cells_;
};

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

LogisticFit fitLogistic(LogisticDeviance& deviance, bool derivatives) {
    LogisticFit fit;
    const VectorXd start = deviance.glmStart();
    std::vector<double> x{1.0};
    for (Eigen::Index j = 0; j < start.size(); ++j) x.push_back(start(j));
    std::vector<double> lower(x.size(), -numerics::kInf);
    lower[0] = 0.0;
    std::function<double(const std::vector<double>&)> f = [&](const std::vector<double>& v) {
        return deviance(v);
    };
    fit.opt = !derivatives && deviance.laplace() ? minimiseLaplace(deviance, x)
                                                 : minimise(f, x, lower, 0.2);
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
    const auto p = deviance.columns();
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
    LogisticDeviance deviance(d, nAGQ);
    LogisticFit fit = fitLogistic(deviance, standardErrors);
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
            LogisticDeviance deviance0(reduced, nAGQ);
            const LogisticFit fit0 = fitLogistic(deviance0, false);
            r.lrt.statistic = std::max(0.0, fit0.opt.value - fit.opt.value);
            r.lrt.df = d.conditionColumns;
            r.lrt.p = numerics::pchisq(r.lrt.statistic, r.lrt.df, false);
        }
    }
    return r;
}

namespace {

/// The distinct fixed-effects rows of `~ condition (+ surface)` (treatment contrasts, columns
/// in the span of earlier ones dropped as buildDesign does) over the (condition, surface) pairs
/// present, and the cells per participant on them.
struct CellDesign {
    MatrixXd patterns;
    std::vector<std::vector<std::array<double, 3>>> cells; ///< per participant
    int conditionColumns = 0;
};

CellDesign cellDesign(const std::vector<BinomialCell>& cells, bool withCondition,
                      const std::vector<int>& conditions, const std::vector<int>& surfaces,
                      int participants) {
    CellDesign d;
    std::vector<std::pair<int, int>> keys; // (condition, surface) of each distinct row
    std::vector<int> patternOf;
    for (const auto& c : cells) {
        const std::pair<int, int> key{withCondition ? c.condition : 0, c.surface};
        auto it = std::find(keys.begin(), keys.end(), key);
        patternOf.push_back(static_cast<int>(it - keys.begin()));
        if (it == keys.end()) keys.push_back(key);
    }
    std::vector<VectorXd> columns;
    std::vector<bool> isCondition;
    const auto k = static_cast<Eigen::Index>(keys.size());
    columns.emplace_back(VectorXd::Ones(k));
    isCondition.push_back(false);
    auto addFactor = [&](const std::vector<int>& levels, bool condition) {
        for (std::size_t l = 1; l < levels.size(); ++l) {
            VectorXd col = VectorXd::Zero(k);
            for (Eigen::Index i = 0; i < k; ++i) {
                const auto& key = keys[static_cast<std::size_t>(i)];
                col(i) = (condition ? key.first : key.second) == levels[l] ? 1.0 : 0.0;
            }
            columns.push_back(col);
            isCondition.push_back(condition);
        }
    };
    if (withCondition) addFactor(conditions, true);
    addFactor(surfaces, false);
    std::vector<VectorXd> basis, kept;
    for (std::size_t c = 0; c < columns.size(); ++c) {
        VectorXd r = columns[c];
        const double norm0 = r.norm();
        for (int pass = 0; pass < 2; ++pass)
            for (const auto& q : basis) r -= q * q.dot(r);
        if (norm0 > 0 && r.norm() > 1e-7 * norm0) {
            basis.push_back(r / r.norm());
            kept.push_back(columns[c]);
            if (isCondition[c]) ++d.conditionColumns;
        }
    }
    d.patterns.resize(k, static_cast<Eigen::Index>(kept.size()));
    for (std::size_t c = 0; c < kept.size(); ++c)
        d.patterns.col(static_cast<Eigen::Index>(c)) = kept[c];
    d.cells.resize(static_cast<std::size_t>(participants));
    for (std::size_t i = 0; i < cells.size(); ++i)
        d.cells[static_cast<std::size_t>(cells[i].participant)].push_back(
            {static_cast<double>(patternOf[i]), cells[i].trials, cells[i].successes});
    return d;
}

} // namespace

LogisticLrt logisticLikelihoodRatio(const std::vector<BinomialCell>& cells, int nAGQ) {
    LogisticLrt out;
    if (nAGQ < 1 || nAGQ > 25) {
        out.error = "nAGQ must be between 1 and 25";
        return out;
    }
    std::vector<int> conditions, surfaces, people;
    double trials = 0, successes = 0;
    for (const auto& c : cells) {
        if (c.participant < 0 || c.condition < 0 || !(c.trials >= 0) ||
            !(c.successes >= 0 && c.successes <= c.trials)) {
            out.error = "a cell has a negative code or successes outside 0..trials";
            return out;
        }
        if (c.trials == 0) continue;
        conditions.push_back(c.condition);
        surfaces.push_back(c.surface);
        people.push_back(c.participant);
        trials += c.trials;
        successes += c.successes;
    }
    auto unique = [](std::vector<int>& v) {
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
    };
    unique(conditions), unique(surfaces), unique(people);
    if (conditions.size() < 2) {
        out.error = "contrasts can be applied only to factors with 2 or more levels (condition "
                    "has one level)";
        return out;
    }
    if (people.size() < 2) {
        out.error = "grouping factors must have > 1 sampled level (participant has one level)";
        return out;
    }
    if (successes == 0 || successes == trials) {
        out.error = "Response is constant";
        return out;
    }
    // participants renumbered 0..n-1 in code order (empty cells left out)
    std::vector<BinomialCell> used;
    for (const auto& c : cells)
        if (c.trials > 0) {
            BinomialCell u = c;
            u.participant = static_cast<int>(
                std::lower_bound(people.begin(), people.end(), c.participant) - people.begin());
            used.push_back(u);
        }
    const int n = static_cast<int>(people.size());
    auto fit = [&](bool withCondition, int& conditionColumns) {
        CellDesign d = cellDesign(used, withCondition, conditions, surfaces, n);
        conditionColumns = d.conditionColumns;
        LogisticDeviance deviance(std::move(d.patterns), std::move(d.cells), nAGQ);
        return fitLogistic(deviance, false).opt;
    };
    int columns = 0, unused = 0;
    const Optimum full = fit(true, columns);
    const Optimum reduced = fit(false, unused);
    out.randomVariance = full.x[0] * full.x[0];
    if (columns == 0) {
        out.error = "the condition is aliased with the surfaces (no condition column is estimable)";
        return out;
    }
    out.statistic = std::max(0.0, reduced.value - full.value);
    out.df = columns;
    out.p = numerics::pchisq(out.statistic, out.df, false);
    return out;
}

} // namespace underfoot::analysis
