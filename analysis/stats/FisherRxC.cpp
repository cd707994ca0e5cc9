// SPDX-License-Identifier: GPL-3.0-or-later
// fisher.test on r x c tables: the exact p-value, found by enumerating every table with the
// observed margins (R's FEXACT uses the network algorithm; both sum the same probabilities).
#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

namespace underfoot::analysis {

using namespace numerics;

namespace {

/// Depth-first enumeration of the tables with given margins, column by column; the last
/// column is implied by the remaining row sums. Accumulates the probabilities of the tables
/// at most `logLimit` in log-probability, relative to a common constant.
class TableEnumerator {
  public:
    TableEnumerator(std::vector<double> rows, std::vector<double> cols, double logConstant,
                    double logLimit, const std::vector<double>& logFactorial)
        : rows_(std::move(rows)), cols_(std::move(cols)), logConstant_(logConstant),
          logLimit_(logLimit), lf_(logFactorial) {}

    /// False when the enumeration stopped at `maxTables`.
    bool run(double maxTables) {
        maxTables_ = maxTables;
        column(0, 0.0);
        return !stopped_;
    }
    double pValue() const { return sum_; }
    double tables() const { return visited_; }

  private:
    void column(std::size_t j, double logCells) {
        if (stopped_) return;
        if (j + 1 == cols_.size()) { // last column is determined by the remaining row sums
            double lc = logCells;
            for (double r : rows_) lc += lf(r);
            ++visited_;
            if (visited_ > maxTables_) {
                stopped_ = true;
                return;
            }
            const double logP = logConstant_ - lc;
            if (logP <= logLimit_) sum_ += std::exp(logP);
            return;
        }
        fill(j, 0, cols_[j], logCells);
    }
    void fill(std::size_t j, std::size_t i, double left, double logCells) {
        if (stopped_) return;
        if (i + 1 == rows_.size()) {
            if (left > rows_[i]) return;
            rows_[i] -= left;
            column(j + 1, logCells + lf(left));
            rows_[i] += left;
            return;
        }
        // room in the rows below bounds the smallest value of this cell
        double below = 0;
        for (std::size_t k = i + 1; k < rows_.size(); ++k) below += rows_[k];
        const double lo = std::max(0.0, left - below), hi = std::min(left, rows_[i]);
        for (double v = lo; v <= hi; v += 1) {
            rows_[i] -= v;
            fill(j, i + 1, left - v, logCells + lf(v));
            rows_[i] += v;
            if (stopped_) return;
        }
    }

    double lf(double k) const { return lf_[static_cast<std::size_t>(k)]; }

    std::vector<double> rows_, cols_;
    double logConstant_, logLimit_;
    const std::vector<double>& lf_;
    double sum_ = 0, visited_ = 0, maxTables_ = 0;
    bool stopped_ = false;
};

} // namespace

TestResult fisherTestRxC(const CountTable& table, double maxTables) {
    const std::string method = "Fisher's Exact Test for Count Data";
    if (table.size() < 2 || table.front().size() < 2)
        return failedTest(method, "'x' must have at least 2 rows and columns");
    for (const auto& row : table)
        if (row.size() != table.front().size())
            return failedTest(method, "'x' must be a rectangular table (rows of equal length)");
    TestResult r;
    r.method = method;
    r.alternative = Alternative::TwoSided;
    CountTable x = table;
    bool rounded = false;
    for (auto& row : x)
        for (double& v : row) {
            if (!(v >= 0) || !std::isfinite(v))
                return failedTest(method, "all entries of 'x' must be nonnegative and finite");
            const double rv = std::round(v);
            rounded = rounded || rv != v;
            v = rv;
        }
    if (rounded) r.warnings.emplace_back("'x' has been rounded to integer");
    const std::size_t nr = x.size(), nc = x.front().size();
    std::vector<double> rows(nr, 0.0), cols(nc, 0.0);
    for (std::size_t i = 0; i < nr; ++i)
        for (std::size_t j = 0; j < nc; ++j) {
            rows[i] += x[i][j];
            cols[j] += x[i][j];
        }
    const double n = std::accumulate(rows.begin(), rows.end(), 0.0);
    if (n > kMaxFisherRxCTotal)
        return failedTest(method,
                          fmt::format("FEXACT: the table total {} exceeds the limit of {} of the "
                                      "exact enumeration (use chisqTest, or R's "
                                      "fisher.test(simulate.p.value = TRUE))",
                                      n, kMaxFisherRxCTotal));
    // Rows/columns with zero sum hold only zeros in every table: drop them (same p).
    std::vector<double> rs, cs;
    for (double v : rows)
        if (v > 0) rs.push_back(v);
    for (double v : cols)
        if (v > 0) cs.push_back(v);
    if (rs.size() < 2 || cs.size() < 2) { // a single table with these margins
        r.p = 1;
        return r;
    }
    // Enumerate along the longer side with fewer columns (transpose: same p).
    if (cs.size() > rs.size()) std::swap(rs, cs);
    double logConstant = -std::lgamma(n + 1);
    for (double v : rows) logConstant += std::lgamma(v + 1);
    for (double v : cols) logConstant += std::lgamma(v + 1);
    double logObserved = logConstant;
    for (const auto& row : x)
        for (double v : row) logObserved -= std::lgamma(v + 1);
    // R's FEXACT counts a table as "as or less probable" with a relative tolerance 1e-7.
    const double logLimit = logObserved + std::log1p(1e-7);
    std::vector<double> logFactorial(static_cast<std::size_t>(n) + 1);
    for (std::size_t k = 0; k < logFactorial.size(); ++k) logFactorial[k] = std::lgamma(dbl(k) + 1);
    TableEnumerator e(rs, cs, logConstant, logLimit, logFactorial);
    if (!e.run(maxTables))
        return failedTest(method,
                          fmt::format("FEXACT: more than {} tables have these margins, beyond the "
                                      "limit of the exact enumeration (use chisqTest, or R's "
                                      "fisher.test(simulate.p.value = TRUE))",
                                      maxTables));
    r.p = std::min(1.0, e.pValue());
    return r;
}

} // namespace underfoot::analysis
