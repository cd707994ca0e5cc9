// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/stats/Numerics.h"

#include <boost/math/distributions/beta.hpp>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/hypergeometric.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/special_functions/gamma.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace underfoot::analysis::numerics {

namespace bm = boost::math;
// Errors become NaN / Inf rather than exceptions: the callers check arguments first, and a
// degenerate statistic (0/0) must give NaN exactly where R gives NaN.
using QuietPolicy =
    bm::policies::policy<bm::policies::domain_error<bm::policies::ignore_error>,
                         bm::policies::pole_error<bm::policies::ignore_error>,
                         bm::policies::overflow_error<bm::policies::ignore_error>,
                         bm::policies::underflow_error<bm::policies::ignore_error>,
                         bm::policies::evaluation_error<bm::policies::ignore_error>>;

Root uniroot(const std::function<double(double)>& f, double lower, double upper, double fLower,
             double fUpper, double tolerance, int maxIterations) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    double a = lower, b = upper, fa = fLower, fb = fUpper;
    double c = a, fc = fa;
    if (fa == 0.0) return {a, true};
    if (fb == 0.0) return {b, true};
    for (int iteration = 0; iteration <= maxIterations; ++iteration) {
        const double previousStep = b - a;
        if (std::fabs(fc) < std::fabs(fb)) {
            // keep b as the best approximation
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        const double toleranceNow = 2 * eps * std::fabs(b) + tolerance / 2;
        double step = (c - b) / 2;
        if (std::fabs(step) <= toleranceNow || fb == 0.0) return {b, true};
        if (std::fabs(previousStep) >= toleranceNow && std::fabs(fa) > std::fabs(fb)) {
            // interpolation: secant when two points are known, inverse quadratic otherwise
            double p = 0, q = 0;
            const double cb = c - b;
            if (a == c) {
                const double t1 = fb / fa;
                p = cb * t1;
                q = 1.0 - t1;
            } else {
                const double qa = fa / fc, t1 = fb / fc, t2 = fb / fa;
                p = t2 * (cb * qa * (qa - t1) - (b - a) * (t1 - 1.0));
                q = (qa - 1.0) * (t1 - 1.0) * (t2 - 1.0);
            }
            if (p > 0)
                q = -q;
            else
                p = -p;
            if (p < (0.75 * cb * q - std::fabs(toleranceNow * q) / 2) &&
                p < std::fabs(previousStep * q / 2))
                step = p / q;
        }
        if (std::fabs(step) < toleranceNow) step = step > 0 ? toleranceNow : -toleranceNow;
        a = b;
        fa = fb;
        b += step;
        fb = f(b);
        if ((fb > 0 && fc > 0) || (fb < 0 && fc < 0)) {
            c = a;
            fc = fa;
        }
    }
    return {b, false};
}

std::vector<double> averageRanks(std::span<const double> x) {
    const std::size_t n = x.size();
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t i, std::size_t j) { return x[i] < x[j]; });
    std::vector<double> ranks(n);
    for (std::size_t i = 0; i < n;) {
        std::size_t j = i;
        while (j + 1 < n && x[order[j + 1]] == x[order[i]]) ++j;
        const double rank = (dbl(i) + dbl(j)) / 2.0 + 1.0;
        for (std::size_t k = i; k <= j; ++k) ranks[order[k]] = rank;
        i = j + 1;
    }
    return ranks;
}

std::vector<double> tieGroupSizes(std::span<const double> x) {
    std::vector<double> sorted(x.begin(), x.end());
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> sizes;
    for (std::size_t i = 0; i < sorted.size();) {
        std::size_t j = i;
        while (j < sorted.size() && sorted[j] == sorted[i]) ++j;
        sizes.push_back(dbl(j - i));
        i = j;
    }
    return sizes;
}

double tieCorrectionSum(std::span<const double> x) {
    double sum = 0;
    for (double t : tieGroupSizes(x)) sum += t * t * t - t;
    return sum;
}

double mean(std::span<const double> x) {
    if (x.empty()) return kNaN;
    long double s = 0;
    for (double v : x) s += v;
    s /= static_cast<long double>(x.size());
    if (std::isfinite(static_cast<double>(s))) {
        long double t = 0;
        for (double v : x) t += v - s;
        s += t / static_cast<long double>(x.size());
    }
    return static_cast<double>(s);
}

double variance(std::span<const double> x) {
    if (x.size() < 2) return kNaN;
    const double m = mean(x);
    long double ss = 0;
    for (double v : x) ss += (static_cast<long double>(v) - m) * (static_cast<long double>(v) - m);
    return static_cast<double>(ss / static_cast<long double>(x.size() - 1));
}

double median(std::span<const double> x) {
    if (x.empty()) return kNaN;
    std::vector<double> s(x.begin(), x.end());
    std::sort(s.begin(), s.end());
    const std::size_t n = s.size();
    return n % 2 == 1 ? s[n / 2] : (s[n / 2 - 1] + s[n / 2]) / 2.0;
}

bool anyNonFinite(std::span<const double> x) {
    return std::any_of(x.begin(), x.end(), [](double v) { return !std::isfinite(v); });
}

std::vector<double> dropMissing(std::span<const double> x) {
    std::vector<double> out;
    out.reserve(x.size());
    for (double v : x)
        if (!std::isnan(v)) out.push_back(v);
    return out;
}

double pnorm(double x, bool lowerTail) {
    if (std::isnan(x)) return kNaN;
    if (std::isinf(x)) return (x > 0) == lowerTail ? 1.0 : 0.0;
    const bm::normal_distribution<double, QuietPolicy> d;
    return lowerTail ? bm::cdf(d, x) : bm::cdf(bm::complement(d, x));
}

double qnorm(double p, bool lowerTail) {
    if (std::isnan(p) || p < 0 || p > 1) return kNaN;
    if (p == 0) return lowerTail ? -kInf : kInf;
    if (p == 1) return lowerTail ? kInf : -kInf;
    const bm::normal_distribution<double, QuietPolicy> d;
    return lowerTail ? bm::quantile(d, p) : bm::quantile(bm::complement(d, p));
}

double pt(double t, double df, bool lowerTail) {
    if (std::isnan(t) || std::isnan(df) || df <= 0) return kNaN;
    if (std::isinf(t)) return (t > 0) == lowerTail ? 1.0 : 0.0;
    if (std::isinf(df)) return pnorm(t, lowerTail);
    const bm::students_t_distribution<double, QuietPolicy> d(df);
    return lowerTail ? bm::cdf(d, t) : bm::cdf(bm::complement(d, t));
}

double qt(double p, double df, bool lowerTail) {
    if (std::isnan(p) || std::isnan(df) || df <= 0 || p < 0 || p > 1) return kNaN;
    if (p == 0) return lowerTail ? -kInf : kInf;
    if (p == 1) return lowerTail ? kInf : -kInf;
    if (std::isinf(df)) return qnorm(p, lowerTail);
    const bm::students_t_distribution<double, QuietPolicy> d(df);
    return lowerTail ? bm::quantile(d, p) : bm::quantile(bm::complement(d, p));
}

double pchisq(double x, double df, bool lowerTail) {
    if (std::isnan(x) || std::isnan(df) || df < 0) return kNaN;
    if (x <= 0) return lowerTail ? 0.0 : 1.0;
    if (std::isinf(x)) return lowerTail ? 1.0 : 0.0;
    if (df == 0) return lowerTail ? 1.0 : 0.0; // point mass at 0
    const bm::chi_squared_distribution<double, QuietPolicy> d(df);
    return lowerTail ? bm::cdf(d, x) : bm::cdf(bm::complement(d, x));
}

double pf(double x, double df1, double df2, bool lowerTail) {
    if (std::isnan(x) || std::isnan(df1) || std::isnan(df2) || df1 <= 0 || df2 <= 0) return kNaN;
    if (x <= 0) return lowerTail ? 0.0 : 1.0;
    if (std::isinf(x)) return lowerTail ? 1.0 : 0.0;
    const bm::fisher_f_distribution<double, QuietPolicy> d(df1, df2);
    return lowerTail ? bm::cdf(d, x) : bm::cdf(bm::complement(d, x));
}

double qbeta(double p, double a, double b) {
    if (std::isnan(p) || p < 0 || p > 1 || !(a > 0) || !(b > 0)) return kNaN;
    const bm::beta_distribution<double, QuietPolicy> d(a, b);
    return bm::quantile(d, p);
}

double dbinom(double x, double n, double p) {
    if (x < 0 || x > n) return 0.0;
    const bm::binomial_distribution<double, QuietPolicy> d(n, p);
    return bm::pdf(d, x);
}

double pbinom(double x, double n, double p, bool lowerTail) {
    x = std::floor(x + 1e-7);
    if (x < 0) return lowerTail ? 0.0 : 1.0;
    if (x >= n) return lowerTail ? 1.0 : 0.0;
    const bm::binomial_distribution<double, QuietPolicy> d(n, p);
    return lowerTail ? bm::cdf(d, x) : bm::cdf(bm::complement(d, x));
}

namespace {
double logChoose(double n, double k) {
    return bm::lgamma(n + 1, QuietPolicy()) - bm::lgamma(k + 1, QuietPolicy()) -
           bm::lgamma(n - k + 1, QuietPolicy());
}
} // namespace

double logDhyper(double x, double m, double n, double k) {
    if (x < 0 || x > m || x > k || k - x > n) return -kInf;
    return logChoose(m, x) + logChoose(n, k - x) - logChoose(m + n, k);
}

double phyper(double x, double m, double n, double k, bool lowerTail) {
    x = std::floor(x + 1e-7);
    const double lo = std::max(0.0, k - n), hi = std::min(k, m);
    if (x < lo) return lowerTail ? 0.0 : 1.0;
    if (x >= hi) return lowerTail ? 1.0 : 0.0;
    // Sum the requested tail directly so that small tails keep their relative precision.
    double sum = 0;
    if (lowerTail)
        for (double i = lo; i <= x; i += 1) sum += std::exp(logDhyper(i, m, n, k));
    else
        for (double i = x + 1; i <= hi; i += 1) sum += std::exp(logDhyper(i, m, n, k));
    return std::min(1.0, sum);
}

} // namespace underfoot::analysis::numerics
