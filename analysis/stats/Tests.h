// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Statistical tests that reproduce R's defaults (stats package 4.2, car::leveneTest).
///
/// Every function mirrors one R call; the comment names it. Missing values are NaN and are
/// dropped as R drops NA; infinite values are rejected with an error. Where R stops, the result
/// carries R's message in `error`; where R returns NaN or NA, so does the result.
#include "analysis/stats/TestResult.h"

#include <limits>
#include <span>
#include <vector>

namespace underfoot::analysis {

/// A table of counts, row-major: table[row][column].
using CountTable = std::vector<std::vector<double>>;

/// Whether two samples are paired (R's `paired`).
enum class Pairing { Independent, Paired };
/// Variance assumption of the two-sample t-test (R's `var.equal`).
enum class Variance { Welch, Equal };
/// Exact or normal-approximation p-values of rank tests (R's `exact`: NULL, TRUE, FALSE).
enum class Exactness { Auto, Exact, Approximate };
/// Centre of Levene's test (car::leveneTest `center`): median = Brown-Forsythe, mean = Levene.
enum class LeveneCenter { Median, Mean };
/// Multiple-comparison adjustment (R's p.adjust `method`).
enum class PAdjustMethod { Holm, Bonferroni, Hochberg, BenjaminiHochberg, None };

/// chisq.test(table, correct): Pearson's test of independence on an r x c table, with Yates'
/// correction on 2 x 2 tables unless `Continuity::Uncorrected`.
TestResult chisqTest(const CountTable& table, Continuity continuity = Continuity::Corrected);

/// chisq.test(x, p = p): goodness of fit to the probabilities p (uniform when empty).
TestResult chisqGoodnessOfFit(std::span<const double> counts, std::span<const double> p = {});

/// fisher.test(table, conf.level, alternative) on a 2 x 2 table: exact p-value, conditional
/// maximum-likelihood odds ratio and its interval, found with R's root finder.
TestResult fisherTest(const CountTable& table, double confLevel = 0.95,
                      Alternative alternative = Alternative::TwoSided);

/// Options of t.test.
struct TTestOptions {
    Alternative alternative = Alternative::TwoSided;
    double mu = 0.0;
    Pairing pairing = Pairing::Independent;
    Variance variance = Variance::Welch;
    double confLevel = 0.95;
};
/// t.test(x, mu, conf.level, alternative): one-sample t-test.
TestResult tTest(std::span<const double> x, const TTestOptions& options = {});
/// t.test(x, y, ...): Welch (default), Student (`Variance::Equal`) or paired t-test.
TestResult tTest(std::span<const double> x, std::span<const double> y,
                 const TTestOptions& options = {});

/// Options of wilcox.test (R's defaults; no confidence interval, as R's default conf.int=FALSE).
struct WilcoxonOptions {
    Alternative alternative = Alternative::TwoSided;
    double mu = 0.0;
    Pairing pairing = Pairing::Independent;
    Continuity continuity = Continuity::Corrected;
    Exactness exactness = Exactness::Auto;
};
/// wilcox.test(x, mu): one-sample signed-rank test (exact for n < 50 without ties or zeros).
TestResult wilcoxonTest(std::span<const double> x, const WilcoxonOptions& options = {});
/// wilcox.test(x, y): rank-sum test, or signed-rank on x - y when paired.
TestResult wilcoxonTest(std::span<const double> x, std::span<const double> y,
                        const WilcoxonOptions& options = {});

/// One pair of a pairwise comparison: group `first` against group `second` (first > second).
struct PairwiseResult {
    std::size_t first = 0;
    std::size_t second = 0;
    TestResult test;
    double pAdjusted = std::numeric_limits<double>::quiet_NaN();
};

/// pairwise.wilcox.test(x, g, paired, p.adjust.method): every later group against every earlier
/// one, in R's order ((2,1), (3,1), (3,2), ...; 0-based here), p-values adjusted together.
/// With `Pairing::Paired` the groups are conditions measured on the same subjects, in order.
std::vector<PairwiseResult> pairwiseWilcoxon(const std::vector<std::vector<double>>& groups,
                                             PAdjustMethod method = PAdjustMethod::Holm,
                                             const WilcoxonOptions& options = {});

/// kruskal.test(list(...)): Kruskal-Wallis rank sum test over groups.
TestResult kruskalTest(const std::vector<std::vector<double>>& groups);

/// friedman.test(matrix): rows = blocks (subjects), columns = conditions; incomplete rows
/// (any NaN) are dropped as R drops them.
TestResult friedmanTest(const std::vector<std::vector<double>>& rows);

/// cor.test(x, y, method = "spearman"): rho, S and R's p-value (exact permutations for n <= 9,
/// AS 89 Edgeworth series for n <= 1290 without ties, t approximation otherwise).
TestResult spearmanTest(std::span<const double> x, std::span<const double> y,
                        Alternative alternative = Alternative::TwoSided,
                        Exactness exactness = Exactness::Auto);

/// p.adjust(p, method); NaN entries stay NaN and are not counted in n, as R's NA.
std::vector<double> pAdjust(std::span<const double> p, PAdjustMethod method);

/// shapiro.test(x): Shapiro-Wilk W and its p-value (Royston 1995, algorithm AS R94).
TestResult shapiroTest(std::span<const double> x);

/// car::leveneTest(y ~ group, center): one-way ANOVA on absolute deviations from each group's
/// median (Brown-Forsythe, the default) or mean (Levene). df = (k - 1, N - k).
TestResult leveneTest(const std::vector<std::vector<double>>& groups,
                      LeveneCenter center = LeveneCenter::Median);

/// binom.test(x, n, p, alternative, conf.level): exact test with Clopper-Pearson interval.
TestResult binomTest(double successes, double trials, double p = 0.5,
                     Alternative alternative = Alternative::TwoSided, double confLevel = 0.95);

/// prop.test(x, n, p, alternative, conf.level, correct). `p` empty = R's NULL (0.5 for one
/// sample, equality for several).
TestResult propTest(std::span<const double> successes, std::span<const double> trials,
                    std::span<const double> p = {}, Alternative alternative = Alternative::TwoSided,
                    double confLevel = 0.95, Continuity continuity = Continuity::Corrected);

/// Wilson score interval of a proportion, as prop.test(x, n, correct = FALSE)$conf.int
/// (or with continuity correction when asked). n = 0 gives NaN bounds.
Interval wilsonInterval(double successes, double trials, double confLevel = 0.95,
                        Continuity continuity = Continuity::Uncorrected);

/// Cohen's d of two independent samples with the pooled standard deviation.
double cohensD(std::span<const double> x, std::span<const double> y);

/// Phi coefficient of a 2 x 2 table (signed: ad - bc over the root of the margins' product).
double phiCoefficient(const CountTable& table);

/// Cramér's V of an r x c table (uncorrected chi-square).
double cramersV(const CountTable& table);

// ---------------------------------------------------------------- the further tests of R

/// Largest table total and number of tables with the observed margins that fisherTestRxC
/// enumerates; beyond them it refuses with a message (as R reports FEXACT's workspace limit).
inline constexpr double kMaxFisherRxCTotal = 1000;
inline constexpr double kMaxFisherRxCTables = 1e8;

/// fisher.test(table) on an r x c table (any size >= 2 x 2): two-sided exact p-value, the sum
/// of the probabilities of every table with the observed margins that is at most as probable as
/// the observed one (relative tolerance 1e-7, as R's FEXACT). Enumerates the tables; refuses
/// totals above kMaxFisherRxCTotal or more than `maxTables` tables (about 4e7 tables a second
/// here). No estimate.
TestResult fisherTestRxC(const CountTable& table, double maxTables = kMaxFisherRxCTables);

/// Largest n for which kendallTest computes the exact distribution (R's default: n < 50).
inline constexpr std::size_t kMaxExactKendallN = 100;

/// cor.test(x, y, method = "pearson", alternative, conf.level): r, t on n - 2 df, p, and the
/// Fisher-z interval (for n > 3, as R).
TestResult pearsonTest(std::span<const double> x, std::span<const double> y,
                       Alternative alternative = Alternative::TwoSided, double confLevel = 0.95);

/// cor.test(x, y, method = "kendall", alternative, exact, continuity): tau-b; exact p (statistic
/// T) for n < 50 without ties, otherwise the normal approximation z with R's tie-corrected
/// variance (and continuity correction when asked; R's default continuity = FALSE).
TestResult kendallTest(std::span<const double> x, std::span<const double> y,
                       Alternative alternative = Alternative::TwoSided,
                       Exactness exactness = Exactness::Auto,
                       Continuity continuity = Continuity::Uncorrected);

/// wilcox.test(x, mu, conf.int = TRUE, conf.level): the signed-rank test of wilcoxonTest plus
/// the Hodges-Lehmann "(pseudo)median" and its interval: exact (Walsh averages at qsignrank's
/// quantiles) when the p-value is exact without ties or zeros, else R's inversion of the
/// normal approximation with uniroot(tol = 1e-4), with R's level adjustments and warnings.
TestResult wilcoxonTestCi(std::span<const double> x, const WilcoxonOptions& options = {},
                          double confLevel = 0.95);
/// wilcox.test(x, y, conf.int = TRUE, ...): paired (signed rank on x - y) or two-sample
/// ("difference in location": exact from the m n differences and qwilcox without ties,
/// otherwise the normal approximation inverted with uniroot).
TestResult wilcoxonTestCi(std::span<const double> x, std::span<const double> y,
                          const WilcoxonOptions& options = {}, double confLevel = 0.95);

} // namespace underfoot::analysis
