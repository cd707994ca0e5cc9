// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// One answered trial, independent of how the experiment layer stores it. The long-format trial
/// CSV written by `underfoot export` maps one row onto one record (io/TrialCsv.h).
#include <limits>
#include <optional>
#include <string>

namespace underfoot::analysis {

/// One trial of one participant.
struct TrialRecord {
    std::string study;
    std::string participant;
    std::string group; ///< between-subject condition, e.g. "2_coherent"
    std::string session;
    int trialIndex = 0;
    std::string block;
    bool practice = false; ///< practice trials never enter the tables
    std::string stimulusId;
    std::string surfaceId;    ///< presented surface, e.g. "wood_reverb"
    std::string soundscapeId; ///< empty when no soundscape was played
    std::string modalities;
    int repetition = 0;
    std::string answerId; ///< surface id or "dont_know"; empty = not answered
    /// Correctness recorded by the experiment layer; empty = derive with answerIsCorrect().
    std::optional<bool> recordedCorrect;
    double realism = std::numeric_limits<double>::quiet_NaN(); ///< NaN when not asked/answered
    double quality = std::numeric_limits<double>::quiet_NaN(); ///< NaN when not asked/answered
    std::string soundscapeAnswer;                              ///< empty when not asked
    std::optional<bool> recordedSoundscapeCorrect;
    double responseTimeSeconds = std::numeric_limits<double>::quiet_NaN();
    bool excluded = false; ///< excluded trials never enter the tables
    std::string exclusionReason;
    /// A synthetic participant's trial (`simulated` column; absent = false).
    bool simulated = false;
};

} // namespace underfoot::analysis
