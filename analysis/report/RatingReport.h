// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reports of rating studies (analysis/ratings/RatingAnalysis.h) in the paper's form: tables of
/// medians and IQRs, test tables with Holm-corrected p-values and significance stars, and box
/// plots drawn as SVG by our own code (Tukey whiskers; outliers as circles, extremes as dots).
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/Export.h"

#include <string>

namespace underfoot::analysis {

/// Header of the tidy CSV of a rating study.
inline constexpr std::string_view kRatingTidyCsvHeader =
    "section,scale,subject,comparison,statistic,value";

/// The box plot of one scale: one box per cell, coloured by the level of the first factor.
std::string ratingBoxPlotSvg(const ScaleAnalysis& scale);

/// The report in one format (Markdown, HTML with inline SVG box plots, tidy CSV). LaTeX gives
/// booktabs tables of the cell medians and the tests.
std::string renderRatingReport(const RatingStudyAnalysis& analysis, ReportFormat format);

/// "***" for p < 0.001, "**" < 0.01, "*" < 0.05, "" otherwise (NaN: "").
const char* significanceStars(double p);

} // namespace underfoot::analysis
