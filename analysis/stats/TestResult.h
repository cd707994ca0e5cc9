// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Result of one statistical test, shaped like R's `htest` object so that every figure can be
/// compared with R's output one to one.
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// Alternative hypothesis, as R's `alternative` argument.
enum class Alternative { TwoSided, Less, Greater };

/// Continuity correction (Yates for chi-square, 0.5 for rank tests), as R's `correct`.
enum class Continuity { Corrected, Uncorrected };

/// A confidence interval with its level (R's `conf.int` with attribute `conf.level`).
struct Interval {
    double lower = std::numeric_limits<double>::quiet_NaN();
    double upper = std::numeric_limits<double>::quiet_NaN();
    double level = std::numeric_limits<double>::quiet_NaN();
};

/// One named estimate (R's `estimate` names, e.g. "mean of x", "odds ratio").
struct NamedValue {
    std::string name;
    double value = std::numeric_limits<double>::quiet_NaN();
};

/// Everything R prints for a test. When R stops with an error, `error` holds R's message and
/// the numbers stay NaN; where R returns NaN/NA without stopping, so do we.
struct TestResult {
    std::string method;        ///< R's wording, e.g. "Welch Two Sample t-test"
    std::string statisticName; ///< R's name of the statistic: "X-squared", "t", "V", "W", ...
    double statistic = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> df; ///< degrees of freedom (empty when the test has none)
    double p = std::numeric_limits<double>::quiet_NaN();
    std::optional<Interval> confInt;
    std::vector<NamedValue> estimate;
    Alternative alternative = Alternative::TwoSided;
    std::vector<std::string> warnings; ///< R's warnings, e.g. "Chi-squared approximation ..."
    std::string error;                 ///< non-empty when R would stop() with this message

    /// True when the test ran (R did not stop).
    [[nodiscard]] bool ok() const { return error.empty(); }
};

/// A failed test carrying R's error message.
inline TestResult failedTest(std::string method, std::string message) {
    TestResult r;
    r.method = std::move(method);
    r.error = std::move(message);
    return r;
}

/// R's name of an alternative ("two.sided", "less", "greater").
const char* alternativeName(Alternative alternative);

} // namespace underfoot::analysis
