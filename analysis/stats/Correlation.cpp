// SPDX-License-Identifier: GPL-3.0-or-later
// cor.test(method = "pearson") and cor.test(method = "kendall"), following R 4.2's
// cor.test.default and the C routines cor() (tau-b) and ckendall/pkendall (exact distribution).
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace underfoot::analysis {

using namespace numerics;

namespace {

/// Complete pairs (R's cor.test drops a pair when either value is NA); rejects infinities.
bool completePairs(std::span<const double> x, std::span<const double> y, std::vector<double>& xs,
                   std::vector<double>& ys, std::string& error) {
    if (x.size() != y.size()) {
        error = "'x' and 'y' must have the same length";
        return false;
    }
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (std::isinf(x[i]) || std::isinf(y[i])) {
            error = "infinite values in 'x' or 'y'";
            return false;
        }
        if (std::isnan(x[i]) || std::isnan(y[i])) continue;
        xs.push_back(x[i]);
        ys.push_back(y[i]);
    }
    return true;
}

double tPValue(double t, double df, Alternative alternative) {
    switch (alternative) {
    case Alternative::Less:
        return pt(t, df);
    case Alternative::Greater:
        return pt(t, df, false);
    case Alternative::TwoSided:
        break;
    }
    return 2 * std::min(pt(t, df), pt(t, df, false));
}

/// Pearson's r with two-pass centring, as R's cor().
double pearsonR(std::span<const double> x, std::span<const double> y) {
    const double mx = mean(x), my = mean(y);
    long double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const long double dx = x[i] - mx, dy = y[i] - my;
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    if (sxx == 0 || syy == 0) return kNaN;
    const double r = static_cast<double>(sxy / std::sqrt(sxx * syy));
    return std::clamp(r, -1.0, 1.0); // R clips the rounding overshoot the same way
}

/// Kendall's tau-b as R's cor(method = "kendall").
double kendallTauB(std::span<const double> x, std::span<const double> y) {
    double sxy = 0, sxx = 0, syy = 0;
    auto sign = [](double v) { return v > 0 ? 1.0 : v < 0 ? -1.0 : 0.0; };
    for (std::size_t i = 0; i < x.size(); ++i)
        for (std::size_t j = 0; j < x.size(); ++j) {
            if (i == j) continue;
            const double sx = sign(x[i] - x[j]), sy = sign(y[i] - y[j]);
            sxy += sx * sy;
            sxx += sx * sx;
            syy += sy * sy;
        }
    if (sxx == 0 || syy == 0) return kNaN;
    return sxy / (std::sqrt(sxx) * std::sqrt(syy));
}

/// Number of permutations of 1..n with each count k of concordant pairs (R's ckendall).
std::vector<double> kendallCounts(std::size_t n) {
    std::vector<double> w{1.0};
    for (std::size_t m = 2; m <= n; ++m) {
        std::vector<double> next(m * (m - 1) / 2 + 1, 0.0);
        for (std::size_t k = 0; k < next.size(); ++k)
            for (std::size_t i = 0; i < m && i <= k; ++i)
                if (k - i < w.size()) next[k] += w[k - i];
        w = std::move(next);
    }
    return w;
}

/// R's pkendall(q, n): P(T <= q).
double pkendall(double q, std::size_t n) {
    const auto w = kendallCounts(n);
    const double qf = std::floor(q + 1e-7);
    if (qf < 0) return 0;
    if (qf > dbl(n * (n - 1) / 2)) return 1;
    double p = 0;
    for (std::size_t j = 0; dbl(j) <= qf; ++j) p += w[j];
    return p / std::tgamma(dbl(n) + 1);
}

std::vector<double> tieSizesAbove1(std::span<const double> v) {
    std::map<double, double> counts;
    for (double d : v) counts[d] += 1;
    std::vector<double> out;
    for (const auto& [value, c] : counts)
        if (c > 1) out.push_back(c);
    return out;
}

} // namespace

TestResult pearsonTest(std::span<const double> x, std::span<const double> y,
                       Alternative alternative, double confLevel) {
    const std::string method = "Pearson's product-moment correlation";
    std::vector<double> xs, ys;
    std::string error;
    if (!completePairs(x, y, xs, ys, error)) return failedTest(method, error);
    if (!(confLevel > 0 && confLevel < 1) || !std::isfinite(confLevel))
        return failedTest(method, "'conf.level' must be a single number between 0 and 1");
    const std::size_t n = xs.size();
    if (n < 3) return failedTest(method, "not enough finite observations");
    TestResult res;
    res.method = method;
    res.alternative = alternative;
    res.statisticName = "t";
    const double df = dbl(n) - 2;
    res.df = {df};
    const double r = pearsonR(xs, ys);
    if (std::isnan(r)) res.warnings.emplace_back("the standard deviation is zero");
    res.estimate = {{"cor", r}};
    res.statistic = std::sqrt(df) * r / std::sqrt(1 - r * r);
    res.p = std::isnan(r) ? kNaN : tPValue(res.statistic, df, alternative);
    if (n > 3) {
        const double z = std::atanh(r), sigma = 1 / std::sqrt(dbl(n) - 3);
        Interval ci;
        ci.level = confLevel;
        switch (alternative) {
        case Alternative::Less:
            ci.lower = -kInf;
            ci.upper = z + sigma * qnorm(confLevel);
            break;
        case Alternative::Greater:
            ci.lower = z - sigma * qnorm(confLevel);
            ci.upper = kInf;
            break;
        case Alternative::TwoSided:
            ci.lower = z - sigma * qnorm((1 + confLevel) / 2);
            ci.upper = z + sigma * qnorm((1 + confLevel) / 2);
            break;
        }
        ci.lower = std::tanh(ci.lower);
        ci.upper = std::tanh(ci.upper);
        res.confInt = ci;
    }
    return res;
}

TestResult kendallTest(std::span<const double> x, std::span<const double> y,
                       Alternative alternative, Exactness exactness, Continuity continuity) {
    const std::string method = "Kendall's rank correlation tau";
    std::vector<double> xs, ys;
    std::string error;
    if (!completePairs(x, y, xs, ys, error)) return failedTest(method, error);
    const std::size_t n = xs.size();
    if (n < 2) return failedTest(method, "not enough finite observations");
    TestResult res;
    res.method = method;
    res.alternative = alternative;
    const double r = kendallTauB(xs, ys);
    res.estimate = {{"tau", r}};
    const auto xt = tieSizesAbove1(xs), yt = tieSizesAbove1(ys);
    const bool ties = !xt.empty() || !yt.empty();
    bool exact = exactness == Exactness::Auto ? n < 50 : exactness == Exactness::Exact;
    if (!std::isfinite(r)) {
        res.statisticName = (exact && !ties) ? "T" : "z";
        res.estimate[0].value = kNaN;
        res.warnings.emplace_back("the standard deviation is zero");
        return res;
    }
    if (exact && !ties) {
        if (n > kMaxExactKendallN)
            return failedTest(method, "exact Kendall p-values are limited to n <= " +
                                          std::to_string(kMaxExactKendallN));
        const double nd = dbl(n);
        const double q = std::round((r + 1) * nd * (nd - 1) / 4);
        res.statisticName = "T";
        res.statistic = q;
        switch (alternative) {
        case Alternative::TwoSided: {
            const double p = q > nd * (nd - 1) / 4 ? 1 - pkendall(q - 1, n) : pkendall(q, n);
            res.p = std::min(2 * p, 1.0);
            break;
        }
        case Alternative::Greater:
            res.p = 1 - pkendall(q - 1, n);
            break;
        case Alternative::Less:
            res.p = pkendall(q, n);
            break;
        }
        return res;
    }
    const double nd = dbl(n);
    const double t0 = nd * (nd - 1) / 2;
    double t1 = 0, t2 = 0, vt = 0, vu = 0, sx1 = 0, sy1 = 0, sx2 = 0, sy2 = 0;
    for (double t : xt) {
        t1 += t * (t - 1) / 2;
        vt += t * (t - 1) * (2 * t + 5);
        sx1 += t * (t - 1);
        sx2 += t * (t - 1) * (t - 2);
    }
    for (double t : yt) {
        t2 += t * (t - 1) / 2;
        vu += t * (t - 1) * (2 * t + 5);
        sy1 += t * (t - 1);
        sy2 += t * (t - 1) * (t - 2);
    }
    double s = r * std::sqrt((t0 - t1) * (t0 - t2));
    const double v0 = nd * (nd - 1) * (2 * nd + 5);
    const double varS = (v0 - vt - vu) / 18 + sx1 * sy1 / (2 * nd * (nd - 1)) +
                        sx2 * sy2 / (9 * nd * (nd - 1) * (nd - 2));
    if (exact && ties) res.warnings.emplace_back("Cannot compute exact p-value with ties");
    if (continuity == Continuity::Corrected)
        s = (s > 0 ? 1.0 : s < 0 ? -1.0 : 0.0) * (std::fabs(s) - 1);
    res.statisticName = "z";
    res.statistic = s / std::sqrt(varS);
    switch (alternative) {
    case Alternative::Less:
        res.p = pnorm(res.statistic);
        break;
    case Alternative::Greater:
        res.p = pnorm(res.statistic, false);
        break;
    case Alternative::TwoSided:
        res.p = 2 * std::min(pnorm(res.statistic), pnorm(res.statistic, false));
        break;
    }
    return res;
}

} // namespace underfoot::analysis
