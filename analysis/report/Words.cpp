// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/Words.h"

#include <fmt/format.h>

#include <cmath>

namespace underfoot::analysis {

std::string pInWords(double p) {
    if (std::isnan(p)) return "p = NA";
    if (p < 0.001) return "p < 0.001";
    return fmt::format("p = {:.3f}", p);
}

std::string statisticSymbol(const std::string& rName) {
    if (rName.find("chi-squared") != std::string::npos || rName == "X-squared") return "χ²";
    if (rName == "F value") return "F"; // Levene (car::leveneTest's column name)
    if (rName.empty()) return "statistic";
    return rName;
}

namespace {
std::string number2(double v) {
    if (std::isnan(v)) return "NA";
    if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
    return fmt::format("{:.2f}", v);
}
} // namespace

std::string testInWords(const TestResult& t) {
    if (!t.ok()) return "not computed (" + t.error + ")";
    std::string df;
    for (double d : t.df)
        df += (df.empty() ? "" : ", ") +
              (d == std::round(d) ? fmt::format("{:.0f}", d) : fmt::format("{:.1f}", d));
    return fmt::format("{}{} = {}, {}", statisticSymbol(t.statisticName),
                       df.empty() ? "" : "(" + df + ")", number2(t.statistic), pInWords(t.p));
}

std::string statisticInWords(const std::string& symbol, double value, double p) {
    return fmt::format("{} = {}, {}", symbol, number2(value), pInWords(p));
}

} // namespace underfoot::analysis
