// SPDX-License-Identifier: GPL-3.0-or-later
// wilcox.test, kruskal.test, friedman.test and Spearman's cor.test, following R 4.2.
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

namespace underfoot::analysis {

namespace numerics {

/// Exact null distribution of the signed-rank statistic V for n untied, non-zero values:
/// counts of subsets of {1..n} with each sum (exact in double for n < 50: at most 2^49).
std::vector<double> signedRankCounts(std::size_t n) {
    const std::size_t maxSum = n * (n + 1) / 2;
    std::vector<double> c(maxSum + 1, 0.0);
    c[0] = 1;
    for (std::size_t i = 1; i <= n; ++i)
        for (std::size_t s = std::min(maxSum, i * (i + 1) / 2); s >= i; --s) c[s] += c[s - i];
    return c;
}

/// Exact null distribution of the rank-sum statistic W (Mann-Whitney U) for sample sizes m, n:
/// coefficients of the Gaussian binomial [m + n choose m]_q, built with additions only.
std::vector<double> rankSumCounts(std::size_t m, std::size_t n) {
    if (m > n) std::swap(m, n);
    const std::size_t maxU = m * n;
    // g[j] = [N choose j]_q as the polynomial coefficients, for the current N.
    std::vector<std::vector<double>> g(m + 1);
    g[0] = {1.0};
    for (std::size_t total = 1; total <= m + n; ++total) {
        for (std::size_t j = std::min(m, total); j >= 1; --j) {
            // [N choose j] = [N-1 choose j-1] + q^j [N-1 choose j]
            const std::size_t degree = j * (total - j);
            std::vector<double> next(std::min(degree, maxU) + 1, 0.0);
            const auto& prev = g[j - 1];
            for (std::size_t s = 0; s < prev.size() && s < next.size(); ++s) next[s] += prev[s];
            const auto& same = g[j];
            for (std::size_t s = 0; s < same.size() && s + j < next.size(); ++s)
                next[s + j] += same[s];
            g[j] = std::move(next);
        }
    }
    return g[m];
}

} // namespace numerics

using namespace numerics;

namespace {

// Limits of the exact distributions when the caller forces exact p-values beyond R's defaults
// (n < 50): counts stay finite in double and the time stays under about a second.
constexpr std::size_t kMaxExactSignedRankN = 1000;
constexpr std::size_t kMaxExactRankSumProduct = 10000;

/// P(X <= q) or P(X > q) from a table of counts, summing the requested tail directly.
double tailProbability(const std::vector<double>& counts, double q, bool lowerTail) {
    const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
    const double qf = std::floor(q + 1e-7);
    double sum = 0;
    for (std::size_t s = 0; s < counts.size(); ++s)
        if (lowerTail ? dbl(s) <= qf : dbl(s) > qf) sum += counts[s];
    return sum / total;
}

double normalPValue(double z, Alternative alternative) {
    if (std::isnan(z)) return kNaN;
    switch (alternative) {
    case Alternative::Less:
        return pnorm(z);
    case Alternative::Greater:
        return pnorm(z, false);
    case Alternative::TwoSided:
        break;
    }
    return 2 * std::min(pnorm(z), pnorm(z, false));
}

double correction(double z, Alternative alternative, Continuity continuity) {
    if (continuity == Continuity::Uncorrected) return 0;
    switch (alternative) {
    case Alternative::Less:
        return -0.5;
    case Alternative::Greater:
        return 0.5;
    case Alternative::TwoSided:
        break;
    }
    return z > 0 ? 0.5 : z < 0 ? -0.5 : 0.0;
}

bool hasTies(std::span<const double> ranks) {
    std::vector<double> s(ranks.begin(), ranks.end());
    std::sort(s.begin(), s.end());
    return std::adjacent_find(s.begin(), s.end()) != s.end();
}

TestResult signedRank(std::vector<double> x, const WilcoxonOptions& o) {
    TestResult r;
    r.method = "Wilcoxon signed rank test";
    r.statisticName = "V";
    r.alternative = o.alternative;
    if (x.empty()) return failedTest(r.method, "not enough (non-missing) 'x' observations");
    for (double& v : x) v -= o.mu;
    const bool zeroes = std::any_of(x.begin(), x.end(), [](double v) { return v == 0; });
    std::erase(x, 0.0);
    const std::size_t count = x.size();
    const double n = dbl(count);
    const bool exact = o.exactness == Exactness::Auto ? n < 50 : o.exactness == Exactness::Exact;
    std::vector<double> absX(count);
    for (std::size_t i = 0; i < count; ++i) absX[i] = std::fabs(x[i]);
    const auto ranks = averageRanks(absX);
    double v = 0;
    for (std::size_t i = 0; i < count; ++i)
        if (x[i] > 0) v += ranks[i];
    r.statistic = v;
    const bool ties = hasTies(ranks);
    if (exact && !ties && !zeroes) {
        if (count > kMaxExactSignedRankN)
            return failedTest(r.method, fmt::format("exact p-value available for n <= {} only; "
                                                    "use the normal approximation",
                                                    kMaxExactSignedRankN));
        r.method = "Wilcoxon signed rank exact test";
        const auto counts = signedRankCounts(count);
        switch (o.alternative) {
        case Alternative::TwoSided: {
            const double p = v > n * (n + 1) / 4 ? tailProbability(counts, v - 1, false)
                                                 : tailProbability(counts, v, true);
            r.p = std::min(2 * p, 1.0);
            break;
        }
        case Alternative::Greater:
            r.p = tailProbability(counts, v - 1, false);
            break;
        case Alternative::Less:
            r.p = tailProbability(counts, v, true);
            break;
        }
        return r;
    }
    double z = v - n * (n + 1) / 4;
    const double sigma = std::sqrt(n * (n + 1) * (2 * n + 1) / 24 - tieCorrectionSum(ranks) / 48);
    if (o.continuity == Continuity::Corrected) r.method += " with continuity correction";
    z = (z - correction(z, o.alternative, o.continuity)) / sigma;
    r.p = normalPValue(z, o.alternative);
    if (exact && ties) r.warnings.emplace_back("cannot compute exact p-value with ties");
    if (exact && zeroes) r.warnings.emplace_back("cannot compute exact p-value with zeroes");
    return r;
}

} // namespace

TestResult wilcoxonTest(std::span<const double> x, const WilcoxonOptions& options) {
    if (!std::isfinite(options.mu))
        return failedTest("Wilcoxon signed rank test", "'mu' must be a single number");
    auto xs = dropMissing(x);
    if (anyNonFinite(xs)) return failedTest("Wilcoxon signed rank test", "'x' must be finite");
    return signedRank(std::move(xs), options);
}

TestResult wilcoxonTest(std::span<const double> x, std::span<const double> y,
                        const WilcoxonOptions& o) {
    if (!std::isfinite(o.mu))
        return failedTest("Wilcoxon rank sum test", "'mu' must be a single number");
    if (o.pairing == Pairing::Paired) {
        if (x.size() != y.size())
            return failedTest("Wilcoxon signed rank test", "'x' and 'y' must have the same length");
        std::vector<double> d;
        for (std::size_t i = 0; i < x.size(); ++i)
            if (!std::isnan(x[i]) && !std::isnan(y[i])) d.push_back(x[i] - y[i]);
        if (anyNonFinite(d))
            return failedTest("Wilcoxon signed rank test", "values must be finite");
        return signedRank(std::move(d), o);
    }
    TestResult r;
    r.method = "Wilcoxon rank sum test";
    r.statisticName = "W";
    r.alternative = o.alternative;
    const auto xs = dropMissing(x), ys = dropMissing(y);
    if (anyNonFinite(xs) || anyNonFinite(ys)) return failedTest(r.method, "values must be finite");
    if (xs.empty()) return failedTest(r.method, "not enough (non-missing) 'x' observations");
    if (ys.empty()) return failedTest(r.method, "not enough 'y' observations");
    std::vector<double> combined;
    for (double v : xs) combined.push_back(v - o.mu);
    combined.insert(combined.end(), ys.begin(), ys.end());
    const auto ranks = averageRanks(combined);
    const double nx = dbl(xs.size()), ny = dbl(ys.size());
    const bool exact =
        o.exactness == Exactness::Auto ? (nx < 50 && ny < 50) : o.exactness == Exactness::Exact;
    double w = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) w += ranks[i];
    w -= nx * (nx + 1) / 2;
    r.statistic = w;
    const bool ties = hasTies(ranks);
    if (exact && !ties) {
        if (xs.size() * ys.size() > kMaxExactRankSumProduct)
            return failedTest(r.method, fmt::format("exact p-value available for m * n <= {} only; "
                                                    "use the normal approximation",
                                                    kMaxExactRankSumProduct));
        r.method = "Wilcoxon rank sum exact test";
        const auto counts = rankSumCounts(xs.size(), ys.size());
        switch (o.alternative) {
        case Alternative::TwoSided: {
            const double p = w > nx * ny / 2 ? tailProbability(counts, w - 1, false)
                                             : tailProbability(counts, w, true);
            r.p = std::min(2 * p, 1.0);
            break;
        }
        case Alternative::Greater:
            r.p = tailProbability(counts, w - 1, false);
            break;
        case Alternative::Less:
            r.p = tailProbability(counts, w, true);
            break;
        }
        return r;
    }
    double z = w - nx * ny / 2;
    const double sigma = std::sqrt(
        (nx * ny / 12) * ((nx + ny + 1) - tieCorrectionSum(ranks) / ((nx + ny) * (nx + ny - 1))));
    if (o.continuity == Continuity::Corrected) r.method += " with continuity correction";
    z = (z - correction(z, o.alternative, o.continuity)) / sigma;
    r.p = normalPValue(z, o.alternative);
    if (exact && ties) r.warnings.emplace_back("cannot compute exact p-value with ties");
    return r;
}

std::vector<PairwiseResult> pairwiseWilcoxon(const std::vector<std::vector<double>>& groups,
                                             PAdjustMethod method, const WilcoxonOptions& options) {
    std::vector<PairwiseResult> out;
    for (std::size_t second = 0; second + 1 < groups.size(); ++second)
        for (std::size_t first = second + 1; first < groups.size(); ++first)
            out.push_back(
                {first, second, wilcoxonTest(groups[first], groups[second], options), kNaN});
    std::vector<double> p;
    for (const auto& r : out) p.push_back(r.test.ok() ? r.test.p : kNaN);
    const auto adjusted = pAdjust(p, method);
    for (std::size_t i = 0; i < out.size(); ++i) out[i].pAdjusted = adjusted[i];
    return out;
}

TestResult kruskalTest(const std::vector<std::vector<double>>& groups) {
    const std::string method = "Kruskal-Wallis rank sum test";
    if (groups.size() < 2) return failedTest(method, "'x' must be a list with at least 2 elements");
    std::vector<double> all;
    std::vector<std::size_t> sizes;
    for (const auto& g : groups) {
        const auto values = dropMissing(g);
        if (anyNonFinite(values)) return failedTest(method, "values must be finite");
        if (values.empty()) return failedTest(method, "all groups must contain data");
        sizes.push_back(values.size());
        all.insert(all.end(), values.begin(), values.end());
    }
    const double n = dbl(all.size());
    if (all.size() < 2) return failedTest(method, "not enough observations");
    const auto ranks = averageRanks(all);
    double stat = 0;
    std::size_t offset = 0;
    for (std::size_t size : sizes) {
        double sum = 0;
        for (std::size_t i = 0; i < size; ++i) sum += ranks[offset + i];
        stat += sum * sum / dbl(size);
        offset += size;
    }
    stat =
        (12 * stat / (n * (n + 1)) - 3 * (n + 1)) / (1 - tieCorrectionSum(all) / (n * n * n - n));
    TestResult r;
    r.method = method;
    r.statisticName = "Kruskal-Wallis chi-squared";
    r.statistic = stat;
    r.df = {dbl(groups.size()) - 1};
    r.p = pchisq(stat, r.df[0], false);
    return r;
}

TestResult friedmanTest(const std::vector<std::vector<double>>& rows) {
    const std::string method = "Friedman rank sum test";
    if (rows.empty()) return failedTest(method, "'y' must have at least one row");
    const std::size_t k = rows.front().size();
    for (const auto& row : rows)
        if (row.size() != k)
            return failedTest(method, "'y' must be a matrix: rows of equal length");
    if (k < 2) return failedTest(method, "'y' must have at least 2 columns (conditions)");
    std::vector<double> columnRankSums(k, 0.0);
    double n = 0, tieSum = 0;
    for (const auto& row : rows) {
        if (std::any_of(row.begin(), row.end(), [](double v) { return std::isnan(v); }))
            continue; // complete cases only
        if (anyNonFinite(row)) return failedTest(method, "values must be finite");
        const auto ranks = averageRanks(row);
        for (std::size_t j = 0; j < k; ++j) columnRankSums[j] += ranks[j];
        tieSum += tieCorrectionSum(row);
        n += 1;
    }
    if (n == 0) return failedTest(method, "no complete rows (blocks) to test");
    const double kd = dbl(k);
    double ss = 0;
    for (double s : columnRankSums) ss += (s - n * (kd + 1) / 2) * (s - n * (kd + 1) / 2);
    TestResult r;
    r.method = method;
    r.statisticName = "Friedman chi-squared";
    r.statistic = 12 * ss / (n * kd * (kd + 1) - tieSum / (kd - 1));
    r.df = {kd - 1};
    r.p = pchisq(r.statistic, r.df[0], false);
    return r;
}

namespace {

/// P(S >= is) (upper) or P(S < is) (lower) for Spearman's S = sum of squared rank differences,
/// algorithm AS 89 (Best & Roberts 1975) as R's prho: exact enumeration of the permutations
/// for n <= 9, Edgeworth series beyond.
double spearmanTail(std::size_t n, double is, bool lowerTail) {
    double pv = lowerTail ? 0.0 : 1.0;
    if (n <= 1 || is <= 0) return pv;
    const double nd = dbl(n);
    const double n3 = nd * (nd * nd - 1) / 3; // (n^3 - n) / 3: the largest S
    if (is > n3) return 1 - pv;
    if (n <= 9) {
        std::vector<int> perm(n);
        std::iota(perm.begin(), perm.end(), 1);
        double total = 0, atLeast = 0;
        do {
            int s = 0;
            for (std::size_t i = 0; i < n; ++i) {
                const int d = static_cast<int>(i) + 1 - perm[i];
                s += d * d;
            }
            total += 1;
            if (is <= s) atLeast += 1;
        } while (std::next_permutation(perm.begin(), perm.end()));
        if (is == n3) atLeast = 1; // AS 89 as amended in R (".eq." of the paper)
        return (lowerTail ? total - atLeast : atLeast) / total;
    }
    constexpr double c1 = .2274, c2 = .2531, c3 = .1745, c4 = .0758, c5 = .1033, c6 = .3932,
                     c7 = .0879, c8 = .0151, c9 = .0072, c10 = .0831, c11 = .0131, c12 = 4.6e-4;
    const double b = 1 / nd;
    const double x = (6 * (is - 1) * b / (nd * nd - 1) - 1) * std::sqrt(nd - 1);
    double y = x * x;
    const double u = x * b *
                     (c1 + b * (c2 + c3 * b) +
                      y * (-c4 + b * (c5 + c6 * b) -
                           y * b * (c7 + c8 * b - y * (c9 - c10 * b + y * b * (c11 - c12 * y)))));
    y = u / std::exp(y / 2);
    pv = (lowerTail ? -y : y) + pnorm(x, lowerTail);
    return std::clamp(pv, 0.0, 1.0);
}

double pearson(std::span<const double> x, std::span<const double> y) {
    const double mx = mean(x), my = mean(y);
    long double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
    }
    if (sxx == 0 || syy == 0) return kNaN; // R: "the standard deviation is zero" -> NA
    return static_cast<double>(sxy / std::sqrt(sxx * syy));
}

} // namespace

TestResult spearmanTest(std::span<const double> x, std::span<const double> y,
                        Alternative alternative, Exactness exactness) {
    TestResult r;
    r.method = "Spearman's rank correlation rho";
    r.statisticName = "S";
    r.alternative = alternative;
    if (x.size() != y.size()) return failedTest(r.method, "'x' and 'y' must have the same length");
    std::vector<double> xs, ys;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (std::isfinite(x[i]) && std::isfinite(y[i])) { // complete.cases drops NA, keeps Inf;
            xs.push_back(x[i]);                           // we reject Inf below
            ys.push_back(y[i]);
        } else if (!std::isnan(x[i]) && !std::isnan(y[i])) {
            return failedTest(r.method, "values must be finite");
        }
    const std::size_t count = xs.size();
    const double n = dbl(count);
    if (count < 2) return failedTest(r.method, "not enough finite observations");
    const auto rx = averageRanks(xs), ry = averageRanks(ys);
    const double rho = pearson(rx, ry);
    r.estimate = {{"rho", rho}};
    if (!std::isfinite(rho)) {
        r.warnings.emplace_back("the standard deviation is zero");
        return r; // R: estimate NA, statistic NA, p NA
    }
    bool exact = exactness != Exactness::Approximate;
    const bool ties = hasTies(xs) || hasTies(ys);
    if (ties && exact) {
        exact = false;
        r.warnings.emplace_back("Cannot compute exact p-value with ties");
    }
    const double q = (n * n * n - n) * (1 - rho) / 6;
    r.statistic = q;
    auto pspearman = [&](bool lowerTail) {
        if (count <= 1290 && exact)
            return spearmanTail(count, std::round(q) + 2 * (lowerTail ? 1 : 0), lowerTail);
        const double den = n * (n * n - 1) / 6;
        const double rr = 1 - q / den;
        return pt(rr / std::sqrt((1 - rr * rr) / (n - 2)), n - 2, !lowerTail);
    };
    switch (alternative) {
    case Alternative::TwoSided: {
        const double p = q > (n * n * n - n) / 6 ? pspearman(false) : pspearman(true);
        r.p = std::min(2 * p, 1.0);
        break;
    }
    case Alternative::Greater:
        r.p = pspearman(true);
        break;
    case Alternative::Less:
        r.p = pspearman(false);
        break;
    }
    return r;
}

} // namespace underfoot::analysis
