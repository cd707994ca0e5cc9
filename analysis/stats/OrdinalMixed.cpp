// SPDX-License-Identifier: GPL-3.0-or-later
// Cumulative link mixed model (see OrdinalMixed.h).
#include "analysis/stats/OrdinalMixed.h"

#include "analysis/stats/MixedDesign.h"
#include "analysis/stats/Numerics.h"

#include <boost/math/distributions/normal.hpp>
#include <fmt/format.h>
#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace underfoot::analysis {

namespace {
namespace clmm {

using mixed::Design;
using mixed::MatrixXd;
using mixed::VectorXd;
using numerics::dbl;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The link's distribution: F, 1 - F, the density f and its first two derivatives.
struct Link {
    OrdinalLink kind = OrdinalLink::Logit;

    [[nodiscard]] double cdf(double x) const {
        switch (kind) {
        case OrdinalLink::Logit:
            return x >= 0 ? 1.0 / (1.0 + std::exp(-x)) : std::exp(x) / (1.0 + std::exp(x));
        case OrdinalLink::Probit:
            return 0.5 * std::erfc(-x / std::numbers::sqrt2);
        case OrdinalLink::Cloglog:
            return -std::expm1(-std::exp(x));
        }
        return 0;
    }
    [[nodiscard]] double sf(double x) const {
        switch (kind) {
        case OrdinalLink::Logit:
            return cdf(-x);
        case OrdinalLink::Probit:
            return 0.5 * std::erfc(x / std::numbers::sqrt2);
        case OrdinalLink::Cloglog:
            return std::exp(-std::exp(x));
        }
        return 0;
    }
    /// f, f' and f'' at x.
    void density(double x, double& f, double& f1, double& f2) const {
        switch (kind) {
        case OrdinalLink::Logit: {
            const double e = std::exp(-std::fabs(x));
            f = e / ((1.0 + e) * (1.0 + e));
            const double F = cdf(x);
            f1 = f * (1.0 - 2.0 * F);
            f2 = f * (1.0 - 6.0 * f);
            return;
        }
        case OrdinalLink::Probit: {
            f = std::exp(-0.5 * x * x) / std::sqrt(2.0 * std::numbers::pi);
            f1 = -x * f;
            f2 = (x * x - 1.0) * f;
            return;
        }
        case OrdinalLink::Cloglog: {
            const double ex = std::exp(x);
            f = std::exp(x - ex);
            if (f == 0.0) {
                f1 = f2 = 0.0;
                return;
            }
            f1 = f * (1.0 - ex);
            f2 = f * ((1.0 - ex) * (1.0 - ex) - ex);
            return;
        }
        }
    }
    [[nodiscard]] double quantile(double p) const {
        switch (kind) {
        case OrdinalLink::Logit:
            return std::log(p / (1.0 - p));
        case OrdinalLink::Probit:
            return boost::math::quantile(boost::math::normal(), p);
        case OrdinalLink::Cloglog:
            return std::log(-std::log1p(-p));
        }
        return 0;
    }
};

/// Answers of one participant with the same fixed-effects row and category, counted.
struct Cell {
    int row = 0; ///< an observation with this row of X
    int k = 0;   ///< category index 0..J-1
    double n = 0;
};

/// log p of one cell and its derivatives in s = x'beta + sigma u and in the cell's upper (a)
/// and lower (c) thresholds: p = F(a - s) - F(c - s).
struct Terms {
    double l = 0, ls = 0, lss = 0, lsss = 0;
    double la = 0, lsa = 0, lssa = 0; ///< d/da of l, ls, lss
    double lc = 0, lsc = 0, lssc = 0; ///< d/dc of l, ls, lss
};

/// Negative log-likelihood of the clmm in psi = (thresholds, beta, sigma), integrated per
/// participant by the Laplace approximation or adaptive Gauss-Hermite quadrature.
class Likelihood {
  public:
    Likelihood(const Design& d, MatrixXd X, const std::vector<int>& category, int J, Link link,
               int nAGQ)
        : X_(std::move(X)), J_(J), link_(link), u_(static_cast<std::size_t>(d.nGroups), 0.0) {
        if (nAGQ > 1) gaussHermiteRule(nAGQ, nodes_, weights_);
        for (double w : weights_) logWeights_.push_back(std::log(w));
        cells_.resize(d.members.size());
        for (std::size_t g = 0; g < d.members.size(); ++g)
            for (int i : d.members[g]) {
                auto& cells = cells_[g];
                const int k = category[static_cast<std::size_t>(i)];
                std::size_t c = 0;
                while (c < cells.size() && (cells[c].k != k || !sameRow(cells[c].row, i))) ++c;
                if (c == cells.size()) cells.push_back({i, k, 0.0});
                cells[c].n += 1;
            }
    }

    [[nodiscard]] int thresholds() const { return J_ - 1; }
    [[nodiscard]] Eigen::Index fixed() const { return X_.cols(); }
    [[nodiscard]] std::size_t size() const {
        return static_cast<std::size_t>(J_ - 1 + X_.cols() + 1);
    }

    /// Negative log-likelihood (Laplace or quadrature); +Inf where undefined.
    double operator()(const std::vector<double>& psi) {
        if (!unpack(psi)) return kInf;
        double nll = 0;
        for (std::size_t g = 0; g < cells_.size(); ++g) {
            const double v = groupValue(g);
            if (!std::isfinite(v)) return kInf;
            nll += v;
        }
        return nll;
    }

    /// Laplace negative log-likelihood and its gradient in psi (the conditional mode's
    /// dependence on psi by the implicit function theorem).
    double gradient(const std::vector<double>& psi, std::vector<double>& grad) {
        grad.assign(psi.size(), 0.0);
        if (!unpack(psi)) return kInf;
        const auto p = X_.cols();
        const auto T = static_cast<std::size_t>(J_ - 1);
        const double s = sigma_;
        double nll = 0;
        for (std::size_t g = 0; g < cells_.size(); ++g) {
            const double u = mode(g);
            if (!std::isfinite(u)) return kInf;
            double value = 0.5 * u * u, S1 = 0, W = 0, Tt = 0;
            bs_.setZero(p), bw_.setZero(p), bt_.setZero(p);
            gt_.assign(T, 0.0), ut_.assign(T, 0.0), dt_.assign(T, 0.0);
            for (const Cell& c : cells_[g]) {
                Terms t;
                if (!terms(c, offset_(c.row) + s * u, 2, t)) return kInf;
                value -= c.n * t.l;
                S1 -= c.n * t.ls, W -= c.n * t.lss, Tt -= c.n * t.lsss;
                if (p > 0) { // (no block of a matrix without columns)
                    const auto x = X_.row(c.row);
                    bs_.noalias() -= c.n * t.ls * x.transpose();
                    bw_.noalias() -= c.n * t.lss * x.transpose();
                    bt_.noalias() -= c.n * t.lsss * x.transpose();
                }
                if (c.k < J_ - 1) {
                    const auto a = static_cast<std::size_t>(c.k);
                    gt_[a] -= c.n * t.la, ut_[a] -= c.n * t.lsa, dt_[a] -= c.n * t.lssa;
                }
                if (c.k > 0) {
                    const auto b = static_cast<std::size_t>(c.k - 1);
                    gt_[b] -= c.n * t.lc, ut_[b] -= c.n * t.lsc, dt_[b] -= c.n * t.lssc;
                }
            }
            const double D = s * s * W + 1.0;
            nll += value + 0.5 * std::log(D);
            const double dDdu = s * s * s * Tt, half = 0.5 / D;
            for (std::size_t t = 0; t < T; ++t)
                grad[t] += gt_[t] + half * (s * s * dt_[t] - dDdu * s * ut_[t] / D);
            for (Eigen::Index j = 0; j < p; ++j)
                grad[T + static_cast<std::size_t>(j)] +=
                    bs_(j) + half * (s * s * bt_(j) - dDdu * s * bw_(j) / D);
            grad[T + static_cast<std::size_t>(p)] +=
                u * S1 + half * (2.0 * s * W + s * s * u * Tt - dDdu * (S1 + s * u * W) / D);
        }
        return nll;
    }

  private:
    /// Whether observations a and b have the same fixed-effects row.
    [[nodiscard]] bool sameRow(Eigen::Index a, Eigen::Index b) const {
        for (Eigen::Index j = 0; j < X_.cols(); ++j)
            if (X_(a, j) != X_(b, j)) return false;
        return true;
    }

    /// Sets thresholds, offsets and sigma; false when the thresholds are not increasing.
    bool unpack(const std::vector<double>& psi) {
        const auto T = static_cast<std::size_t>(J_ - 1);
        theta_.assign(psi.begin(), psi.begin() + static_cast<std::ptrdiff_t>(T));
        for (std::size_t t = 1; t < T; ++t)
            if (!(theta_[t] > theta_[t - 1])) return false;
        beta_.resize(X_.cols());
        for (Eigen::Index j = 0; j < X_.cols(); ++j)
            beta_(j) = psi[T + static_cast<std::size_t>(j)];
        if (X_.cols() > 0)
            offset_.noalias() = X_ * beta_;
        else
            offset_.setZero(X_.rows());
        sigma_ = psi.back();
        for (double v : psi)
            if (!std::isfinite(v)) return false;
        return true;
    }

    /// Terms of cell c at s; `order` 0: l only, 1: up to lss, 2: everything. False if p <= 0.
    bool terms(const Cell& c, double s, int order, Terms& t) const {
        const bool up = c.k<J_ - 1, lo = c.k> 0;
        const double a = up ? theta_[static_cast<std::size_t>(c.k)] - s : kInf;
        const double b = lo ? theta_[static_cast<std::size_t>(c.k - 1)] - s : -kInf;
        double p = 0;
        if (!up)
            p = link_.sf(b);
        else if (!lo)
            p = link_.cdf(a);
        else
            p = b > 0 ? link_.sf(b) - link_.sf(a) : link_.cdf(a) - link_.cdf(b);
        if (!(p > 0)) return false;
        t.l = std::log(p);
        if (order == 0) return true;
        double fa = 0, fa1 = 0, fa2 = 0, fb = 0, fb1 = 0, fb2 = 0;
        if (up) link_.density(a, fa, fa1, fa2);
        if (lo) link_.density(b, fb, fb1, fb2);
        const double ps = -fa + fb, pss = fa1 - fb1;
        t.ls = ps / p;
        t.lss = pss / p - t.ls * t.ls;
        if (order == 1) return true;
        const double psss = -fa2 + fb2;
        t.lsss = psss / p - 3.0 * t.ls * pss / p + 2.0 * t.ls * t.ls * t.ls;
        auto threshold = [&](double pt, double pst, double psst, double& l, double& lst,
                             double& lsst) {
            l = pt / p;
            lst = pst / p - t.ls * l;
            lsst = psst / p - (pss / p) * l - 2.0 * t.ls * lst;
        };
        if (up) threshold(fa, -fa1, fa2, t.la, t.lsa, t.lssa);
        if (lo) threshold(-fb, fb1, -fb2, t.lc, t.lsc, t.lssc);
        return true;
    }

    /// g(u) = -log p(y | u) + u^2 / 2 of participant g; `d2` (optional) gets g''(u).
    double g(std::size_t grp, double u, double* d2 = nullptr) const {
        double v = 0.5 * u * u, w = 0;
        Terms t;
        for (const Cell& c : cells_[grp]) {
            if (!terms(c, offset_(c.row) + sigma_ * u, d2 ? 1 : 0, t)) return kInf;
            v -= c.n * t.l;
            w -= c.n * t.lss;
        }
        if (d2) *d2 = sigma_ * sigma_ * w + 1.0;
        return v;
    }

    /// Conditional mode of u (g is strictly convex for these links): safeguarded Newton.
    double mode(std::size_t grp) {
        if (sigma_ == 0.0) return u_[grp] = 0.0;
        double u = std::isfinite(u_[grp]) ? u_[grp] : 0.0;
        double lo = -kInf, hi = kInf, previous = kInf;
        Terms t;
        for (int it = 0; it < 200; ++it) {
            double s1 = 0, s2 = 0;
            bool ok = true;
            for (const Cell& c : cells_[grp]) {
                if (!terms(c, offset_(c.row) + sigma_ * u, 1, t)) {
                    ok = false;
                    break;
                }
                s1 -= c.n * t.ls, s2 -= c.n * t.lss;
            }
            if (!ok) { // outside the support: back towards the bracket
                u = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi) : 0.5 * u;
                continue;
            }
            const double d1 = sigma_ * s1 + u, d2 = sigma_ * sigma_ * s2 + 1.0;
            if (d1 == 0) break;
            (d1 > 0 ? hi : lo) = u;
            double next = u - d1 / d2;
            const bool bounded = std::isfinite(lo) && std::isfinite(hi);
            const bool newton = !bounded || (next > lo && next < hi &&
                                             std::fabs(next - u) <= 0.5 * std::fabs(previous));
            if (!newton) next = 0.5 * (lo + hi);
            previous = next - u;
            u = next;
            if (newton && std::fabs(previous) < 1e-11 * (1 + std::fabs(u))) break;
        }
        return u_[grp] = u;
    }

    double groupValue(std::size_t grp) {
        const double u = mode(grp);
        double D = 1;
        const double g0 = g(grp, u, &D);
        if (!std::isfinite(g0)) return kInf;
        if (nodes_.empty()) return g0 + 0.5 * std::log(D);
        const double sc = 1.0 / std::sqrt(D);
        terms_.resize(nodes_.size());
        double top = -kInf;
        for (std::size_t k = 0; k < nodes_.size(); ++k) {
            const double gk = g(grp, u + sc * nodes_[k]);
            terms_[k] = -gk + 0.5 * nodes_[k] * nodes_[k] + logWeights_[k];
            top = std::max(top, terms_[k]);
        }
        if (!std::isfinite(top)) return kInf;
        double sum = 0;
        for (double t : terms_) sum += std::exp(t - top);
        return -(std::log(sc) + top + std::log(sum));
    }

    MatrixXd X_;
    int J_ = 2;
    Link link_;
    std::vector<std::vector<Cell>> cells_;
    std::vector<double> u_, nodes_, weights_, logWeights_, terms_;
    std::vector<double> theta_, gt_, ut_, dt_;
    VectorXd beta_, offset_, bs_, bw_, bt_;
    double sigma_ = 0;
};

/// psi from the optimiser's x: thresholds theta_1 = x_1, theta_t = theta_{t-1} + exp(x_t)
/// (increasing by construction), beta and sigma as they are.
std::vector<double> toPsi(const std::vector<double>& x, int T) {
    std::vector<double> psi = x;
    for (int t = 1; t < T; ++t)
        psi[static_cast<std::size_t>(t)] =
            psi[static_cast<std::size_t>(t - 1)] + std::exp(x[static_cast<std::size_t>(t)]);
    return psi;
}

std::vector<double> toX(const std::vector<double>& psi, int T) {
    std::vector<double> x = psi;
    for (int t = 1; t < T; ++t)
        x[static_cast<std::size_t>(t)] = std::log(std::max(
            psi[static_cast<std::size_t>(t)] - psi[static_cast<std::size_t>(t - 1)], 1e-8));
    return x;
}

/// Minimises the Laplace likelihood with NLopt's L-BFGS and the analytic gradient. sigma is
/// left unbounded (the likelihood is even in it) and |sigma| returned.
mixed::Optimum minimiseLaplace(Likelihood& lik, const std::vector<double>& psi0) {
    const int T = lik.thresholds();
    struct Ctx {
        Likelihood* lik;
        int T;
        std::vector<double> gpsi;
    } ctx{&lik, T, {}};
    auto thunk = [](const std::vector<double>& x, std::vector<double>& grad, void* data) {
        auto* c = static_cast<Ctx*>(data);
        const auto psi = toPsi(x, c->T);
        const double v = c->lik->gradient(psi, c->gpsi);
        if (!grad.empty()) { // chain rule through the threshold increments
            grad = c->gpsi;
            double tail = 0;
            for (int t = c->T - 1; t >= 1; --t) {
                tail += c->gpsi[static_cast<std::size_t>(t)];
                grad[static_cast<std::size_t>(t)] = tail * std::exp(x[static_cast<std::size_t>(t)]);
            }
            if (c->T > 0) grad[0] = tail + c->gpsi[0];
        }
        return std::isfinite(v) ? v : 1e300;
    };
    mixed::Optimum out;
    std::vector<double> x = toX(psi0, T);
    nlopt::opt opt(nlopt::LD_LBFGS, static_cast<unsigned>(x.size()));
    opt.set_min_objective(thunk, &ctx);
    opt.set_ftol_rel(1e-15);
    opt.set_xtol_rel(1e-11);
    opt.set_maxeval(5000);
    double value = 0;
    try {
        if (opt.optimize(x, value) == nlopt::MAXEVAL_REACHED) {
            out.converged = false;
            out.message = "maximum number of function evaluations exceeded";
        }
    } catch (const nlopt::roundoff_limited&) { // converged as far as rounding allows
    } catch (const std::exception& e) {
        out.converged = false;
        out.message = e.what();
    }
    out.x = toPsi(x, T);
    out.x.back() = std::fabs(out.x.back());
    out.value = lik(out.x);
    return out;
}

/// The optimum: Laplace by L-BFGS; quadrature by BOBYQA from the Laplace optimum. sigma is set
/// to 0 where that is at least as good (a flat likelihood near the boundary).
mixed::Optimum optimise(const Design& d, const MatrixXd& X, const std::vector<int>& category, int J,
                        Link link, int nAGQ, const std::vector<double>& start) {
    Likelihood laplace(d, X, category, J, link, 1);
    mixed::Optimum best = minimiseLaplace(laplace, start);
    if (nAGQ > 1) {
        Likelihood agq(d, X, category, J, link, nAGQ);
        const int T = J - 1;
        std::function<double(const std::vector<double>&)> f = [&](const std::vector<double>& x) {
            return agq(toPsi(x, T));
        };
        const std::vector<double> lower(best.x.size(), -kInf);
        mixed::Optimum q = mixed::minimise(f, toX(best.x, T), lower, 0.1);
        q.x = toPsi(q.x, T);
        q.x.back() = std::fabs(q.x.back());
        q.value = agq(q.x);
        best = q;
    }
    if (best.x.back() > 0) {
        auto x0 = best.x;
        x0.back() = 0.0;
        Likelihood lik(d, X, category, J, link, nAGQ);
        const double f0 = lik(x0);
        if (f0 <= best.value + 1e-9) {
            // refit with sigma held at 0 (no random effect: every integral is exact)
            Likelihood fixed0(d, X, category, J, link, 1);
            std::function<double(const std::vector<double>&)> f =
                [&](const std::vector<double>& x) {
                    auto psi = toPsi(x, J - 1);
                    psi.push_back(0.0);
                    return fixed0(psi);
                };
            auto x = toX(x0, J - 1);
            x.pop_back();
            const std::vector<double> lower(x.size(), -kInf);
            const mixed::Optimum z = mixed::minimise(f, x, lower, 0.05);
            auto psi = toPsi(z.x, J - 1);
            psi.push_back(0.0);
            const double v = lik(psi);
            if (v <= f0)
                best.x = psi, best.value = v;
            else
                best.x = x0, best.value = f0;
        }
    }
    return best;
}

/// Starting values: thresholds from the cumulative proportions, beta 0, sigma 1.
std::vector<double> startValues(const std::vector<int>& category, int J, Eigen::Index p,
                                const Link& link) {
    std::vector<double> counts(static_cast<std::size_t>(J), 0.0);
    for (int k : category) counts[static_cast<std::size_t>(k)] += 1;
    std::vector<double> psi;
    double cum = 0, total = dbl(category.size());
    for (int t = 0; t < J - 1; ++t) {
        cum += counts[static_cast<std::size_t>(t)];
        psi.push_back(link.quantile(std::clamp(cum / total, 1e-3, 1 - 1e-3)));
    }
    for (std::size_t t = 1; t < psi.size(); ++t) psi[t] = std::max(psi[t], psi[t - 1] + 1e-3);
    for (Eigen::Index j = 0; j < p; ++j) psi.push_back(0.0);
    psi.push_back(1.0);
    return psi;
}

/// Condition or surface columns whose ratings are all in one extreme category or all above
/// (below) every other rating: the estimate diverges (separation).
void separationWarnings(const Design& d, const MatrixXd& X, const std::vector<int>& category, int J,
                        std::vector<std::string>& warnings) {
    std::vector<std::string> separated;
    for (Eigen::Index j = 0; j < X.cols(); ++j) {
        int inLo = J, inHi = -1, outLo = J, outHi = -1;
        for (Eigen::Index i = 0; i < X.rows(); ++i) {
            const int k = category[static_cast<std::size_t>(i)];
            if (X(i, j) != 0)
                inLo = std::min(inLo, k), inHi = std::max(inHi, k);
            else
                outLo = std::min(outLo, k), outHi = std::max(outHi, k);
        }
        if (inHi < 0 || outHi < 0) continue;
        if ((inLo == inHi && (inLo == 0 || inLo == J - 1)) || inLo > outHi || inHi < outLo)
            separated.push_back(d.names[static_cast<std::size_t>(j) + 1] + " = 1");
    }
    if (!separated.empty())
        warnings.push_back(fmt::format(
            "separation: the ratings where {} lie in an extreme category or beyond every other "
            "rating (the estimate diverges and its Wald test is meaningless; use the "
            "likelihood-ratio test)",
            fmt::join(separated, ", ")));
}

std::string categoryName(double c) {
    return fmt::format("{}", c);
}

} // namespace clmm
} // namespace

std::string toString(OrdinalLink link) {
    switch (link) {
    case OrdinalLink::Logit:
        return "logit";
    case OrdinalLink::Probit:
        return "probit";
    case OrdinalLink::Cloglog:
        return "cloglog";
    }
    return "logit";
}

bool parseOrdinalLink(const std::string& text, OrdinalLink& link) {
    if (text == "logit")
        link = OrdinalLink::Logit;
    else if (text == "probit")
        link = OrdinalLink::Probit;
    else if (text == "cloglog")
        link = OrdinalLink::Cloglog;
    else
        return false;
    return true;
}

OrdinalMixedResult fitOrdinalMixedModel(const MixedModelData& data, const OrdinalOptions& options) {
    using namespace clmm;
    OrdinalMixedResult r;
    r.nAGQ = options.nAGQ;
    r.statisticName = "z";
    r.link = toString(options.link);
    r.formula = std::string("y ~ condition") + (data.surface.empty() ? "" : " + surface") +
                " + (1 | participant)";
    r.method = options.nAGQ == 1
                   ? fmt::format("Cumulative Link Mixed Model fitted with the Laplace "
                                 "approximation, link: {}, threshold: flexible",
                                 r.link)
                   : fmt::format("Cumulative Link Mixed Model fitted with the adaptive "
                                 "Gauss-Hermite quadrature approximation with {} quadrature "
                                 "points, link: {}, threshold: flexible",
                                 options.nAGQ, r.link);
    if (options.nAGQ < 1 || options.nAGQ > 25) {
        r.error = "nAGQ must be between 1 and 25";
        return r;
    }
    const Design d = mixed::buildDesign(data, true);
    r.nObs = dbl(d.y.size());
    r.nGroups = d.nGroups;
    if (!d.error.empty()) {
        r.error = d.error;
        return r;
    }
    // categories: the declared ones (each rating must be one of them) or the values present
    std::vector<double> present(d.y.data(), d.y.data() + d.y.size());
    std::sort(present.begin(), present.end());
    present.erase(std::unique(present.begin(), present.end()), present.end());
    if (!options.categories.empty()) {
        std::vector<double> declared = options.categories;
        for (std::size_t i = 0; i < declared.size(); ++i) {
            if (!std::isfinite(declared[i])) {
                r.error = fmt::format("levels[{}] is not a finite number", i);
                return r;
            }
            if (i > 0 && !(declared[i] > declared[i - 1])) {
                r.error = "levels must be increasing (the order of the scale's categories)";
                return r;
            }
        }
        for (double v : present)
            if (!std::binary_search(declared.begin(), declared.end(), v)) {
                r.error = fmt::format("rating {} is not one of the levels ({})", v,
                                      fmt::join(declared, ", "));
                return r;
            }
        std::vector<std::string> unused;
        for (double c : declared)
            if (!std::binary_search(present.begin(), present.end(), c))
                unused.push_back(categoryName(c));
        if (!unused.empty())
            r.warnings.push_back(fmt::format(
                "response categor{} {} of {} never used: dropped, as clmm drops unused levels of "
                "the response (no threshold is estimated next to {})",
                unused.size() == 1 ? "y" : "ies", fmt::join(unused, ", "),
                fmt::join(declared, ", "), unused.size() == 1 ? "it" : "them"));
    }
    if (present.size() > kMaxOrdinalCategories ||
        options.categories.size() > kMaxOrdinalCategories) {
        r.error = fmt::format("more than {} response categories: a rating scale has fewer (use the "
                              "linear mixed model for a continuous response)",
                              kMaxOrdinalCategories);
        return r;
    }
    const int J = static_cast<int>(present.size());
    r.categories = present;
    if (J < 2) {
        r.error = fmt::format("the response has one category (every rating is {}): no thresholds "
                              "to estimate (R's clmm stops with \"length of start is {} should "
                              "equal 1\")",
                              present.empty() ? 0.0 : present[0], d.X.cols() + 1);
        return r;
    }
    std::vector<int> category;
    for (Eigen::Index i = 0; i < d.y.size(); ++i)
        category.push_back(static_cast<int>(
            std::lower_bound(present.begin(), present.end(), d.y(i)) - present.begin()));
    for (const auto& w : d.warnings) r.warnings.push_back(w);
    const MatrixXd X = d.X.rightCols(d.X.cols() - 1); // the thresholds replace the intercept
    const Link link{options.link};
    separationWarnings(d, X, category, J, r.warnings);
    const auto fit =
        optimise(d, X, category, J, link, options.nAGQ, startValues(category, J, X.cols(), link));
    if (!std::isfinite(fit.value)) {
        r.error = "the log-likelihood is not finite at the optimum: the ratings of a level are "
                  "separated from the others beyond what the link can represent (a probability "
                  "underflows to 0); no clmm can be fitted to these ratings";
        return r;
    }
    if (!fit.converged) r.warnings.push_back("convergence failure: " + fit.message);
    const int T = J - 1;
    const auto p = X.cols();
    const double sigma = fit.x.back();
    r.randomVariance = sigma * sigma;
    r.logLik = -fit.value;
    r.deviance = 2.0 * fit.value;
    r.aic = 2.0 * fit.value + 2.0 * dbl(static_cast<std::size_t>(T + p + 1));
    MatrixXd vcov;
    bool vcovOk = false;
    if (options.standardErrors) {
        const bool boundary = sigma == 0.0;
        Likelihood lik(d, X, category, J, link, options.nAGQ);
        std::vector<double> x = fit.x;
        if (boundary) x.pop_back();
        std::function<double(const std::vector<double>&)> f = [&](const std::vector<double>& v) {
            if (!boundary) return lik(v);
            auto psi = v;
            psi.push_back(0.0);
            return lik(psi);
        };
        VectorXd gradient;
        MatrixXd hessian;
        mixed::deriv12(f, x, fit.value, gradient, hessian);
        Eigen::SelfAdjointEigenSolver<MatrixXd> eig(hessian);
        const auto ev = eig.eigenvalues();
        if (ev.allFinite() && ev.minCoeff() > 0 &&
            ev.minCoeff() < 1e-8 * std::max(1.0, ev.maxCoeff()))
            r.warnings.emplace_back(
                "Hessian is numerically singular: parameters are not uniquely determined");
        vcovOk = mixed::invertPositiveDefinite(hessian, vcov) && vcov.allFinite();
        if (!vcovOk)
            r.warnings.emplace_back("Variance-covariance matrix of the parameters is not defined");
        if (boundary)
            r.warnings.emplace_back(
                "random-effect variance estimated at 0 (boundary): R's clmm reports "
                "\"Variance-covariance matrix of the parameters is not defined\" here; the "
                "standard errors given hold the variance at 0");
    }
    auto coefficient = [&](std::string name, Eigen::Index index, bool withP) {
        FixedEffect e;
        e.name = std::move(name);
        e.estimate = fit.x[static_cast<std::size_t>(index)];
        if (vcovOk && vcov(index, index) > 0) {
            e.se = std::sqrt(vcov(index, index));
            e.statistic = e.estimate / e.se;
            if (withP) e.p = 2.0 * numerics::pnorm(-std::fabs(e.statistic));
        }
        return e;
    };
    for (int t = 0; t < T; ++t)
        r.thresholds.push_back(
            coefficient(categoryName(present[static_cast<std::size_t>(t)]) + "|" +
                            categoryName(present[static_cast<std::size_t>(t) + 1]),
                        t, false));
    for (Eigen::Index j = 0; j < p; ++j)
        r.fixed.push_back(coefficient(d.names[static_cast<std::size_t>(j) + 1], T + j, true));
    if (d.conditionColumns > 0 && options.likelihoodRatio) {
        const Design reduced = mixed::buildDesign(data, false);
        if (reduced.error.empty()) {
            const MatrixXd X0 = reduced.X.rightCols(reduced.X.cols() - 1);
            const auto fit0 = optimise(reduced, X0, category, J, link, options.nAGQ,
                                       startValues(category, J, X0.cols(), link));
            r.lrt.statistic = std::max(0.0, 2.0 * (fit0.value - fit.value));
            r.lrt.df = d.conditionColumns;
            r.lrt.p = numerics::pchisq(r.lrt.statistic, r.lrt.df, false);
        }
    }
    return r;
}

} // namespace underfoot::analysis
