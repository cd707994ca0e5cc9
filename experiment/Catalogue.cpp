// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Catalogue.h"

#include "base/Catalogue.h"

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
    // Built once from the project's catalogue, which the build generates from the presets.
    static const Catalogue catalogue = [] {
        Catalogue c;
        for (const auto& s : base::surfaces())
            c.surfaces.push_back({std::string(s.id), std::string(s.label), std::string(s.code)});
        for (const auto& s : base::soundscapes())
            c.soundscapes.push_back({std::string(s.id), std::string(s.label), ""});
        return c;
    }();
    return catalogue;
}

std::string baseSurface(std::string_view surfaceId) {
    if (surfaceId.size() > kReverbSuffix.size() && surfaceId.ends_with(kReverbSuffix))
        return std::string(surfaceId.substr(0, surfaceId.size() - kReverbSuffix.size()));
    return std::string(surfaceId);
}

} // namespace underfoot::experiment
