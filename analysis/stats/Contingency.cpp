// SPDX-License-Identifier: GPL-3.0-or-later
// Tests on counts: chisq.test, fisher.test (2 x 2), binom.test, prop.test, Wilson intervals,
// following the R 4.2 stats sources step by step so that results agree to rounding.
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace underfoot::analysis {

using namespace numerics;

const char* alternativeName(Alternative alternative) {
    switch (alternative) {
    case Alternative::Less:
        return "less";
    case Alternative::Greater:
        return "greater";
    case Alternative::TwoSided:
        break;
    }
    return "two.sided";
}

namespace {

bool isRectangular(const CountTable& table) {
    if (table.empty() || table.front().empty()) return false;
    return std::all_of(table.begin(), table.end(),
                       [&](const auto& row) { return row.size() == table.front().size(); });
}

bool validLevel(double level) {
    return std::isfinite(level) && level > 0 && level < 1;
}

} // namespace

TestResult chisqGoodnessOfFit(std::span<const double> counts, std::span<const double> p) {
    const std::string method = "Chi-squared test for given probabilities";
    for (double v : counts)
        if (!(v >= 0) || !std::isfinite(v))
            return failedTest(method, "all entries of 'x' must be nonnegative and finite");
    double n = 0;
    for (double v : counts) n += v;
    if (n == 0) return failedTest(method, "at least one entry of 'x' must be positive");
    if (counts.size() == 1) return failedTest(method, "'x' must at least have 2 elements");
    std::vector<double> prob(p.begin(), p.end());
    if (prob.empty()) prob.assign(counts.size(), 1.0 / dbl(counts.size()));
    if (prob.size() != counts.size())
        return failedTest(method, "'x' and 'p' must have the same number of elements");
    double sumP = 0;
    for (double v : prob) {
        if (!(v >= 0)) return failedTest(method, "probabilities must be non-negative.");
        sumP += v;
    }
    if (std::fabs(sumP - 1) > std::sqrt(std::numeric_limits<double>::epsilon()))
        return failedTest(method, "probabilities must sum to 1.");
    TestResult r;
    r.method = method;
    r.statisticName = "X-squared";
    double stat = 0;
    bool smallExpected = false;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const double e = n * prob[i];
        stat += (counts[i] - e) * (counts[i] - e) / e;
        smallExpected = smallExpected || e < 5;
    }
    r.statistic = stat;
    r.df = {dbl(counts.size()) - 1};
    r.p = pchisq(stat, r.df[0], false);
    if (smallExpected) r.warnings.emplace_back("Chi-squared approximation may be incorrect");
    return r;
}

TestResult chisqTest(const CountTable& table, Continuity continuity) {
    std::string method = "Pearson's Chi-squared test";
    if (!isRectangular(table))
        return failedTest(method, "'x' must be a non-empty rectangular table");
    const std::size_t nr = table.size(), nc = table.front().size();
    if (nr == 1) return chisqGoodnessOfFit(table.front());
    if (nc == 1) {
        std::vector<double> column;
        for (const auto& row : table) column.push_back(row[0]);
        return chisqGoodnessOfFit(column);
    }
    double n = 0;
    for (const auto& row : table)
        for (double v : row) {
            if (!(v >= 0) || !std::isfinite(v))
                return failedTest(method, "all entries of 'x' must be nonnegative and finite");
            n += v;
        }
    if (n == 0) return failedTest(method, "at least one entry of 'x' must be positive");
    std::vector<double> rowSums(nr, 0.0), colSums(nc, 0.0);
    for (std::size_t i = 0; i < nr; ++i)
        for (std::size_t j = 0; j < nc; ++j) {
            rowSums[i] += table[i][j];
            colSums[j] += table[i][j];
        }
    auto expected = [&](std::size_t i, std::size_t j) { return rowSums[i] * colSums[j] / n; };
    double yates = 0;
    if (continuity == Continuity::Corrected && nr == 2 && nc == 2) {
        yates = 0.5;
        for (std::size_t i = 0; i < 2; ++i)
            for (std::size_t j = 0; j < 2; ++j)
                yates = std::min(yates, std::fabs(table[i][j] - expected(i, j)));
        if (yates > 0) method += " with Yates' continuity correction";
    }
    TestResult r;
    r.method = method;
    r.statisticName = "X-squared";
    double stat = 0;
    bool smallExpected = false;
    for (std::size_t i = 0; i < nr; ++i)
        for (std::size_t j = 0; j < nc; ++j) {
            const double e = expected(i, j);
            const double d = std::fabs(table[i][j] - e) - yates;
            stat += d * d / e;
            smallExpected = smallExpected || e < 5;
        }
    r.statistic = stat;
    r.df = {dbl((nr - 1) * (nc - 1))};
    r.p = pchisq(stat, r.df[0], false);
    if (smallExpected) r.warnings.emplace_back("Chi-squared approximation may be incorrect");
    return r;
}

namespace {

/// The non-central hypergeometric distribution of fisher.test's 2 x 2 case.
class NoncentralHypergeometric {
  public:
    NoncentralHypergeometric(double m, double n, double k, double x)
        : m_(m), n_(n), k_(k), x_(x), lo_(std::max(0.0, k - n)), hi_(std::min(k, m)) {
        for (double s = lo_; s <= hi_; s += 1) {
            support_.push_back(s);
            logdc_.push_back(logDhyper(s, m, n, k));
        }
    }
    double lo() const { return lo_; }
    double hi() const { return hi_; }

    std::vector<double> density(double ncp) const {
        std::vector<double> d(support_.size());
        double maxD = -kInf;
        for (std::size_t i = 0; i < d.size(); ++i) {
            d[i] = logdc_[i] + std::log(ncp) * support_[i];
            maxD = std::max(maxD, d[i]);
        }
        double sum = 0;
        for (double& v : d) {
            v = std::exp(v - maxD);
            sum += v;
        }
        for (double& v : d) v /= sum;
        return d;
    }
    double mean(double ncp) const {
        if (ncp == 0) return lo_;
        if (std::isinf(ncp)) return hi_;
        const auto d = density(ncp);
        double s = 0;
        for (std::size_t i = 0; i < d.size(); ++i) s += support_[i] * d[i];
        return s;
    }
    /// P(X <= q) or, for the upper tail, P(X >= q) under odds ratio ncp.
    double cdf(double q, double ncp, bool upperTail) const {
        if (ncp == 1) return upperTail ? phyper(x_ - 1, m_, n_, k_, false) : phyper(x_, m_, n_, k_);
        if (ncp == 0) return upperTail ? (q <= lo_ ? 1.0 : 0.0) : (q >= lo_ ? 1.0 : 0.0);
        if (std::isinf(ncp)) return upperTail ? (q <= hi_ ? 1.0 : 0.0) : (q >= hi_ ? 1.0 : 0.0);
        const auto d = density(ncp);
        double s = 0;
        for (std::size_t i = 0; i < d.size(); ++i)
            if (upperTail ? support_[i] >= q : support_[i] <= q) s += d[i];
        return s;
    }

  private:
    double m_, n_, k_, x_, lo_, hi_;
    std::vector<double> support_, logdc_;
};

constexpr double kDoubleEps = std::numeric_limits<double>::epsilon();

/// R's uniroot(f, c(lower, upper)) with the end values computed first.
double rootOf(const std::function<double(double)>& f, double lower, double upper) {
    return uniroot(f, lower, upper, f(lower), f(upper)).x;
}

} // namespace

TestResult fisherTest(const CountTable& table, double confLevel, Alternative alternative) {
    const std::string method = "Fisher's Exact Test for Count Data";
    if (!isRectangular(table) || table.size() < 2 || table.front().size() < 2)
        return failedTest(method, "'x' must have at least 2 rows and columns");
    for (const auto& row : table)
        for (double v : row)
            if (!(v >= 0) || !std::isfinite(v))
                return failedTest(method, "all entries of 'x' must be nonnegative and finite");
    if (table.size() != 2 || table.front().size() != 2)
        return failedTest(method, "only 2 x 2 tables are supported (use chisqTest for r x c)");
    if (!validLevel(confLevel))
        return failedTest(method, "'conf.level' must be a single number between 0 and 1");
    TestResult r;
    r.method = method;
    r.alternative = alternative;
    const double a = std::round(table[0][0]), b = std::round(table[0][1]),
                 c = std::round(table[1][0]), d = std::round(table[1][1]);
    if (a != table[0][0] || b != table[0][1] || c != table[1][0] || d != table[1][1])
        r.warnings.emplace_back("'x' has been rounded to integer");
    const double m = a + c, n = b + d, k = a + b, x = a;
    // The exact distribution is held as one value per possible first cell: bound it (a table read
    // from outside must not make us allocate or compute without limit; R would try and stall).
    constexpr double kMaxSupport = 1e5;
    if (const double support = std::min(k, m) - std::max(0.0, k - n) + 1; support > kMaxSupport)
        return failedTest(method, fmt::format("the table's margins allow {} values of the first "
                                              "cell, more than the {} this exact test enumerates "
                                              "(use chisqTest for counts this large)",
                                              support, kMaxSupport));
    const NoncentralHypergeometric h(m, n, k, x);
    const double lo = h.lo(), hi = h.hi();

    switch (alternative) {
    case Alternative::Less:
        r.p = h.cdf(x, 1, false);
        break;
    case Alternative::Greater:
        r.p = h.cdf(x, 1, true);
        break;
    case Alternative::TwoSided: {
        constexpr double relErr = 1 + 1e-7;
        const auto dens = h.density(1);
        const double dx = dens[static_cast<std::size_t>(x - lo)];
        double p = 0;
        for (double v : dens)
            if (v <= dx * relErr) p += v;
        r.p = p;
        break;
    }
    }

    // Conditional maximum-likelihood estimate of the odds ratio.
    double mle = 1;
    if (x == lo) {
        mle = 0;
    } else if (x == hi) {
        mle = kInf;
    } else {
        const double mu = h.mean(1);
        if (mu > x)
            mle = rootOf([&](double t) { return h.mean(t) - x; }, 0, 1);
        else if (mu < x)
            mle = 1 / rootOf([&](double t) { return h.mean(1 / t) - x; }, kDoubleEps, 1);
    }
    r.estimate = {{"odds ratio", mle}};

    auto upperBound = [&](double alpha) {
        if (x == hi) return kInf;
        const double p = h.cdf(x, 1, false);
        if (p < alpha) return rootOf([&](double t) { return h.cdf(x, t, false) - alpha; }, 0, 1);
        if (p > alpha)
            return 1 /
                   rootOf([&](double t) { return h.cdf(x, 1 / t, false) - alpha; }, kDoubleEps, 1);
        return 1.0;
    };
    auto lowerBound = [&](double alpha) {
        if (x == lo) return 0.0;
        const double p = h.cdf(x, 1, true);
        if (p > alpha) return rootOf([&](double t) { return h.cdf(x, t, true) - alpha; }, 0, 1);
        if (p < alpha)
            return 1 /
                   rootOf([&](double t) { return h.cdf(x, 1 / t, true) - alpha; }, kDoubleEps, 1);
        return 1.0;
    };
    Interval ci;
    ci.level = confLevel;
    switch (alternative) {
    case Alternative::Less:
        ci.lower = 0;
        ci.upper = upperBound(1 - confLevel);
        break;
    case Alternative::Greater:
        ci.lower = lowerBound(1 - confLevel);
        ci.upper = kInf;
        break;
    case Alternative::TwoSided: {
        const double alpha = (1 - confLevel) / 2;
        ci.lower = lowerBound(alpha);
        ci.upper = upperBound(alpha);
        break;
    }
    }
    r.confInt = ci;
    return r;
}

TestResult binomTest(double successes, double trials, double p, Alternative alternative,
                     double confLevel) {
    const std::string method = "Exact binomial test";
    const double x = std::round(successes);
    if (!(successes >= 0) || std::fabs(successes - x) > 1e-7)
        return failedTest(method, "'x' must be nonnegative and integer");
    const double n = std::round(trials);
    if (!(trials >= 1) || std::fabs(trials - n) > 1e-7 || x > n)
        return failedTest(method, "'n' must be a positive integer >= 'x'");
    // Counts beyond 2^53 are not exact in double (R's binom.test would loop for ever on them).
    if (n > 9007199254740992.0)
        return failedTest(method, "'n' must be at most 2^53 = 9007199254740992");
    if (!(p >= 0 && p <= 1))
        return failedTest(method, "'p' must be a single number between 0 and 1");
    if (!validLevel(confLevel))
        return failedTest(method, "'conf.level' must be a single number between 0 and 1");
    TestResult r;
    r.method = method;
    r.alternative = alternative;
    r.statisticName = "number of successes";
    r.statistic = x;
    r.df = {n}; // R's "parameter": number of trials
    switch (alternative) {
    case Alternative::Less:
        r.p = pbinom(x, n, p);
        break;
    case Alternative::Greater:
        r.p = pbinom(x - 1, n, p, false);
        break;
    case Alternative::TwoSided:
        if (p == 0) {
            r.p = x == 0 ? 1 : 0;
        } else if (p == 1) {
            r.p = x == n ? 1 : 0;
        } else {
            constexpr double relErr = 1 + 1e-7;
            const double d = dbinom(x, n, p);
            const double mu = n * p;
            const auto atMost = [&](double i) { return dbinom(i, n, p) <= d * relErr; };
            // How many i in [lo, hi] have dbinom(i) <= d * relErr, as R counts them. The mode
            // lies in [floor(mu), ceil(mu)], so the density only falls away from mu on each side:
            // up to 10^6 terms are counted one by one as R does, beyond that the boundary is
            // found by bisection on the monotone side (work O(log n) for any n, not O(n)).
            const auto countAtMost = [&](double lo, double hi, bool rising) {
                if (hi < lo) return 0.0;
                if (hi - lo <= 1e6) {
                    double y = 0;
                    for (double i = lo; i <= hi; i += 1)
                        if (atMost(i)) y += 1;
                    return y;
                }
                // t counts from the end farthest from mu, where the density is smallest: the
                // condition holds on a prefix of t; bisect for its length.
                const auto at = [&](double t) { return atMost(rising ? lo + t : hi - t); };
                const double last = hi - lo;
                if (!at(0)) return 0.0;
                if (at(last)) return last + 1;
                double a = 0, b = last; // at(a) holds, at(b) does not
                while (b - a > 1) {
                    const double m = std::floor((a + b) / 2);
                    (at(m) ? a : b) = m;
                }
                return a + 1;
            };
            if (x == mu) {
                r.p = 1;
            } else if (x < mu) {
                const double y = countAtMost(std::ceil(mu), n, false);
                r.p = pbinom(x, n, p) + pbinom(n - y, n, p, false);
            } else {
                const double y = countAtMost(0, std::floor(mu), true);
                r.p = pbinom(y - 1, n, p) + pbinom(x - 1, n, p, false);
            }
            r.p = std::min(1.0, r.p);
        }
        break;
    }
    auto pLower = [&](double alpha) { return x == 0 ? 0.0 : qbeta(alpha, x, n - x + 1); };
    auto pUpper = [&](double alpha) { return x == n ? 1.0 : qbeta(1 - alpha, x + 1, n - x); };
    Interval ci;
    ci.level = confLevel;
    switch (alternative) {
    case Alternative::Less:
        ci = {0, pUpper(1 - confLevel), confLevel};
        break;
    case Alternative::Greater:
        ci = {pLower(1 - confLevel), 1, confLevel};
        break;
    case Alternative::TwoSided:
        ci = {pLower((1 - confLevel) / 2), pUpper((1 - confLevel) / 2), confLevel};
        break;
    }
    r.confInt = ci;
    r.estimate = {{"probability of success", x / n}};
    return r;
}

TestResult propTest(std::span<const double> successes, std::span<const double> trials,
                    std::span<const double> p, Alternative alternative, double confLevel,
                    Continuity continuity) {
    std::string method = "proportions test";
    if (successes.size() != trials.size())
        return failedTest(method, "'x' and 'n' must have the same length");
    std::vector<double> x, n, nullP;
    if (!p.empty() && p.size() != successes.size())
        return failedTest(method, "'p' must have the same length as 'x' and 'n'");
    for (std::size_t i = 0; i < successes.size(); ++i) {
        if (std::isnan(successes[i]) || std::isnan(trials[i])) continue; // complete cases
        x.push_back(successes[i]);
        n.push_back(trials[i]);
        if (!p.empty()) nullP.push_back(p[i]);
    }
    const std::size_t k = x.size();
    if (k < 1) return failedTest(method, "not enough data");
    for (std::size_t i = 0; i < k; ++i) {
        if (!(n[i] > 0)) return failedTest(method, "elements of 'n' must be positive");
        if (!(x[i] >= 0)) return failedTest(method, "elements of 'x' must be nonnegative");
        if (x[i] > n[i])
            return failedTest(method, "elements of 'x' must not be greater than those of 'n'");
        if (!std::isfinite(x[i]) || !std::isfinite(n[i]))
            return failedTest(method, "elements of 'x' and 'n' must be finite");
    }
    const bool nullGiven = !nullP.empty() || k == 1;
    if (nullP.empty() && k == 1) nullP = {0.5};
    for (double v : nullP)
        if (!(v > 0 && v < 1)) return failedTest(method, "elements of 'p' must be in (0,1)");
    if (k > 2 || (k == 2 && !p.empty())) alternative = Alternative::TwoSided;
    if (!validLevel(confLevel))
        return failedTest(method, "'conf.level' must be a single number between 0 and 1");

    TestResult r;
    r.alternative = alternative;
    std::vector<double> estimate(k);
    for (std::size_t i = 0; i < k; ++i) estimate[i] = x[i] / n[i];
    double yates = continuity == Continuity::Corrected && k <= 2 ? 0.5 : 0.0;
    double delta = 0;
    if (k == 1) {
        const double z =
            qnorm(alternative == Alternative::TwoSided ? (1 + confLevel) / 2 : confLevel);
        yates = std::min(yates, std::fabs(x[0] - n[0] * nullP[0]));
        const double z22n = z * z / (2 * n[0]);
        double pc = estimate[0] + yates / n[0];
        const double pu =
            pc >= 1 ? 1
                    : (pc + z22n + z * std::sqrt(pc * (1 - pc) / n[0] + z22n / (2 * n[0]))) /
                          (1 + 2 * z22n);
        pc = estimate[0] - yates / n[0];
        const double pl =
            pc <= 0 ? 0
                    : (pc + z22n - z * std::sqrt(pc * (1 - pc) / n[0] + z22n / (2 * n[0]))) /
                          (1 + 2 * z22n);
        switch (alternative) {
        case Alternative::TwoSided:
            r.confInt = Interval{std::max(pl, 0.0), std::min(pu, 1.0), confLevel};
            break;
        case Alternative::Greater:
            r.confInt = Interval{std::max(pl, 0.0), 1, confLevel};
            break;
        case Alternative::Less:
            r.confInt = Interval{0, std::min(pu, 1.0), confLevel};
            break;
        }
    } else if (k == 2 && !nullGiven) {
        delta = estimate[0] - estimate[1];
        const double sumInv = 1 / n[0] + 1 / n[1];
        yates = std::min(yates, std::fabs(delta) / sumInv);
        const double z =
            alternative == Alternative::TwoSided ? qnorm((1 + confLevel) / 2) : qnorm(confLevel);
        const double width = z * std::sqrt(estimate[0] * (1 - estimate[0]) / n[0] +
                                           estimate[1] * (1 - estimate[1]) / n[1]) +
                             yates * sumInv;
        switch (alternative) {
        case Alternative::TwoSided:
            r.confInt =
                Interval{std::max(delta - width, -1.0), std::min(delta + width, 1.0), confLevel};
            break;
        case Alternative::Greater:
            r.confInt = Interval{std::max(delta - width, -1.0), 1, confLevel};
            break;
        case Alternative::Less:
            r.confInt = Interval{-1, std::min(delta + width, 1.0), confLevel};
            break;
        }
    }
    r.method = (k == 1 ? std::string("1-sample proportions test")
                       : fmt::format("{}-sample test for {} proportions", k,
                                     nullGiven ? "given" : "equality of")) +
               (yates != 0 ? " with" : " without") + " continuity correction";
    std::vector<double> pooled;
    double df = 0;
    if (!nullGiven) {
        double sx = 0, sn = 0;
        for (std::size_t i = 0; i < k; ++i) {
            sx += x[i];
            sn += n[i];
        }
        pooled.assign(k, sx / sn);
        df = dbl(k) - 1;
    } else {
        pooled = nullP;
        df = dbl(k);
    }
    double stat = 0;
    bool smallExpected = false;
    for (std::size_t i = 0; i < k; ++i) {
        const double e1 = n[i] * pooled[i], e2 = n[i] * (1 - pooled[i]);
        const double d1 = std::fabs(x[i] - e1) - yates, d2 = std::fabs(n[i] - x[i] - e2) - yates;
        stat += d1 * d1 / e1 + d2 * d2 / e2;
        smallExpected = smallExpected || e1 < 5 || e2 < 5;
    }
    if (smallExpected) r.warnings.emplace_back("Chi-squared approximation may be incorrect");
    r.statisticName = "X-squared";
    r.statistic = stat;
    r.df = {df};
    if (alternative == Alternative::TwoSided) {
        r.p = pchisq(stat, df, false);
    } else {
        const double sign = k == 1 ? (estimate[0] - nullP[0]) : delta;
        const double z = (sign > 0 ? 1.0 : sign < 0 ? -1.0 : 0.0) * std::sqrt(stat);
        r.p = pnorm(z, alternative == Alternative::Less);
    }
    for (std::size_t i = 0; i < k; ++i)
        r.estimate.push_back(
            {k == 1 ? std::string("p") : fmt::format("prop {}", i + 1), estimate[i]});
    return r;
}

Interval wilsonInterval(double successes, double trials, double confLevel, Continuity continuity) {
    if (!(trials > 0) || !(successes >= 0) || successes > trials || !validLevel(confLevel))
        return Interval{kNaN, kNaN, confLevel};
    // Wilson (1927) score interval; with correction as Newcombe (1998), method 4.
    const double n = trials, est = successes / trials;
    const double yates = continuity == Continuity::Corrected ? 0.5 : 0.0;
    const double z = qnorm((1 + confLevel) / 2);
    const double z22n = z * z / (2 * n);
    double pc = est + yates / n;
    const double pu =
        pc >= 1 ? 1
                : (pc + z22n + z * std::sqrt(pc * (1 - pc) / n + z22n / (2 * n))) / (1 + 2 * z22n);
    pc = est - yates / n;
    const double pl =
        pc <= 0 ? 0
                : (pc + z22n - z * std::sqrt(pc * (1 - pc) / n + z22n / (2 * n))) / (1 + 2 * z22n);
    return Interval{std::max(pl, 0.0), std::min(pu, 1.0), confLevel};
}

double phiCoefficient(const CountTable& t) {
    if (t.size() != 2 || t[0].size() != 2 || t[1].size() != 2) return kNaN;
    const double r1 = t[0][0] + t[0][1], r2 = t[1][0] + t[1][1];
    const double c1 = t[0][0] + t[1][0], c2 = t[0][1] + t[1][1];
    const double den = std::sqrt(r1 * r2 * c1 * c2);
    return den > 0 ? (t[0][0] * t[1][1] - t[0][1] * t[1][0]) / den : kNaN;
}

double cramersV(const CountTable& table) {
    const TestResult chi = chisqTest(table, Continuity::Uncorrected);
    if (!chi.ok() || table.size() < 2 || table.front().size() < 2) return kNaN;
    double n = 0;
    for (const auto& row : table)
        for (double v : row) n += v;
    const double q = dbl(std::min(table.size(), table.front().size())) - 1;
    return std::sqrt(chi.statistic / (n * q));
}

} // namespace underfoot::analysis
