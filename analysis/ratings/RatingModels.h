// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Mixed models on the ratings of one scale of a rating study: every rating an observation,
/// the stimulus (cell) as the fixed factor, the participant as a random intercept; the linear
/// mixed model (lmerTest::lmer, REML) and the cumulative link mixed model (ordinal::clmm,
/// Laplace, logit), each with the likelihood-ratio test of the stimulus, and the sentence on
/// which test to cite beside the Friedman test of the cells. No Qt.
#include "analysis/ratings/RatingAnalysis.h"

namespace underfoot::analysis {

/// Fits both models for `scale` (its range gives the clmm's categories when every rating is a
/// whole point of it); the data's stimulus order orders the levels (the first is the
/// reference). `omnibus` is the scale's Friedman (or Wilcoxon) test, for the advice.
ScaleModels fitScaleModels(const RatingData& data, const RatingScaleInfo& scale,
                           const OmnibusTest& omnibus);

/// The clmm's categories for ratings on [min, max]: every whole point when the range is whole
/// and at most 101 points wide and every value is one of them; empty otherwise (`why` says why).
std::vector<double> ratingCategories(const std::vector<double>& values, double min, double max,
                                     std::string& why);

} // namespace underfoot::analysis
