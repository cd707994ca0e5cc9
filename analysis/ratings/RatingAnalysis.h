// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The analysis of rating studies in the form of the gait sonification paper (004): per scale,
/// medians and IQRs per cell (stimulus), Shapiro-Wilk and Levene checks, a Friedman test across
/// the cells, planned Wilcoxon signed-rank comparisons (cells that differ in exactly one factor)
/// with Holm correction, main effects per factor on each participant's median over the other
/// factors, Kruskal-Wallis (and Holm-corrected Mann-Whitney) tests across participant groups,
/// and Spearman correlations between scales.
///
/// Each participant contributes one value per cell: the mean of its ratings of that stimulus on
/// that scale (the paper averages the two ratings of each clip). Within-subject tests use the
/// participants with a value in every compared cell (complete cases, as R and SPSS).
#include "analysis/ratings/RatingData.h"
#include "analysis/stats/OrdinalMixed.h"
#include "analysis/stats/TestResult.h"

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// Quartiles of R's quantile(type = 7) (the default of R and of boxplot.stats' fivenum differs:
/// see docs/reference/statistics.md; SPSS's "weighted average" is type 6).
double quantileType7(std::vector<double> values, double probability);

/// Tukey box-plot statistics of one cell, with the paper's outlier classes: outliers beyond
/// 1.5 IQR and up to 3 IQR from the box, extremes beyond 3 IQR.
struct BoxStats {
    std::size_t n = 0;
    double median = std::numeric_limits<double>::quiet_NaN();
    double q1 = std::numeric_limits<double>::quiet_NaN();
    double q3 = std::numeric_limits<double>::quiet_NaN();
    double whiskerLow = std::numeric_limits<double>::quiet_NaN();
    double whiskerHigh = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> outliers;
    std::vector<double> extremes;
};
BoxStats boxStats(const std::vector<double>& values);

/// A Wilcoxon signed-rank comparison reported as SPSS reports it: Z from the normal
/// approximation with tie correction and no continuity correction, zero differences dropped,
/// signed negative (computed from the smaller rank sum); p two-sided from that Z.
struct SignedRankZ {
    std::size_t n = 0;   ///< pairs with a non-zero difference
    double vPlus = 0.0;  ///< sum of ranks of positive differences (a - b > 0): R's V
    double vMinus = 0.0; ///< sum of ranks of negative differences
    double z = std::numeric_limits<double>::quiet_NaN();
    double p = std::numeric_limits<double>::quiet_NaN();
    double effectR = std::numeric_limits<double>::quiet_NaN(); ///< |z| / sqrt(number of pairs)
};
SignedRankZ signedRankZ(const std::vector<double>& a, const std::vector<double>& b);

/// Options of the analysis.
struct RatingAnalysisOptions {
    double alpha = 0.05;
    /// Fields of the participant table to compare groups on (empty: every grouping field).
    std::vector<std::string> groupingFields;
};

/// One cell (stimulus) of a scale.
struct RatingCell {
    std::string stimulus;
    std::map<std::string, std::string> factors;
    /// participant -> mean rating.
    std::map<std::string, double> values;
    BoxStats box;
    TestResult shapiro;
};

/// One paired comparison.
struct PairedComparison {
    std::string first; ///< cell or level name
    std::string second;
    /// What differs ("depth at cadence=80"), or the factor of a main effect.
    std::string context;
    double medianFirst = std::numeric_limits<double>::quiet_NaN();
    double medianSecond = std::numeric_limits<double>::quiet_NaN();
    std::size_t pairs = 0;
    SignedRankZ test;
    double pHolm = std::numeric_limits<double>::quiet_NaN();
};

/// A Friedman test across conditions (or one Wilcoxon test when there are only two).
struct OmnibusTest {
    std::string name;
    std::vector<std::string> conditions;
    std::size_t participants = 0;
    TestResult result;
};

/// A factor's main effect: each participant's median over the other factors, per level.
struct FactorEffect {
    std::string factor;
    std::vector<std::string> levels;
    std::vector<BoxStats> levelStats;
    OmnibusTest omnibus;
    std::vector<PairedComparison> pairs;
};

/// Participant groups compared on each participant's median rating of a scale.
struct GroupComparison {
    std::string field;
    struct Group {
        std::string level;
        std::size_t n = 0;
        double median = std::numeric_limits<double>::quiet_NaN();
        double q1 = std::numeric_limits<double>::quiet_NaN();
        double q3 = std::numeric_limits<double>::quiet_NaN();
    };
    std::vector<Group> groups;
    TestResult kruskal;
    /// Holm-corrected Mann-Whitney tests (only when Kruskal-Wallis is significant).
    struct Pair {
        std::string first, second;
        TestResult test;
        double pHolm = std::numeric_limits<double>::quiet_NaN();
    };
    std::vector<Pair> pairs;
};

/// The stimulus (cell) effect on every rating of a scale by mixed models, the participant as a
/// random intercept, beside the Friedman test of the cells (analysis/ratings/RatingModels.h).
struct ScaleModels {
    MixedModelResult lmm;    ///< lmerTest::lmer(rating ~ stimulus + (1 | participant))
    OrdinalMixedResult clmm; ///< ordinal::clmm(ordered(rating) ~ stimulus + (1 | participant))
    std::string clmmSkipped; ///< why the clmm was not fitted (e.g. ratings between categories)
    std::string advice;      ///< which test to cite, in one sentence
    std::size_t ratings = 0; ///< observations the models used
    bool fitted = false;     ///< false: fewer than two stimuli or participants
};

/// The analysis of one scale.
struct ScaleAnalysis {
    RatingScaleInfo scale;
    std::vector<RatingCell> cells;
    std::size_t participants = 0;
    TestResult levene;
    OmnibusTest omnibus;
    std::vector<PairedComparison> planned;
    std::vector<FactorEffect> factorEffects;
    std::vector<GroupComparison> groups;
    ScaleModels models;
};

/// Spearman correlation of two scales over (participant, stimulus) pairs rated on both.
struct ScaleCorrelation {
    std::string first, second;
    std::size_t n = 0;
    TestResult test;
    double pHolm = std::numeric_limits<double>::quiet_NaN();
};

/// The whole analysis.
struct RatingStudyAnalysis {
    std::string title;
    RatingAnalysisOptions options;
    std::size_t participants = 0;
    std::vector<ScaleAnalysis> scales;
    std::vector<ScaleCorrelation> correlations;
};

/// Runs every analysis. Throws std::invalid_argument when there is no rating.
RatingStudyAnalysis analyzeRatingStudy(const RatingData& data,
                                       const RatingAnalysisOptions& options = {});

} // namespace underfoot::analysis
