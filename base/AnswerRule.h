// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The project's one correctness rule for surface identification, shared by the trial core
// (experiment/), which stores and exports `correct`, and the analysis (analysis/), which
// scores trials and tables: an answer is correct when it names the surface walked on. A
// `*_reverb` surface is the base surface heard through a room, so the answer and the stimulus
// are compared by their base surfaces ("wood" is correct for "wood_reverb", and "wood_reverb"
// for "wood"); the soundscape never counts; "I don't know" (dont_know) and no answer never are.
// After Nordahl, Turchet and Serafin, IEEE TVCG 17(9), 2011 (the surface identification task).
#include <string_view>

namespace underfoot::base {

/// The id of the "I don't know" answer option.
inline constexpr std::string_view kDontKnowAnswer = "dont_know";

/// The surface walked on for a stimulus surface id: "wood_reverb" -> "wood"; others unchanged.
inline constexpr std::string_view baseSurfaceOf(std::string_view surfaceId) {
    constexpr std::string_view suffix = "_reverb";
    if (surfaceId.size() > suffix.size() && surfaceId.ends_with(suffix))
        return surfaceId.substr(0, surfaceId.size() - suffix.size());
    return surfaceId;
}

/// Whether `answerId` names the surface of `stimulusSurfaceId` (see the header).
inline constexpr bool answerIsCorrect(std::string_view answerId,
                                      std::string_view stimulusSurfaceId) {
    if (answerId.empty() || answerId == kDontKnowAnswer) return false;
    return baseSurfaceOf(answerId) == baseSurfaceOf(stimulusSurfaceId);
}

} // namespace underfoot::base
