// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Mixed models beside the between-group comparisons of `underfoot analyze`: for
/// every pair of groups, the logistic mixed model on correct answers and, on each rating, the
/// linear and the cumulative link mixed model (with the Mann-Whitney test), per surface and over
/// all surfaces (surface as a fixed factor), with the participant as a random intercept; and the
/// sentence saying which test to cite.
#include "analysis/tables/Tables.h"

#include <span>

namespace underfoot::analysis {

/// Fills report.mixedModels and report.mixedModelAdvice from the trials the tables used
/// (same scoring rules). Needs report.groups and report.comparisons (analyzeTrials with
/// byGroup); does nothing with fewer than two groups. nAGQ as in glmer (1 = Laplace).
void addMixedModelComparisons(AnalysisReport& report, std::span<const TrialRecord> trials,
                              const AnalysisOptions& options, int nAGQ = 1);

} // namespace underfoot::analysis
