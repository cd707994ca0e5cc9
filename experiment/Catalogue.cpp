// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Catalogue.h"

#include <algorithm>
#include <cctype>

namespace underfoot::experiment {

namespace {
const CatalogueEntry* findIn(const std::vector<CatalogueEntry>& entries, std::string_view id) {
    const auto it = std::find_if(entries.begin(), entries.end(),
                                 [&](const CatalogueEntry& e) { return e.id == id; });
    return it == entries.end() ? nullptr : &*it;
}
} // namespace

const CatalogueEntry* Catalogue::surface(std::string_view id) const {
    return findIn(surfaces, id);
}

const CatalogueEntry* Catalogue::soundscape(std::string_view id) const {
    return findIn(soundscapes, id);
}

const CatalogueEntry* Catalogue::surfaceByCode(std::string_view code) const {
    const auto it = std::find_if(surfaces.begin(), surfaces.end(), [&](const CatalogueEntry& e) {
        return !e.code.empty() && e.code == code;
    });
    return it == surfaces.end() ? nullptr : &*it;
}

const Catalogue& defaultCatalogue() {
    static const Catalogue catalogue{
        // Codes from /work/shared/data/published/README.md.
        {{"beach_sand", "beach sand", "BS"},
         {"gravel", "gravel", "GL"},
         {"dirt_pebbles", "dirt", "DR"},
         {"deep_snow", "snow", "SW"},
         {"frozen_snow", "frozen snow", "FS"},
         {"high_grass", "high grass", "HG"},
         {"forest_underbrush", "forest underbrush", "UB"},
         {"dry_leaves", "dry leaves", "DL"},
         {"wood", "wood", "WD"},
         {"creaking_wood", "creaking wood", "CW"},
         {"metal", "metal", "MT"},
         {"concrete", "concrete", "CC"},
         {"carpet", "carpet", "CP"},
         {"puddles", "puddles", "PD"},
         {"water", "water", "WT"},
         {"wood_reverb", "wood with reverb", "WR"},
         {"creaking_wood_reverb", "creaking wood with reverb", "CR"},
         {"metal_reverb", "metal with reverb", "MR"}},
        {{"beach_summer", "beach in summer", ""},
         {"farm_courtyard", "courtyard of a farm in the countryside", ""},
         {"ski_slope", "ski slope", ""},
         {"forest", "forest", ""},
         {"park_fall", "park in the fall", ""}}};
    return catalogue;
}

std::string baseSurface(std::string_view surfaceId) {
    if (surfaceId.size() > kReverbSuffix.size() && surfaceId.ends_with(kReverbSuffix))
        return std::string(surfaceId.substr(0, surfaceId.size() - kReverbSuffix.size()));
    return std::string(surfaceId);
}

} // namespace underfoot::experiment
