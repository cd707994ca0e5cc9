// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reports of rating studies (analysis/ratings/RatingAnalysis.h) in the paper's form: tables of
/// medians and IQRs, test tables with Holm-corrected p-values and significance stars, and box
/// plots drawn as SVG by our own code (Tukey whiskers; outliers as circles, extremes as dots).
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/Export.h"

#include <limits>
#include <map>
#include <string>

namespace underfoot::analysis {

/// What people read in place of ids: the protocol's stimulus labels. An id without
/// a label is shown as is.
struct RatingLabels {
    std::map<std::string, std::string> stimuli; ///< stimulus id -> label
    /// Simulated participants among those analysed (a banner says so when any).
    int simulatedParticipants = 0;
    std::string stimulus(const std::string& id) const {
        const auto it = stimuli.find(id);
        return it == stimuli.end() || it->second.empty() ? id : it->second;
    }
};

/// Mean of a cell's participant values with its 95 % t interval (mean ± t(0.975, n - 1) SD /
/// sqrt(n); NaN bounds when n < 2).
struct MeanInterval {
    std::size_t n = 0;
    double mean = std::numeric_limits<double>::quiet_NaN();
    double lower = std::numeric_limits<double>::quiet_NaN();
    double upper = std::numeric_limits<double>::quiet_NaN();
};
MeanInterval cellMeanInterval(const RatingCell& cell);

/// Header of the tidy CSV of a rating study.
inline constexpr std::string_view kRatingTidyCsvHeader =
    "section,scale,subject,comparison,statistic,value";

/// The box plot of one scale: one box per cell, coloured by the level of the first factor.
/// Axis titles: the scale (y) and "Condition" (x); cells by their labels.
std::string ratingBoxPlotSvg(const ScaleAnalysis& scale, const RatingLabels& labels = {});

/// Means with 95 % confidence intervals per cell, with every participant's value as a point
/// (spread sideways by a fixed pattern, not at random), axis titles, cells by their labels.
std::string ratingMeansSvg(const ScaleAnalysis& scale, const RatingLabels& labels = {});

/// The report in one format (Markdown, HTML with inline SVG box plots, tidy CSV). LaTeX gives
/// booktabs tables of the cell medians and the tests.
std::string renderRatingReport(const RatingStudyAnalysis& analysis, ReportFormat format,
                               const RatingLabels& labels = {});

/// "***" for p < 0.001, "**" < 0.01, "*" < 0.05, "" otherwise (NaN: "").
const char* significanceStars(double p);

} // namespace underfoot::analysis
