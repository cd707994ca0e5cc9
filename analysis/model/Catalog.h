// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The surfaces and soundscapes the analysis knows (the project's catalogue, base/Catalogue.h,
/// generated from the preset files) with the codes of the published tables, and the answer
/// lists of the reference studies (docs/explanation/studies.md).
#include "base/AnswerRule.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::analysis {

/// Material class of a surface, as in the Eurohaptics category analysis.
enum class SurfaceCategory { Solid, Aggregate, Liquid, Unknown };

/// Id of the "I don't know" answer.
inline constexpr std::string_view kDontKnowId = "dont_know";

/// One surface known to the project.
struct SurfaceInfo {
    std::string id;     ///< e.g. "wood_reverb"
    std::string label;  ///< e.g. "Wood (reverb)"
    std::string code;   ///< code of the published tables, e.g. "WR"
    std::string baseId; ///< surface a listener must name: "wood" for "wood_reverb"
    SurfaceCategory category = SurfaceCategory::Unknown;
};

/// All surfaces in the project's canonical order (the TVCG 2011 exp. 1 table order).
const std::vector<SurfaceInfo>& surfaceCatalog();

/// Surface by id or by published code (case-insensitive for codes), if known.
std::optional<SurfaceInfo> findSurface(std::string_view idOrCode);

/// Base surface of a stimulus surface (itself when it is not a reverb variant or unknown).
std::string baseSurfaceId(std::string_view surfaceId);

/// Category of a surface id (reverb variants take their base surface's category).
SurfaceCategory surfaceCategory(std::string_view surfaceId);

/// "solid", "aggregate", "liquid" or "unknown".
const char* categoryName(SurfaceCategory category);

/// Human label of a surface, answer or soundscape id (the id itself when unknown).
std::string labelFor(std::string_view id);

/// Soundscape ids and labels (beach_summer, farm_courtyard, ski_slope, forest, park_fall).
struct SoundscapeInfo {
    std::string id;
    std::string label;
};
/// All soundscapes known to the project.
const std::vector<SoundscapeInfo>& soundscapeCatalog();
/// Soundscape id from an id or a published label ("Ski slope", "Beach"), if known.
std::optional<std::string> findSoundscapeId(std::string_view idOrLabel);

/// One option of the answer sheet.
struct AnswerOption {
    std::string id;    ///< surface id or "dont_know"
    std::string label; ///< text shown to the participant
};

/// Ordered answer options of a protocol, "I don't know" last.
struct AnswerList {
    std::vector<AnswerOption> options;

    /// Index of an answer id, if present.
    [[nodiscard]] std::optional<std::size_t> indexOf(std::string_view id) const;
    /// Appends an option before "I don't know" when it is not yet listed.
    void addBeforeDontKnow(const std::string& id);
};

/// The answer sheet of TVCG 2011 exp. 2 / Eurohaptics 2010: 15 surfaces and "I don't know".
AnswerList defaultAnswerList();

/// Whether an answer names the surface walked on: the project's one rule (base/AnswerRule.h;
/// the answer first, then the stimulus's surface).
using base::answerIsCorrect;

} // namespace underfoot::analysis
