// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// JSON front end of the mixed-effects models (`underfoot stats glmm` / `lmm` / `clmm`), kept
/// apart from StatsJson.cpp's classic tests. Request:
///   {"y": [...], "condition": [...], "participant": [...], "surface": [...]?, "nAGQ": 1,
///    "condition_levels": [...]?, "surface_levels": [...]?,
///    "link": "logit"|"probit"|"cloglog" (clmm), "levels": [1, ..., 7]? (clmm)}
/// (glmm: y 0/1; lmm: y numeric; clmm: y ratings, ordered numerically, "levels" the scale's
/// categories; condition / participant / surface entries are strings or numbers; null is missing
/// and drops the observation as R's na.omit). Answer: method, formula, fixed [{name, estimate,
/// se, statistic, df (lmm), p}], thresholds [{name, estimate, se, statistic}] (clmm),
/// statistic_name, random_variance, residual_variance (lmm), loglik, aic, deviance, nobs,
/// ngroups, nAGQ (glmm, clmm), link and levels (clmm), lrt {statistic, df, p}, warnings.
#include "analysis/io/StatsJson.h"
#include "analysis/stats/MixedModels.h"
#include "analysis/stats/OrdinalMixed.h"

#include <string_view>

namespace underfoot::analysis {

/// True for "glmm", "lmm" and "clmm".
bool isMixedModelTest(std::string_view test);

/// Runs "glmm", "lmm" or "clmm" on a JSON request (errors as {"error": ...} with ok = false).
StatsResponse runMixedModelRequest(std::string_view test, std::string_view requestJson);

/// The answer object of a fitted model, as text (NaN is null).
std::string mixedModelResultJson(std::string_view test, const MixedModelResult& result);
/// The answer object of a fitted clmm (with its thresholds), as text.
std::string ordinalModelResultJson(const OrdinalMixedResult& result);

} // namespace underfoot::analysis
