// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Renders an analysis report as tidy CSV (one row per cell), LaTeX (booktabs), Markdown, or a
/// self-contained HTML page with confusion-matrix heat maps as inline SVG.
#include "analysis/tables/Tables.h"

#include <optional>
#include <string>
#include <string_view>

namespace underfoot::analysis {

/// Output formats of `underfoot analyze`.
enum class ReportFormat { Csv, Latex, Markdown, Html };

/// "csv", "latex", "markdown"/"md", "html" -> format.
std::optional<ReportFormat> parseReportFormat(std::string_view name);

/// Header of the tidy CSV.
inline constexpr std::string_view kTidyCsvHeader =
    "table,group,stimulus,soundscape,column,statistic,value,note";

/// The whole report in one format.
std::string renderReport(const AnalysisReport& report, ReportFormat format);

/// One confusion matrix as an SVG heat map (row percentages as colour, counts as text).
std::string confusionHeatMapSvg(const ConfusionMatrix& confusion);

} // namespace underfoot::analysis
