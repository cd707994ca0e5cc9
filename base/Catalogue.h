// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The project's one catalogue of surfaces and soundscapes, generated at build time from the
/// surface presets (engine/data/surfaces/<id>.toml: id, name, code, category) and the soundscape
/// files (soundscapes/data/<id>.toml) by tools/catalogue/catalogue.py. The experiment (which ids
/// a protocol may name, answer labels) and the analysis (scoring, labels, table order) read it
/// here, so neither needs the engine and a new surface needs only its preset file. Codes are
/// those of the published confusion tables (Nordahl, Turchet & Serafin, IEEE TVCG 17(9), 2011).
#include <span>
#include <string_view>

namespace underfoot::base {

/// One surface preset.
struct SurfaceEntry {
    std::string_view id;       ///< the preset's id (its file name), e.g. "wood_reverb"
    std::string_view label;    ///< the preset's name, shown to people: "Wood (reverb)"
    std::string_view code;     ///< the published tables' code, "WR"; empty when it has none
    std::string_view baseId;   ///< the surface a listener names: "wood" for "wood_reverb"
    std::string_view category; ///< "solid", "aggregate" or "liquid"
};

/// One soundscape.
struct SoundscapeEntry {
    std::string_view id;    ///< e.g. "park_fall"
    std::string_view label; ///< its name: "Park in the fall"
};

/// Every surface: those of the published tables first, in the tables' row order, then the
/// others by id.
std::span<const SurfaceEntry> surfaces();
/// Every soundscape, in the order of the published tables, then the others by id.
std::span<const SoundscapeEntry> soundscapes();

} // namespace underfoot::base
