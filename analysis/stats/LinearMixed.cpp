// SPDX-License-Identifier: GPL-3.0-or-later
// The linear mixed model by REML with Satterthwaite df, as lmerTest::lmer (see MixedModels.h).
#include "analysis/stats/MixedDesign.h"
#include "analysis/stats/MixedModels.h"
#include "analysis/stats/Numerics.h"

#include <boost/math/tools/minima.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

namespace underfoot::analysis {

namespace {
namespace lmm {

using namespace mixed;
using numerics::dbl;

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

} // namespace lmm
} // namespace

MixedModelResult fitLinearMixedModel(const MixedModelData& data) {
    using namespace lmm;
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
