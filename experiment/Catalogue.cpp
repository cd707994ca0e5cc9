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

std::string closestName(std::string_view name, const std::vector<std::string>& candidates) {
    auto lower = [](char c) {
        return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    };
    std::string best;
    std::size_t bestDistance = std::max<std::size_t>(1, name.size() / 2) + 1;
    std::vector<std::size_t> row, previous;
    for (const auto& candidate : candidates) {
        // Wagner-Fischer, two rows.
        previous.resize(candidate.size() + 1);
        row.resize(candidate.size() + 1);
        for (std::size_t j = 0; j <= candidate.size(); ++j) previous[j] = j;
        for (std::size_t i = 1; i <= name.size(); ++i) {
            row[0] = i;
            for (std::size_t j = 1; j <= candidate.size(); ++j)
                row[j] = std::min(
                    {previous[j] + 1, row[j - 1] + 1,
                     previous[j - 1] + (lower(name[i - 1]) == lower(candidate[j - 1]) ? 0 : 1)});
            std::swap(row, previous);
        }
        std::size_t distance = previous[candidate.size()];
        // A name contained in the candidate ("snow" in "deep_snow") counts as close.
        std::string lowered(candidate), wanted(name);
        for (auto& c : lowered) c = lower(c);
        for (auto& c : wanted) c = lower(c);
        if (!wanted.empty() && lowered.find(wanted) != std::string::npos)
            distance = std::min<std::size_t>(distance, 1);
        if (distance < bestDistance) {
            bestDistance = distance;
            best = candidate;
        }
    }
    return best;
}

std::string sortedIdsWithSuggestion(std::string_view name, std::vector<std::string> ids) {
    std::sort(ids.begin(), ids.end());
    std::string out;
    for (const auto& id : ids) out += (out.empty() ? "" : ", ") + id;
    if (const std::string close = closestName(name, ids); !close.empty())
        out += " (did you mean '" + close + "'?)";
    return out;
}

} // namespace underfoot::experiment
