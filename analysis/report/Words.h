// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Test results in words, as a paper writes them beside the numbers:
/// "χ²(1) = 8.90, p = 0.003", "t(13.4) = 2.45, p = 0.028", "Z = -2.31, p = 0.021",
/// "W = 12.00, p = 0.041", "ρ = 0.52, p < 0.001". Shared by the confusion and rating reports.
#include "analysis/stats/TestResult.h"

#include <string>

namespace underfoot::analysis {

/// "p = 0.003", "p < 0.001", "p = NA".
std::string pInWords(double p);
/// The statistic's symbol: R's "X-squared", "Friedman chi-squared", "Kruskal-Wallis
/// chi-squared" -> "χ²", "F value" -> "F"; others ("t", "W", "V", "Z") as R names them.
std::string statisticSymbol(const std::string& rName);
/// "χ²(1) = 8.90, p = 0.003": the symbol, the degrees of freedom in brackets (whole numbers
/// without decimals, others to 1 decimal), the statistic to 2 decimals, p to 3 (< 0.001 below).
/// A test that did not run: "not computed (reason)".
std::string testInWords(const TestResult& test);
/// "Z = -2.31, p = 0.021" (a statistic without degrees of freedom).
std::string statisticInWords(const std::string& symbol, double value, double p);

} // namespace underfoot::analysis
