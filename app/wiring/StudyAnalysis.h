// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The analysis of a study store, set up once for every front end: `underfoot analyze --study`
/// and the console's Results view call these, so both compare the same groups in the same order
/// with the same answer list and the same mixed models. The defaults come from the protocol (a
/// between-participant design compares its groups, in the protocol's order; the answer list is
/// the protocol's surface question, "I don't know" last); a front end overrides them only where
/// its user asked. The trials and ratings are read through the study's own CSV export, parsed
/// from memory.
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/ratings/RatingData.h"
#include "analysis/report/RatingReport.h"
#include "analysis/tables/Tables.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"

#include <optional>
#include <string>
#include <vector>

namespace underfoot::wiring {

/// What a front end may change of a study's analysis; every unset member keeps the study's
/// default.
struct StudyAnalysisOverrides {
    /// Per-group tables and between-group tests; default: the design is between participants.
    std::optional<bool> byGroup;
    /// Group order; default: the protocol's order of its groups.
    std::vector<std::string> groupOrder;
    /// Answer list; default: the protocol's surface options ("I don't know" last).
    std::optional<analysis::AnswerList> answers;
    bool poolSoundscapes = false;
    double confLevel = 0.95;
    /// Simulated participants (`session --simulate`) are analysed only when asked for.
    bool includeSimulated = false;
    /// Report title; default: the protocol's title.
    std::string title;
    /// Participant fields a rating analysis compares groups on; default: every field.
    std::vector<std::string> ratingGroupFields;
};

/// The analysis options of a study of `protocol`, `overrides` applied.
analysis::AnalysisOptions studyAnalysisOptions(const experiment::Protocol& protocol,
                                               const StudyAnalysisOverrides& overrides = {});

/// Simulated participants stored in the study.
int simulatedParticipants(const experiment::StudyStore& store);

/// Whether the study is analysed in the rating form (medians, Friedman, Wilcoxon, mixed models
/// per scale): its protocol rates on scales and asks no surface question.
bool isRatingStudy(const experiment::Protocol& protocol);

/// Confusion matrices, per-stimulus summary, between-group tests and mixed models (glmer; lmer
/// and clmm on ratings) of the study's answered trials. Throws std::runtime_error on a store
/// that cannot be read.
analysis::AnalysisReport analyzeStudy(const experiment::StudyStore& store,
                                      const StudyAnalysisOverrides& overrides = {});

/// The ratings of a rating study, with the labels its report shows.
struct StudyRatings {
    analysis::RatingData data;
    analysis::RatingLabels labels;
};
/// The study's answered ratings, participants' grouping fields and scales (simulated
/// participants only when `overrides.includeSimulated`).
StudyRatings studyRatings(const experiment::StudyStore& store,
                          const StudyAnalysisOverrides& overrides = {});

/// The rating form's analysis of `ratings`; throws std::invalid_argument on a grouping field
/// the study does not have, or on no ratings at all.
analysis::RatingStudyAnalysis analyzeRatings(const StudyRatings& ratings,
                                             const StudyAnalysisOverrides& overrides = {});

} // namespace underfoot::wiring
