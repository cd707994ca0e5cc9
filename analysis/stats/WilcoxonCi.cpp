// SPDX-License-Identifier: GPL-3.0-or-later
// wilcox.test(conf.int = TRUE): Hodges-Lehmann estimates and confidence intervals, following
// R 4.2's wilcox.test.default line by line (exact from Walsh averages / pairwise differences
// and qsignrank / qwilcox; otherwise by inverting the normal approximation with uniroot).
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace underfoot::analysis {

using namespace numerics;

namespace {

/// R's qsignrank / qwilcox on a table of counts with total `total`.
double quantileFromCounts(const std::vector<double>& counts, double total, double x) {
    const double maxQ = dbl(counts.size() - 1);
    double p = 0;
    std::size_t q = 0;
    if (x <= 0.5) {
        x = x - 10 * DBL_EPSILON;
        for (;;) {
            p += counts[q] / total;
            if (p >= x) break;
            ++q;
        }
        return dbl(q);
    }
    x = 1 - x + 10 * DBL_EPSILON;
    for (;;) {
        p += counts[q] / total;
        if (p > x) return maxQ - dbl(q);
        ++q;
    }
}

/// P(X <= q) from counts (q below 0 gives 0).
double lowerTail(const std::vector<double>& counts, double total, double q) {
    const double qf = std::floor(q + 1e-7);
    double p = 0;
    for (std::size_t i = 0; dbl(i) <= qf && i < counts.size(); ++i) p += counts[i] / total;
    return p;
}

double signif2(double v) {
    if (v == 0 || !std::isfinite(v)) return v;
    const double e = std::floor(std::log10(std::fabs(v))) - 1;
    const double s = std::pow(10.0, e);
    return std::nearbyint(v / s) * s;
}

double rootOrThrow(const std::function<double(double)>& f, double lower, double upper,
                   double fLower, double fUpper) {
    if (fLower * fUpper > 0)
        throw std::runtime_error("f() values at end points not of opposite sign");
    return uniroot(f, lower, upper, fLower, fUpper, 1e-4).x;
}

double sgn(double v) {
    return v > 0 ? 1.0 : v < 0 ? -1.0 : 0.0;
}

double correctionFor(double z, Alternative a, bool correct) {
    if (!correct) return 0;
    switch (a) {
    case Alternative::Greater:
        return 0.5;
    case Alternative::Less:
        return -0.5;
    case Alternative::TwoSided:
        break;
    }
    return sgn(z) * 0.5;
}

/// Exact interval (no ties): the sorted Walsh averages (signed rank) or pairwise differences
/// (rank sum) at the quantiles of the statistic's null distribution `counts` (R's qsignrank /
/// qwilcox, wilcox.test.default). Returns the achieved significance level.
double exactInterval(const std::vector<double>& sorted, const std::vector<double>& counts,
                     double total, double alpha, Alternative alternative, Interval& ci) {
    const double nn = dbl(sorted.size());
    auto at = [&](double k) { return sorted[static_cast<std::size_t>(k) - 1]; };
    const bool twoSided = alternative == Alternative::TwoSided;
    double qu = quantileFromCounts(counts, total, twoSided ? alpha / 2 : alpha);
    if (qu == 0) qu = 1;
    const double achieved = (twoSided ? 2 : 1) * lowerTail(counts, total, std::trunc(qu) - 1);
    ci.lower = alternative == Alternative::Less ? -kInf : at(qu);
    ci.upper = alternative == Alternative::Greater ? kInf : at(nn - qu + 1);
    return achieved;
}

/// Adds `warning` unless it is there already (the normal approximation's root finder evaluates
/// the statistic many times).
void warnOnce(TestResult& r, const char* warning) {
    if (std::find(r.warnings.begin(), r.warnings.end(), warning) == r.warnings.end())
        r.warnings.emplace_back(warning);
}

/// R's warnings when an exact interval was asked for but the normal approximation was used.
void exactFallbackWarnings(TestResult& r, bool exact, bool ties, bool zeroes) {
    if (exact && ties)
        r.warnings.emplace_back("cannot compute exact confidence interval with ties");
    if (exact && zeroes)
        r.warnings.emplace_back("cannot compute exact confidence interval with zeroes");
}

/// Signed-rank part: x already has mu subtracted and zeros dropped.
void signedRankCi(TestResult& r, std::vector<double> x, const WilcoxonOptions& o, bool exact,
                  bool ties, bool zeroes, double confLevel) {
    for (double& v : x) v += o.mu;
    const std::size_t n = x.size();
    double alpha = 1 - confLevel;
    if (exact && !ties && !zeroes) {
        std::vector<double> diffs;
        diffs.reserve(n * (n + 1) / 2);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = i; j < n; ++j) diffs.push_back((x[i] + x[j]) / 2);
        std::sort(diffs.begin(), diffs.end());
        const auto counts = signedRankCounts(n);
        Interval ci;
        const double achieved =
            exactInterval(diffs, counts, std::pow(2.0, dbl(n)), alpha, o.alternative, ci);
        if (achieved - alpha > alpha / 2) {
            r.warnings.emplace_back("requested conf.level not achievable");
            confLevel = 1 - signif2(achieved);
        }
        ci.level = confLevel;
        r.confInt = ci;
        r.estimate = {{"(pseudo)median", median(diffs)}};
        return;
    }
    bool correct = o.continuity == Continuity::Corrected;
    const double mumin = *std::min_element(x.begin(), x.end());
    const double mumax = *std::max_element(x.begin(), x.end());
    auto W = [&](double d) {
        std::vector<double> xd, ad;
        for (double v : x)
            if (v - d != 0) {
                xd.push_back(v - d);
                ad.push_back(std::fabs(v - d));
            }
        const double nx = dbl(xd.size());
        const auto dr = averageRanks(ad);
        double zd = -nx * (nx + 1) / 4;
        for (std::size_t i = 0; i < xd.size(); ++i)
            if (xd[i] > 0) zd += dr[i];
        const double sigma =
            std::sqrt(nx * (nx + 1) * (2 * nx + 1) / 24 - tieCorrectionSum(dr) / 48);
        if (sigma == 0)
            warnOnce(r,
                     "cannot compute confidence interval when all observations are zero or tied");
        return (zd - correctionFor(zd, o.alternative, correct)) / sigma;
    };
    const double wMin = W(mumin);
    const double wMax = std::isfinite(wMin) ? W(mumax) : kNaN;
    if (!std::isfinite(wMax)) {
        Interval ci;
        ci.lower = o.alternative == Alternative::Less ? -kInf : kNaN;
        ci.upper = o.alternative == Alternative::Greater ? kInf : kNaN;
        ci.level = 0;
        r.confInt = ci;
        r.estimate = {{"midrange", (mumin + mumax) / 2}};
        return;
    }
    auto root = [&](double zq) {
        return rootOrThrow([&](double d) { return W(d) - zq; }, mumin, mumax, wMin - zq, wMax - zq);
    };
    Interval ci;
    auto checkLevel = [&] {
        if (alpha >= 1 || 1 - confLevel < alpha * 0.75) {
            confLevel = 1 - std::min(1.0, alpha);
            r.warnings.emplace_back("requested conf.level not achievable");
        }
    };
    switch (o.alternative) {
    case Alternative::TwoSided:
        while (wMin - qnorm(alpha / 2, false) < 0 || wMax - qnorm(alpha / 2) > 0) alpha *= 2;
        checkLevel();
        if (alpha < 1) {
            ci.lower = root(qnorm(alpha / 2, false));
            ci.upper = root(qnorm(alpha / 2));
        } else {
            ci.lower = ci.upper = median(x);
        }
        break;
    case Alternative::Greater:
        while (wMin - qnorm(alpha, false) < 0) alpha *= 2;
        checkLevel();
        ci.lower = alpha < 1 ? root(qnorm(alpha, false)) : median(x);
        ci.upper = kInf;
        break;
    case Alternative::Less:
        while (wMax - qnorm(alpha / 2) > 0) alpha *= 2;
        checkLevel();
        ci.lower = -kInf;
        ci.upper = alpha < 1 ? root(qnorm(alpha)) : median(x);
        break;
    }
    ci.level = confLevel;
    r.confInt = ci;
    correct = false;
    r.estimate = {{"(pseudo)median", rootOrThrow(W, mumin, mumax, W(mumin), W(mumax))}};
    exactFallbackWarnings(r, exact, ties, zeroes);
}

void rankSumCi(TestResult& r, const std::vector<double>& x, const std::vector<double>& y,
               const WilcoxonOptions& o, bool exact, bool ties, double confLevel) {
    const std::size_t m = x.size(), n = y.size();
    const double nx = dbl(m), ny = dbl(n);
    const double alpha = 1 - confLevel;
    if (exact && !ties) {
        std::vector<double> diffs;
        diffs.reserve(m * n);
        for (double a : x)
            for (double b : y) diffs.push_back(a - b);
        std::sort(diffs.begin(), diffs.end());
        const auto counts = rankSumCounts(m, n);
        Interval ci;
        const double achieved =
            exactInterval(diffs, counts, std::accumulate(counts.begin(), counts.end(), 0.0), alpha,
                          o.alternative, ci);
        if (achieved - alpha > alpha / 2) {
            r.warnings.emplace_back("Requested conf.level not achievable");
            confLevel = 1 - achieved;
        }
        ci.level = confLevel;
        r.confInt = ci;
        r.estimate = {{"difference in location", median(diffs)}};
        return;
    }
    bool correct = o.continuity == Continuity::Corrected;
    const double mumin =
        *std::min_element(x.begin(), x.end()) - *std::max_element(y.begin(), y.end());
    const double mumax =
        *std::max_element(x.begin(), x.end()) - *std::min_element(y.begin(), y.end());
    auto W = [&](double d) {
        std::vector<double> all;
        all.reserve(m + n);
        for (double v : x) all.push_back(v - d);
        all.insert(all.end(), y.begin(), y.end());
        const auto dr = averageRanks(all);
        double dz = -nx * (nx + 1) / 2 - nx * ny / 2;
        for (std::size_t i = 0; i < m; ++i) dz += dr[i];
        const double sigma = std::sqrt(
            (nx * ny / 12) * ((nx + ny + 1) - tieCorrectionSum(dr) / ((nx + ny) * (nx + ny - 1))));
        if (sigma == 0)
            warnOnce(r, "cannot compute confidence interval when all observations are tied");
        return (dz - correctionFor(dz, o.alternative, correct)) / sigma;
    };
    const double wMin = W(mumin), wMax = W(mumax);
    auto root = [&](double zq) {
        const double fl = wMin - zq;
        if (fl <= 0) return mumin;
        const double fu = wMax - zq;
        if (fu >= 0) return mumax;
        return rootOrThrow([&](double d) { return W(d) - zq; }, mumin, mumax, fl, fu);
    };
    Interval ci;
    switch (o.alternative) {
    case Alternative::TwoSided:
        ci.lower = root(qnorm(alpha / 2, false));
        ci.upper = root(qnorm(alpha / 2));
        break;
    case Alternative::Greater:
        ci.lower = root(qnorm(alpha, false));
        ci.upper = kInf;
        break;
    case Alternative::Less:
        ci.lower = -kInf;
        ci.upper = root(qnorm(alpha));
        break;
    }
    ci.level = confLevel;
    r.confInt = ci;
    correct = false;
    r.estimate = {{"difference in location", rootOrThrow(W, mumin, mumax, W(mumin), W(mumax))}};
    exactFallbackWarnings(r, exact, ties, false);
}

bool anyTies(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return std::adjacent_find(v.begin(), v.end()) != v.end();
}

bool validLevel(double c) {
    return std::isfinite(c) && c > 0 && c < 1;
}

/// R's order of warnings: those of the interval computation first, then each "cannot compute
/// exact p-value with X" of the test followed by its "cannot compute exact confidence interval
/// with X". `base` are the test's warnings, r.warnings those the interval added.
void orderWarningsAsR(TestResult& r, const std::vector<std::string>& base) {
    std::vector<std::string> out, exactCi;
    for (const auto& w : r.warnings)
        (w.rfind("cannot compute exact confidence interval", 0) == 0 ? exactCi : out).push_back(w);
    for (const auto& w : base) {
        out.push_back(w);
        const std::string prefix = "cannot compute exact p-value with ";
        if (w.rfind(prefix, 0) == 0) {
            const std::string ci =
                "cannot compute exact confidence interval with " + w.substr(prefix.size());
            if (std::find(exactCi.begin(), exactCi.end(), ci) != exactCi.end()) out.push_back(ci);
        }
    }
    r.warnings = std::move(out);
}

/// The test result `r` with the interval `compute` adds (warnings in R's order); the failed
/// test when the interval computation stops, as R's wilcox.test does.
template <typename Compute>
TestResult withInterval(TestResult r, Compute&& compute) {
    const auto base = std::move(r.warnings);
    r.warnings.clear();
    try {
        compute(r);
        orderWarningsAsR(r, base);
    } catch (const std::exception& e) {
        return failedTest(r.method, e.what());
    }
    return r;
}

TestResult signedRankWithCi(TestResult r, const std::vector<double>& d, const WilcoxonOptions& o,
                            double confLevel) {
    std::vector<double> x;
    bool zeroes = false;
    for (double v : d) {
        if (std::isnan(v)) continue;
        if (v - o.mu == 0) {
            zeroes = true;
            continue;
        }
        x.push_back(v - o.mu);
    }
    if (x.empty()) { // R: n == 0 gives NaN bounds and estimate
        Interval ci;
        ci.lower = o.alternative == Alternative::Less ? -kInf : kNaN;
        ci.upper = o.alternative == Alternative::Greater ? kInf : kNaN;
        ci.level = 0;
        r.confInt = ci;
        r.estimate = {{"(pseudo)median", kNaN}};
        return r;
    }
    std::vector<double> absx;
    for (double v : x) absx.push_back(std::fabs(v));
    const bool ties = anyTies(averageRanks(absx));
    const bool exact =
        o.exactness == Exactness::Auto ? x.size() < 50 : o.exactness == Exactness::Exact;
    return withInterval(std::move(r), [&](TestResult& out) {
        signedRankCi(out, x, o, exact, ties, zeroes, confLevel);
    });
}

} // namespace

TestResult wilcoxonTestCi(std::span<const double> x, const WilcoxonOptions& options,
                          double confLevel) {
    if (!validLevel(confLevel))
        return failedTest("Wilcoxon signed rank test",
                          "'conf.level' must be a single number between 0 and 1");
    TestResult r = wilcoxonTest(x, options);
    if (!r.ok()) return r;
    return signedRankWithCi(std::move(r), std::vector<double>(x.begin(), x.end()), options,
                            confLevel);
}

TestResult wilcoxonTestCi(std::span<const double> x, std::span<const double> y,
                          const WilcoxonOptions& options, double confLevel) {
    if (!validLevel(confLevel))
        return failedTest("Wilcoxon rank sum test",
                          "'conf.level' must be a single number between 0 and 1");
    TestResult r = wilcoxonTest(x, y, options);
    if (!r.ok()) return r;
    if (options.pairing == Pairing::Paired) {
        std::vector<double> d;
        for (std::size_t i = 0; i < x.size(); ++i)
            if (!std::isnan(x[i]) && !std::isnan(y[i])) d.push_back(x[i] - y[i]);
        return signedRankWithCi(std::move(r), d, options, confLevel);
    }
    const auto xs = dropMissing(x), ys = dropMissing(y);
    std::vector<double> all;
    for (double v : xs) all.push_back(v - options.mu);
    all.insert(all.end(), ys.begin(), ys.end());
    const bool ties = anyTies(averageRanks(all));
    const bool exact = options.exactness == Exactness::Auto ? xs.size() < 50 && ys.size() < 50
                                                            : options.exactness == Exactness::Exact;
    return withInterval(std::move(r), [&](TestResult& out) {
        rankSumCi(out, xs, ys, options, exact, ties, confLevel);
    });
}

} // namespace underfoot::analysis
