// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// JSON front end of the mixed-effects models (`underfoot stats glmm` / `underfoot stats lmm`),
/// kept apart from StatsJson.cpp's classic tests. Request:
///   {"y": [...], "condition": [...], "participant": [...], "surface": [...]?, "nAGQ": 1,
///    "condition_levels": [...]?, "surface_levels": [...]?}
/// (glmm: y 0/1; lmm: y numeric; condition / participant / surface entries are strings or
/// numbers; null is missing and drops the observation as R's na.omit). Answer: method, formula,
/// fixed [{name, estimate, se, statistic, df (lmm), p}], statistic_name, random_variance,
/// residual_variance (lmm), loglik, aic, deviance, nobs, ngroups, nAGQ (glmm), lrt {statistic,
/// df, p}, warnings.
#include "analysis/io/StatsJson.h"
#include "analysis/stats/MixedModels.h"

#include <string_view>

namespace underfoot::analysis {

/// True for "glmm" and "lmm".
bool isMixedModelTest(std::string_view test);

/// Runs "glmm" or "lmm" on a JSON request (errors as {"error": ...} with ok = false).
StatsResponse runMixedModelRequest(std::string_view test, std::string_view requestJson);

/// The answer object of a fitted model, as text (NaN is null).
std::string mixedModelResultJson(std::string_view test, const MixedModelResult& result);

} // namespace underfoot::analysis
