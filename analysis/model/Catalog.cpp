// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/model/Catalog.h"

#include "base/Catalogue.h"

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
    // The project's catalogue (generated from the presets), in the published tables' order.
    static const std::vector<SurfaceInfo> catalog = [] {
        std::vector<SurfaceInfo> out;
        for (const auto& s : base::surfaces()) {
            const auto category = s.category == "solid"       ? SurfaceCategory::Solid
                                  : s.category == "aggregate" ? SurfaceCategory::Aggregate
                                  : s.category == "liquid"    ? SurfaceCategory::Liquid
                                                              : SurfaceCategory::Unknown;
            out.push_back({std::string(s.id), std::string(s.label), std::string(s.code),
                           std::string(s.baseId), category});
        }
        return out;
    }();
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
    static const std::vector<SoundscapeInfo> catalog = [] {
        std::vector<SoundscapeInfo> out;
        for (const auto& s : base::soundscapes())
            out.push_back({std::string(s.id), std::string(s.label)});
        return out;
    }();
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
