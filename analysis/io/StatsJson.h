// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// JSON front end of the statistical tests (`underfoot stats TEST`): one request object in,
/// one result object out, so that scripts in any language use the same tested code.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace underfoot::analysis {

/// Outcome of one request: `json` is the result object or {"error": "..."}.
struct StatsResponse {
    bool ok = false;
    std::string json;
};

/// Names of the tests `runStatsRequest` knows.
const std::vector<std::string>& statsTestNames();

/// Runs one test on a JSON request. Input fields (all optional ones take R's defaults):
/// chisq {table, correct}, chisq_gof {x, p}, fisher {table, conf_level, alternative} (r x c
/// tables: exact two-sided p only, see fisherTestRxC),
/// t {x, y?, paired, var_equal, mu, conf_level, alternative},
/// wilcoxon {x, y?, paired, correct, exact?, mu, alternative, conf_int, conf_level} (conf_int:
/// Hodges-Lehmann estimate and interval), kruskal {groups},
/// pearson {x, y, alternative, conf_level}, kendall {x, y, alternative, exact?, continuity},
/// friedman {y}, spearman {x, y, alternative, exact?}, p_adjust {p, method},
/// pairwise_wilcoxon {groups, paired, correct, exact?, method},
/// shapiro {x}, levene {groups, center}, binom {x, n, p, conf_level, alternative},
/// prop {x, n, p, correct, conf_level, alternative}, wilson {x, n, conf_level, correct}.
/// null in a numeric array is a missing value (R's NA). Output: statistic, statistic_name, df
/// (number or array), p, conf_int, conf_level, estimate (+ estimate_names), method,
/// alternative, warnings; `adjusted` for p_adjust, `rho` for spearman, `tau` for kendall. NaN is
/// null and infinities are the strings "Inf" / "-Inf".
StatsResponse runStatsRequest(std::string_view test, std::string_view requestJson);

/// Line and column (both from 1) of the byte a JSON parser reports (nlohmann's parse_error::byte,
/// counted from 1), for error messages that say where the request is wrong.
std::pair<std::size_t, std::size_t> jsonErrorPosition(std::string_view text, std::size_t byte);

} // namespace underfoot::analysis
