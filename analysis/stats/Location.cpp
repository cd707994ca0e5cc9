// SPDX-License-Identifier: GPL-3.0-or-later
// t.test, shapiro.test, car::leveneTest, p.adjust and Cohen's d, following R 4.2.
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace underfoot::analysis {

using namespace numerics;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

void finishT(TestResult& r, double tstat, double df, double stderrValue, const TTestOptions& o) {
    r.statisticName = "t";
    r.statistic = tstat;
    r.df = {df};
    Interval ci;
    ci.level = o.confLevel;
    switch (o.alternative) {
    case Alternative::Less:
        r.p = pt(tstat, df);
        ci.lower = -kInf;
        ci.upper = tstat + qt(o.confLevel, df);
        break;
    case Alternative::Greater:
        r.p = pt(tstat, df, false);
        ci.lower = tstat - qt(o.confLevel, df);
        ci.upper = kInf;
        break;
    case Alternative::TwoSided: {
        r.p = 2 * pt(-std::fabs(tstat), df);
        const double q = qt(1 - (1 - o.confLevel) / 2, df);
        ci.lower = tstat - q;
        ci.upper = tstat + q;
        break;
    }
    }
    ci.lower = o.mu + ci.lower * stderrValue;
    ci.upper = o.mu + ci.upper * stderrValue;
    r.confInt = ci;
    r.alternative = o.alternative;
}

std::string checkT(const TTestOptions& o) {
    if (!std::isfinite(o.mu)) return "'mu' must be a single number";
    if (!std::isfinite(o.confLevel) || o.confLevel < 0 || o.confLevel > 1)
        return "'conf.level' must be a single number between 0 and 1";
    return {};
}

TestResult oneSampleT(std::vector<double> x, const TTestOptions& o, bool paired) {
    TestResult r;
    r.method = paired ? "Paired t-test" : "One Sample t-test";
    const double nx = dbl(x.size());
    if (x.size() < 2) return failedTest(r.method, "not enough 'x' observations");
    const double mx = mean(x), vx = variance(x);
    const double se = std::sqrt(vx / nx);
    if (se < 10 * kEps * std::fabs(mx))
        return failedTest(r.method, "data are essentially constant");
    finishT(r, (mx - o.mu) / se, nx - 1, se, o);
    r.estimate = {{paired ? "mean difference" : "mean of x", mx}};
    return r;
}

} // namespace

TestResult tTest(std::span<const double> x, const TTestOptions& options) {
    if (auto e = checkT(options); !e.empty()) return failedTest("One Sample t-test", e);
    if (anyNonFinite(dropMissing(x)))
        return failedTest("One Sample t-test", "'x' contains infinite values");
    return oneSampleT(dropMissing(x), options, false);
}

TestResult tTest(std::span<const double> x, std::span<const double> y,
                 const TTestOptions& options) {
    const bool paired = options.pairing == Pairing::Paired;
    const std::string method = paired                                ? "Paired t-test"
                               : options.variance == Variance::Welch ? "Welch Two Sample t-test"
                                                                     : "Two Sample t-test";
    if (auto e = checkT(options); !e.empty()) return failedTest(method, e);
    if (anyNonFinite(dropMissing(x)) || anyNonFinite(dropMissing(y)))
        return failedTest(method, "'x' and 'y' must not contain infinite values");
    if (paired) {
        if (x.size() != y.size())
            return failedTest(method, "'x' and 'y' must have the same length");
        std::vector<double> d;
        for (std::size_t i = 0; i < x.size(); ++i)
            if (!std::isnan(x[i]) && !std::isnan(y[i])) d.push_back(x[i] - y[i]);
        return oneSampleT(std::move(d), options, true);
    }
    const auto xs = dropMissing(x), ys = dropMissing(y);
    const bool equal = options.variance == Variance::Equal;
    const double nx = dbl(xs.size()), ny = dbl(ys.size());
    if (nx < 1 || (!equal && nx < 2)) return failedTest(method, "not enough 'x' observations");
    if (ny < 1 || (!equal && ny < 2)) return failedTest(method, "not enough 'y' observations");
    if (equal && nx + ny < 3) return failedTest(method, "not enough observations");
    const double mx = mean(xs), my = mean(ys);
    const double vx = variance(xs), vy = variance(ys);
    double se = 0, df = 0;
    if (equal) {
        df = nx + ny - 2;
        double v = 0;
        if (nx > 1) v += (nx - 1) * vx;
        if (ny > 1) v += (ny - 1) * vy;
        v /= df;
        se = std::sqrt(v * (1 / nx + 1 / ny));
    } else {
        const double sx = std::sqrt(vx / nx), sy = std::sqrt(vy / ny);
        se = std::sqrt(sx * sx + sy * sy);
        df = std::pow(se, 4) / (std::pow(sx, 4) / (nx - 1) + std::pow(sy, 4) / (ny - 1));
    }
    if (se < 10 * kEps * std::max(std::fabs(mx), std::fabs(my)))
        return failedTest(method, "data are essentially constant");
    TestResult r;
    r.method = method;
    finishT(r, (mx - my - options.mu) / se, df, se, options);
    r.estimate = {{"mean of x", mx}, {"mean of y", my}};
    return r;
}

namespace {

/// Polynomial c[0] + c[1] x + ... (AS 181.2 evaluation order).
double poly(std::span<const double> c, double x) {
    double result = c[0];
    if (c.size() > 1) {
        double p = x * c[c.size() - 1];
        for (std::size_t j = c.size() - 2; j > 0; --j) p = (p + c[j]) * x;
        result += p;
    }
    return result;
}

} // namespace

TestResult shapiroTest(std::span<const double> input) {
    // Royston (1995) "A remark on algorithm AS 181: the W-test for normality", Applied
    // Statistics 44(4), algorithm AS R94, as used by R's shapiro.test (no censoring).
    const std::string method = "Shapiro-Wilk normality test";
    std::vector<double> x = dropMissing(input);
    if (anyNonFinite(x)) return failedTest(method, "'x' contains infinite values");
    std::sort(x.begin(), x.end());
    const std::size_t n = x.size();
    if (n < 3 || n > 5000) return failedTest(method, "sample size must be between 3 and 5000");
    double range = x[n - 1] - x[0];
    if (range == 0) return failedTest(method, "all 'x' values are identical");
    if (range < 1e-10) {
        for (double& v : x) v /= range;
        range = x[n - 1] - x[0];
    }
    const double an = dbl(n);
    const std::size_t half = n / 2;
    std::vector<double> a(half + 1, 0.0); // 1-based coefficients
    static constexpr double c1[] = {0., .221157, -.147981, -2.07119, 4.434685, -2.706056};
    static constexpr double c2[] = {0., .042981, -.293762, -1.752461, 5.682633, -3.582633};
    if (n == 3) {
        a[1] = std::sqrt(0.5);
    } else {
        const double an25 = an + .25;
        double summ2 = 0;
        for (std::size_t i = 1; i <= half; ++i) {
            a[i] = qnorm((dbl(i) - .375) / an25);
            summ2 += a[i] * a[i];
        }
        summ2 *= 2;
        const double ssumm2 = std::sqrt(summ2), rsn = 1 / std::sqrt(an);
        const double a1 = poly(c1, rsn) - a[1] / ssumm2;
        std::size_t first = 2;
        double fac = 0;
        if (n > 5) {
            first = 3;
            const double a2 = -a[2] / ssumm2 + poly(c2, rsn);
            fac = std::sqrt((summ2 - 2 * a[1] * a[1] - 2 * a[2] * a[2]) /
                            (1 - 2 * a1 * a1 - 2 * a2 * a2));
            a[2] = a2;
        } else {
            fac = std::sqrt((summ2 - 2 * a[1] * a[1]) / (1 - 2 * a1 * a1));
        }
        a[1] = a1;
        for (std::size_t i = first; i <= half; ++i) a[i] /= -fac;
    }
    // W as the squared correlation between the data and the coefficients, computed as 1 - W
    // to keep precision when W is near 1.
    auto coefficient = [&](std::size_t i) { // antisymmetric coefficient of the i-th order stat
        const std::size_t j = n - 1 - i;
        if (i == j) return 0.0;
        return i < j ? -a[i + 1] : a[j + 1];
    };
    double sa = 0, sx = 0;
    for (std::size_t i = 0; i < n; ++i) {
        sa += coefficient(i);
        sx += x[i] / range;
    }
    sa /= an;
    sx /= an;
    double ssa = 0, ssx = 0, sax = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double asa = coefficient(i) - sa, xsx = x[i] / range - sx;
        ssa += asa * asa;
        ssx += xsx * xsx;
        sax += asa * xsx;
    }
    const double ssassx = std::sqrt(ssa * ssx);
    const double w1 = (ssassx - sax) * (ssassx + sax) / (ssa * ssx);
    const double w = 1 - w1;
    TestResult r;
    r.method = method;
    r.statisticName = "W";
    r.statistic = w;
    if (n == 3) {
        constexpr double sixOverPi = 1.90985931710274, asinSqrt3over4 = 1.04719755119660;
        r.p = std::max(0.0, sixOverPi * (std::asin(std::sqrt(w)) - asinSqrt3over4));
        return r;
    }
    double y = std::log(w1);
    const double lnN = std::log(an);
    double m = 0, s = 0;
    if (n <= 11) {
        static constexpr double g[] = {-2.273, .459};
        static constexpr double c3[] = {.544, -.39978, .025054, -6.714e-4};
        static constexpr double c4[] = {1.3822, -.77857, .062767, -.0020322};
        const double gamma = poly(g, an);
        if (y >= gamma) {
            r.p = 1e-99; // R's value for W beyond the approximation's range
            return r;
        }
        y = -std::log(gamma - y);
        m = poly(c3, an);
        s = std::exp(poly(c4, an));
    } else {
        static constexpr double c5[] = {-1.5861, -.31082, -.083751, .0038915};
        static constexpr double c6[] = {-.4803, -.082676, .0030302};
        m = poly(c5, lnN);
        s = std::exp(poly(c6, lnN));
    }
    r.p = pnorm((y - m) / s, false);
    return r;
}

TestResult leveneTest(const std::vector<std::vector<double>>& groups, LeveneCenter center) {
    const std::string method = center == LeveneCenter::Median
                                   ? "Levene's Test for Homogeneity of Variance (center = median)"
                                   : "Levene's Test for Homogeneity of Variance (center = mean)";
    std::vector<std::vector<double>> dev;
    std::size_t total = 0;
    for (const auto& g : groups) {
        auto values = dropMissing(g);
        if (anyNonFinite(values)) return failedTest(method, "values must be finite");
        if (values.empty()) continue; // car drops empty factor levels with the data
        const double c = center == LeveneCenter::Median ? median(values) : mean(values);
        for (double& v : values) v = std::fabs(v - c);
        total += values.size();
        dev.push_back(std::move(values));
    }
    const std::size_t k = dev.size();
    if (k < 2) return failedTest(method, "need at least 2 groups with data");
    if (total <= k)
        return failedTest(method, "not enough observations: need more than one per group");
    // One-way ANOVA on the absolute deviations.
    std::vector<double> all;
    for (const auto& g : dev) all.insert(all.end(), g.begin(), g.end());
    const double grand = mean(all);
    double ssBetween = 0, ssWithin = 0;
    for (const auto& g : dev) {
        const double m = mean(g);
        ssBetween += dbl(g.size()) * (m - grand) * (m - grand);
        for (double v : g) ssWithin += (v - m) * (v - m);
    }
    const double df1 = dbl(k) - 1, df2 = dbl(total) - dbl(k);
    TestResult r;
    r.method = method;
    r.statisticName = "F value";
    r.statistic = (ssBetween / df1) / (ssWithin / df2);
    r.df = {df1, df2};
    r.p = pf(r.statistic, df1, df2, false);
    return r;
}

std::vector<double> pAdjust(std::span<const double> p, PAdjustMethod method) {
    std::vector<double> out(p.begin(), p.end());
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < p.size(); ++i)
        if (!std::isnan(p[i])) idx.push_back(i);
    const double n = dbl(idx.size());
    if (idx.size() <= 1 || method == PAdjustMethod::None) return out;
    switch (method) {
    case PAdjustMethod::Bonferroni:
        for (std::size_t i : idx) out[i] = std::min(1.0, n * p[i]);
        break;
    case PAdjustMethod::Holm: {
        auto order = idx;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return p[a] < p[b]; });
        double running = 0;
        for (std::size_t i = 0; i < order.size(); ++i) {
            running = std::max(running, (n - dbl(i)) * p[order[i]]);
            out[order[i]] = std::min(1.0, running);
        }
        break;
    }
    case PAdjustMethod::Hochberg:
    case PAdjustMethod::BenjaminiHochberg: {
        auto order = idx;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return p[a] > p[b]; });
        double running = kInf;
        for (std::size_t i = 0; i < order.size(); ++i) {
            const double rankFromTop = n - dbl(i); // i = lp..1 in R
            const double factor =
                method == PAdjustMethod::Hochberg ? (n + 1 - rankFromTop) : n / rankFromTop;
            running = std::min(running, factor * p[order[i]]);
            out[order[i]] = std::min(1.0, running);
        }
        break;
    }
    case PAdjustMethod::None:
        break;
    }
    return out;
}

double cohensD(std::span<const double> x, std::span<const double> y) {
    const auto xs = dropMissing(x), ys = dropMissing(y);
    if (xs.size() < 2 || ys.size() < 2) return kNaN;
    const double nx = dbl(xs.size()), ny = dbl(ys.size());
    const double pooled =
        std::sqrt(((nx - 1) * variance(xs) + (ny - 1) * variance(ys)) / (nx + ny - 2));
    return pooled > 0 ? (mean(xs) - mean(ys)) / pooled : kNaN;
}

} // namespace underfoot::analysis
