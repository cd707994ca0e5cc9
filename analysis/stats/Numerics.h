// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Numerical helpers shared by the tests: R's root finder, ranks, distributions with NaN
/// instead of exceptions, and mean/variance as R computes them.
#include <cstddef>
#include <functional>
#include <limits>
#include <span>
#include <vector>

namespace underfoot::analysis::numerics {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Converts a count to double without a narrowing warning.
template <typename T>
constexpr double dbl(T v) {
    return static_cast<double>(v);
}

/// Result of `uniroot`.
struct Root {
    double x = kNaN;
    bool converged = false;
};

/// Brent's zero finder with R's `uniroot` defaults (tol = eps^0.25, maxiter = 1000), so that
/// estimates computed by root finding (Fisher's conditional MLE and its interval) agree with R
/// to the last printed digit. Source: Brent (1973), as in R's zeroin.c (Forsythe, Malcolm,
/// Moler 1977). fLower/fUpper are f at the ends; they must have opposite signs.
Root uniroot(const std::function<double(double)>& f, double lower, double upper, double fLower,
             double fUpper, double tolerance = 1.220703125e-4, int maxIterations = 1000);

/// R's rank(x) with ties.method = "average" (1-based ranks).
std::vector<double> averageRanks(std::span<const double> x);

/// Exact null distribution of the signed-rank statistic V = 0..n(n+1)/2 for n untied,
/// non-zero values (R's csignrank): counts of subsets of {1..n} with each sum.
std::vector<double> signedRankCounts(std::size_t n);

/// Exact null distribution of the rank-sum statistic W = 0..mn (Mann-Whitney U; R's cwilcox).
std::vector<double> rankSumCounts(std::size_t m, std::size_t n);

/// Sizes of the groups of tied values (every group, including singletons).
std::vector<double> tieGroupSizes(std::span<const double> x);

/// Sum over tie groups of t^3 - t.
double tieCorrectionSum(std::span<const double> x);

/// Mean as R computes it (long double accumulation with one refinement pass).
double mean(std::span<const double> x);

/// Sample variance (n - 1 denominator), two-pass.
double variance(std::span<const double> x);

/// Median (R's median: mean of the two middle values for even n).
double median(std::span<const double> x);

/// True when any value is NaN or infinite.
bool anyNonFinite(std::span<const double> x);

/// Copy of x without NaN values (R drops NA before testing).
std::vector<double> dropMissing(std::span<const double> x);

// Distribution functions; NaN on invalid arguments, never an exception.
double pnorm(double x, bool lowerTail = true);
double qnorm(double p, bool lowerTail = true);
double pt(double t, double df, bool lowerTail = true);
double qt(double p, double df, bool lowerTail = true);
double pchisq(double x, double df, bool lowerTail = true);
double pf(double x, double df1, double df2, bool lowerTail = true);
double qbeta(double p, double a, double b);
double dbinom(double x, double n, double p);
double pbinom(double x, double n, double p, bool lowerTail = true);
/// log of the hypergeometric density: x white balls drawn in k draws from m white and n black.
double logDhyper(double x, double m, double n, double k);
double phyper(double x, double m, double n, double k, bool lowerTail = true);

} // namespace underfoot::analysis::numerics
