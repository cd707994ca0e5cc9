// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The ids a protocol may name: surfaces and soundscapes. The experiment library does not know
/// the engine; the caller passes the list it knows (the app passes the engine's own list).
#include "base/AnswerRule.h"
#include "base/Suggest.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::experiment {

/// One named entry of a catalogue (id plus a human label used in answer lists and codebooks).
struct CatalogueEntry {
    std::string id;
    std::string label;
    /// Two-letter code used in the published confusion tables (e.g. "BS"); may be empty.
    std::string code;
};

/// Known surfaces and soundscapes.
struct Catalogue {
    std::vector<CatalogueEntry> surfaces;
    std::vector<CatalogueEntry> soundscapes;

    /// The surface entry with this id, or nullptr.
    const CatalogueEntry* surface(std::string_view id) const;
    /// The soundscape entry with this id, or nullptr.
    const CatalogueEntry* soundscape(std::string_view id) const;
    /// The surface whose published code is `code` (case-sensitive, e.g. "WR"), or nullptr.
    const CatalogueEntry* surfaceByCode(std::string_view code) const;
};

/// Every surface preset and soundscape the program ships (base/Catalogue.h, generated from the
/// preset files), with the labels and codes the analysis uses too.
const Catalogue& defaultCatalogue();

/// The did-you-mean of messages about unknown ids (base/Suggest.h).
using base::closestName;
using base::sortedIdsWithSuggestion;

/// The id of the "I don't know" answer option.
inline constexpr std::string_view kDontKnow = "dont_know";
/// Suffix of the reverb variants of a surface (wood_reverb is wood with convolution reverb).
inline constexpr std::string_view kReverbSuffix = "_reverb";

/// The surface walked on for a stimulus surface id: strips the reverb suffix
/// ("wood_reverb" -> "wood"); other ids are returned unchanged.
std::string baseSurface(std::string_view surfaceId);

/// Whether an answer names the surface walked on: the project's one rule (base/AnswerRule.h).
using base::answerIsCorrect;

} // namespace underfoot::experiment
