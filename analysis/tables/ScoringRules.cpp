// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/tables/ScoringRules.h"

#include "analysis/model/Catalog.h"

#include <cmath>

namespace underfoot::analysis::rules {

bool entersTables(const TrialRecord& t) {
    return !t.practice && !t.excluded && !t.answerId.empty();
}

bool isCorrect(const TrialRecord& t) {
    if (t.recordedCorrect) return *t.recordedCorrect;
    return answerIsCorrect(t.answerId, t.surfaceId);
}

bool isDontKnow(const TrialRecord& t) {
    return t.answerId == kDontKnowId;
}

bool countsForRealism(const TrialRecord& t) {
    return isCorrect(t) && !std::isnan(t.realism);
}

bool countsForQuality(const TrialRecord& t) {
    return !isDontKnow(t) && !std::isnan(t.quality);
}

std::optional<bool> soundscapeCorrect(const TrialRecord& t) {
    if (t.soundscapeId.empty() || t.soundscapeAnswer.empty()) return std::nullopt;
    if (t.recordedSoundscapeCorrect) return *t.recordedSoundscapeCorrect;
    const auto played = findSoundscapeId(t.soundscapeId).value_or(t.soundscapeId);
    const auto named = findSoundscapeId(t.soundscapeAnswer).value_or(t.soundscapeAnswer);
    return played == named;
}

} // namespace underfoot::analysis::rules
