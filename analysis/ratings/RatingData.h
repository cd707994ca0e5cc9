// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Rating studies (listening tests, questionnaires after conditions): the ratings of every
/// participant on every scale, with the factor levels of each stimulus and the participants'
/// answers to grouping questions (expertise, listening device...). Read from the CSV files that
/// `underfoot export` writes (ratings, participants, scales), so analysis/ does not depend on
/// the experiment runner.
#include <map>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// One rating: participant `participant` rated stimulus `stimulus` `value` on `scale`.
struct RatingObservation {
    std::string participant;
    std::string stimulus;
    std::map<std::string, std::string> factors;
    std::string scale;
    double value = 0.0;
};

/// A rating scale (its range draws the box-plot axis).
struct RatingScaleInfo {
    std::string id;
    std::string prompt;
    double min = 0.0;
    double max = 10.0;
    /// Named points, "value=label; ..." (for the report).
    std::string anchors;
};

/// Everything a rating-study analysis reads.
struct RatingData {
    std::string title;
    std::vector<RatingObservation> ratings;
    /// Scales in protocol order (when unknown: inferred from the data, range = observed range).
    std::vector<RatingScaleInfo> scales;
    /// participant -> field -> answer (participant-level grouping variables).
    std::map<std::string, std::map<std::string, std::string>> participantFields;
    /// Grouping fields in order (the participant CSV's extra columns).
    std::vector<std::string> groupingFields;
    /// Stimuli in first-seen order, factor names in column order, levels in first-seen order.
    std::vector<std::string> stimulusOrder;
    std::vector<std::string> factorOrder;
    std::map<std::string, std::vector<std::string>> levelOrder;
};

/// Reads the ratings CSV of `underfoot export` (study, participant, group, trial_index,
/// stimulus_id, practice, excluded, <factor columns>, scale, value): practice and excluded rows
/// are left out. Optional: the participants CSV (participant, group, status, age, gender, shoes,
/// hearing, <field columns>) and the scales CSV (scale, prompt, min, max, anchors, stimuli).
/// Throws std::runtime_error naming source:line and what was expected (missing column,
/// non-numeric or non-finite value).
RatingData parseRatingData(const std::string& ratingsCsv, const std::string& ratingsSource,
                           const std::string& participantsCsv = {},
                           const std::string& participantsSource = {},
                           const std::string& scalesCsv = {}, const std::string& scalesSource = {});

/// Reads the files; an empty path skips that file.
RatingData readRatingData(const std::string& ratingsPath, const std::string& participantsPath = {},
                          const std::string& scalesPath = {});

} // namespace underfoot::analysis
