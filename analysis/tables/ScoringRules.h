// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Which trials and answers count for which figure: the one rule set behind every table.
///
///  1. A trial enters the tables when it is not a practice trial, not excluded, and answered
///     (its answer id is not empty).
///  2. It is correct when the experiment layer recorded it correct; when nothing was recorded,
///     when the answer names the surface walked on (a reverb variant is named by its base
///     surface: "wood" for "wood_reverb"). The soundscape does not matter (TVCG 2011 group 3).
///  3. "I don't know" is neither correct nor wrong; wrong = entered - correct - don't know.
///  4. Mean realism uses correct answers with a realism rating only.
///  5. Mean quality uses every answer except "I don't know" that has a quality rating.
///  6. Soundscape recognition uses trials with a soundscape played and a soundscape answer; it
///     is correct as recorded or, when nothing was recorded, when the answer names the
///     soundscape played (ids or published labels).
#include "analysis/model/TrialRecord.h"

#include <optional>

namespace underfoot::analysis::rules {

/// Rule 1.
bool entersTables(const TrialRecord& trial);
/// Rule 2.
bool isCorrect(const TrialRecord& trial);
/// Rule 3.
bool isDontKnow(const TrialRecord& trial);
/// Rule 4.
bool countsForRealism(const TrialRecord& trial);
/// Rule 5.
bool countsForQuality(const TrialRecord& trial);
/// Rule 6: empty when the trial does not count for soundscape recognition.
std::optional<bool> soundscapeCorrect(const TrialRecord& trial);

} // namespace underfoot::analysis::rules
