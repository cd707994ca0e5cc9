// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/model/Catalog.h"

#include <algorithm>
#include <cctype>

namespace underfoot::analysis {

namespace {

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) ==
                      std::tolower(static_cast<unsigned char>(y));
           });
}

} // namespace

const std::vector<SurfaceInfo>& surfaceCatalog() {
    using C = SurfaceCategory;
    static const std::vector<SurfaceInfo> catalog{
        {"beach_sand", "Beach sand", "BS", "beach_sand", C::Aggregate},
        {"gravel", "Gravel", "GL", "gravel", C::Aggregate},
        {"dirt_pebbles", "Dirt (pebbles)", "DR", "dirt_pebbles", C::Aggregate},
        {"deep_snow", "Deep snow", "SW", "deep_snow", C::Aggregate},
        {"high_grass", "High grass", "HG", "high_grass", C::Aggregate},
        {"forest_underbrush", "Forest underbrush", "UB", "forest_underbrush", C::Aggregate},
        {"dry_leaves", "Dry leaves", "DL", "dry_leaves", C::Aggregate},
        {"wood", "Wood", "WD", "wood", C::Solid},
        {"creaking_wood", "Creaking wood", "CW", "creaking_wood", C::Solid},
        {"metal", "Metal", "MT", "metal", C::Solid},
        {"wood_reverb", "Wood (reverb)", "WR", "wood", C::Solid},
        {"creaking_wood_reverb", "Creaking wood (reverb)", "CR", "creaking_wood", C::Solid},
        {"metal_reverb", "Metal (reverb)", "MR", "metal", C::Solid},
        {"frozen_snow", "Frozen snow", "FS", "frozen_snow", C::Aggregate},
        {"concrete", "Concrete", "CC", "concrete", C::Solid},
        {"puddles", "Puddles", "PD", "puddles", C::Liquid},
        {"water", "Water", "WT", "water", C::Liquid},
        {"carpet", "Carpet", "CP", "carpet", C::Solid},
    };
    return catalog;
}

std::optional<SurfaceInfo> findSurface(std::string_view idOrCode) {
    for (const auto& s : surfaceCatalog())
        if (s.id == idOrCode || equalsIgnoreCase(s.code, idOrCode)) return s;
    return std::nullopt;
}

std::string baseSurfaceId(std::string_view surfaceId) {
    if (auto s = findSurface(surfaceId)) return s->baseId;
    return std::string(surfaceId);
}

SurfaceCategory surfaceCategory(std::string_view surfaceId) {
    if (auto s = findSurface(surfaceId)) return s->category;
    return SurfaceCategory::Unknown;
}

const char* categoryName(SurfaceCategory category) {
    switch (category) {
    case SurfaceCategory::Solid:
        return "solid";
    case SurfaceCategory::Aggregate:
        return "aggregate";
    case SurfaceCategory::Liquid:
        return "liquid";
    case SurfaceCategory::Unknown:
        break;
    }
    return "unknown";
}

const std::vector<SoundscapeInfo>& soundscapeCatalog() {
    static const std::vector<SoundscapeInfo> catalog{
        {"beach_summer", "Beach in summer"}, {"farm_courtyard", "Courtyard of a farm"},
        {"ski_slope", "Ski slope"},          {"forest", "Forest"},
        {"park_fall", "Park in the fall"},
    };
    return catalog;
}

std::optional<std::string> findSoundscapeId(std::string_view idOrLabel) {
    for (const auto& s : soundscapeCatalog())
        if (s.id == idOrLabel || equalsIgnoreCase(s.label, idOrLabel)) return s.id;
    // Short labels of the published tables.
    static const std::pair<std::string_view, std::string_view> aliases[] = {
        {"beach", "beach_summer"}, {"farm", "farm_courtyard"}, {"courtyard", "farm_courtyard"},
        {"park", "park_fall"},     {"ski slope", "ski_slope"}, {"forest", "forest"}};
    for (const auto& [alias, id] : aliases)
        if (equalsIgnoreCase(alias, idOrLabel)) return std::string(id);
    return std::nullopt;
}

std::string labelFor(std::string_view id) {
    if (id == kDontKnowId) return "I don't know";
    for (const auto& s : surfaceCatalog())
        if (s.id == id) return s.label;
    for (const auto& s : soundscapeCatalog())
        if (s.id == id) return s.label;
    return std::string(id);
}

std::optional<std::size_t> AnswerList::indexOf(std::string_view id) const {
    for (std::size_t i = 0; i < options.size(); ++i)
        if (options[i].id == id) return i;
    return std::nullopt;
}

void AnswerList::addBeforeDontKnow(const std::string& id) {
    if (indexOf(id)) return;
    auto dk = std::find_if(options.begin(), options.end(),
                           [](const AnswerOption& o) { return o.id == kDontKnowId; });
    options.insert(dk, AnswerOption{id, labelFor(id)});
}

AnswerList defaultAnswerList() {
    AnswerList list;
    for (const char* id : {"beach_sand", "gravel", "dirt_pebbles", "deep_snow", "high_grass",
                           "forest_underbrush", "dry_leaves", "wood", "creaking_wood", "metal",
                           "carpet", "concrete", "frozen_snow", "puddles", "water"})
        list.options.push_back({id, labelFor(id)});
    list.options.push_back({std::string(kDontKnowId), labelFor(kDontKnowId)});
    return list;
}

} // namespace underfoot::analysis
