// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Confusion matrices, category matrices, per-stimulus summaries and between-group comparisons,
/// built from trial records (or from imported count tables) under tables/ScoringRules.h.
#include "analysis/model/Catalog.h"
#include "analysis/model/TrialRecord.h"
#include "analysis/stats/TestResult.h"

#include <compare>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// A presented stimulus: surface and the soundscape played with it (empty = none or pooled).
struct StimulusKey {
    std::string surfaceId;
    std::string soundscapeId;
    auto operator<=>(const StimulusKey&) const = default;
};

/// Rows per soundscape or pooled over soundscapes.
enum class SoundscapeSplit { BySoundscape, Pooled };

/// Presented stimulus (rows) x answer option (columns) counts of one group.
struct ConfusionMatrix {
    std::string group; ///< group name ("all" when pooled)
    std::vector<StimulusKey> rows;
    AnswerList columns;
    std::vector<std::vector<double>> counts; ///< rows x columns
    /// Presentations per row when known from the design (imported tables); NaN otherwise.
    double nominalRowTotal = std::numeric_limits<double>::quiet_NaN();

    /// Sum of a row.
    [[nodiscard]] double rowTotal(std::size_t row) const;
    /// Row percentage of one cell (NaN for an empty row).
    [[nodiscard]] double rowPercent(std::size_t row, std::size_t column) const;
};

/// Counts of one row category (solid, aggregate, liquid) answered with each category.
struct CategoryMatrix {
    std::string group;
    std::vector<SurfaceCategory> rows; ///< presented categories present in the data
    std::vector<std::string> columns;  ///< "solid", "aggregate", "liquid", "dont_know", "other"
    std::vector<std::vector<double>> counts;
    /// Row percentage (NaN for an empty row).
    [[nodiscard]] double rowPercent(std::size_t row, std::size_t column) const;
};

/// A proportion with its Wilson interval.
struct Proportion {
    double count = 0;
    double n = 0;
    double percent = std::numeric_limits<double>::quiet_NaN();
    Interval wilson; ///< in percent
};

/// A mean with spread and t interval (NaN when n = 0; SD, SE and CI NaN when n < 2).
struct MeanSummary {
    double n = 0;
    double mean = std::numeric_limits<double>::quiet_NaN();
    double sd = std::numeric_limits<double>::quiet_NaN();
    double se = std::numeric_limits<double>::quiet_NaN();
    Interval ci;
    std::vector<double> values; ///< the individual ratings, in trial order (for the figures)
};

/// One row of the studies' per-stimulus summary.
struct SummaryRow {
    std::string group;
    StimulusKey stimulus;
    double n = 0; ///< trials entering the tables
    Proportion correct, wrong, dontKnow, soundscapeCorrect;
    MeanSummary realism; ///< correct answers only
    MeanSummary quality; ///< all answers except "I don't know"
};

/// Which measure a comparison is about.
enum class Measure { Correct, DontKnow, Realism, Quality };
/// "correct", "dont_know", "realism", "quality".
const char* measureName(Measure measure);

/// One test between two groups on one surface (surfaceId empty = pooled over surfaces).
struct ComparisonRow {
    Measure measure = Measure::Correct;
    std::string surfaceId;
    std::string groupA, groupB;
    double nA = 0, nB = 0;
    double valueA = std::numeric_limits<double>::quiet_NaN(); ///< % or mean in group A
    double valueB = std::numeric_limits<double>::quiet_NaN();
    TestResult test; ///< chisq.test (Yates) for counts, Welch t.test for ratings
    double fisherP = std::numeric_limits<double>::quiet_NaN(); ///< exact check for counts
    std::string effectName;                                    ///< "phi" or "Cohen's d"
    double effect = std::numeric_limits<double>::quiet_NaN();
    double pHolm = std::numeric_limits<double>::quiet_NaN(); ///< Holm across surfaces
};

/// The mixed model beside a between-group comparison: the participant as a random
/// intercept, groupB's coefficient against groupA (log-odds ratio for correct answers, mean
/// difference for lmer, log-odds ratio of a higher rating for clmm). Filled by
/// addMixedModelComparisons (report/MixedModelReport.h).
struct MixedComparisonRow {
    Measure measure = Measure::Correct;
    std::string surfaceId; ///< empty = all surfaces, surface as a fixed factor
    std::string groupA, groupB;
    double observations = 0, participants = 0;
    std::string
        model; ///< "glmer (Laplace)" / "lmer (REML, Satterthwaite)" / "clmm (Laplace, logit)"
    double estimate = std::numeric_limits<double>::quiet_NaN();
    double se = std::numeric_limits<double>::quiet_NaN();
    double statistic = std::numeric_limits<double>::quiet_NaN(); ///< Wald z or t
    double df = std::numeric_limits<double>::quiet_NaN();        ///< Satterthwaite (ratings)
    double p = std::numeric_limits<double>::quiet_NaN();         ///< Wald p
    double lrtStatistic = std::numeric_limits<double>::quiet_NaN();
    double lrtP = std::numeric_limits<double>::quiet_NaN();
    double randomVariance = std::numeric_limits<double>::quiet_NaN();
    double classicP = std::numeric_limits<double>::quiet_NaN(); ///< the matching chi-square / t p
    /// Ratings: Mann-Whitney (wilcox.test) p of the pooled ratings of the two groups.
    double nonparametricP = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::string> warnings;
    std::string error;
};

/// Options of an analysis.
struct AnalysisOptions {
    AnswerList answers = defaultAnswerList();
    SoundscapeSplit split = SoundscapeSplit::BySoundscape;
    bool byGroup = false; ///< per-group tables and between-group comparisons
    /// Order of the groups in tables and comparisons; unlisted groups follow alphabetically.
    std::vector<std::string> groupOrder;
    double confLevel = 0.95;
};

/// Everything `underfoot analyze` reports.
struct AnalysisReport {
    std::string title;
    std::string source;
    std::vector<std::string> groups;
    std::vector<ConfusionMatrix> confusions;
    std::vector<CategoryMatrix> categories;
    std::vector<SummaryRow> summary;
    std::vector<ComparisonRow> comparisons;
    std::vector<MixedComparisonRow> mixedModels; ///< mixed models beside the comparisons
    std::string mixedModelAdvice;                ///< which test to cite, and why
    bool hasRatings = false;
    std::vector<std::string> notes; ///< import warnings and remarks shown with the report
    /// Simulated participants among those analysed (`session --simulate`), and all of them:
    /// a report that includes any says so at its top (HTML banner, Markdown line).
    int simulatedParticipants = 0;
    int participants = 0;
};

/// Confusion matrix of the trials of one group (all trials when `group` is empty).
ConfusionMatrix buildConfusion(std::span<const TrialRecord> trials, const AnswerList& answers,
                               SoundscapeSplit split, const std::string& group = {});

/// Category matrix derived from a confusion matrix.
CategoryMatrix buildCategoryMatrix(const ConfusionMatrix& confusion);

/// Full analysis of trial records (`participants` and `simulatedParticipants` count everyone in
/// `trials`).
AnalysisReport analyzeTrials(std::span<const TrialRecord> trials, const AnalysisOptions& options);

/// Analysis of imported count tables (one per group): summaries of proportions and the
/// between-group tests on counts (no ratings).
AnalysisReport analyzeConfusions(std::vector<ConfusionMatrix> confusions,
                                 const AnalysisOptions& options);

/// Canonical order of stimulus rows: catalog order of surfaces, then soundscape.
bool stimulusBefore(const StimulusKey& a, const StimulusKey& b);

} // namespace underfoot::analysis
