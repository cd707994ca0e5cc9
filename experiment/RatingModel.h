// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// How simulated participants rate stimuli on scales: for each scale a base value, an effect
/// per factor level, per stimulus and per participant-field answer, a participant bias and a
/// trial noise (all in scale points), rounded and clamped to the scale. Read from a TOML file
/// (format in docs/reference/protocol.md, "Rating models"), so that simulated studies show the
/// effects a lab expects and the analysis can be checked against them.
#include "experiment/Protocol.h"

#include <map>
#include <string>
#include <vector>

namespace underfoot::experiment {

/// The model of one scale.
struct ScaleRatingModel {
    double base = 0.0;
    /// Standard deviation of a participant's constant bias on this scale.
    double participantSd = 1.0;
    /// Standard deviation of the trial-to-trial noise.
    double noiseSd = 1.0;
    /// factor name -> level -> effect.
    std::map<std::string, std::map<std::string, double>> effects;
    /// stimulus id -> effect (added to the factor effects).
    std::map<std::string, double> stimulusEffects;
    /// participant field -> answer -> effect.
    std::map<std::string, std::map<std::string, double>> fieldEffects;
};

/// A rating model for the scales of one protocol.
struct RatingModel {
    std::string source;
    /// Probability that a simulated listener replays a clip (each further replay is as likely).
    double replayProbability = 0.2;
    std::map<std::string, ScaleRatingModel> scales;

    /// The expected rating (before bias and noise) of `stimulus` on `scaleId` by a participant
    /// with `fields`; NaN when the scale is not modelled.
    double expected(const std::string& scaleId, const Stimulus& stimulus,
                    const std::map<std::string, std::string>& fields) const;
};

/// Parses a rating model. Throws ProtocolError listing every problem with file:line:column.
RatingModel parseRatingModel(const std::string& text, const std::string& sourceName);
/// Reads a rating model file (ProtocolError also when it cannot be read).
RatingModel loadRatingModel(const std::string& path);
/// Problems of a model against a protocol: unknown scales, factors, levels, stimuli, fields.
std::vector<std::string> checkRatingModel(const RatingModel& model, const Protocol& protocol);

} // namespace underfoot::experiment
