// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Coherence.h"

#include "base/TomlReader.h"

#include "soundscapes/Definition.h"
#include "soundscapes/DefinitionReader.h"
#include "soundscapes/Library.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace underfoot::soundscapes {
namespace {

// A required, non-empty string.
std::string str(const DefinitionReader& r, const toml::table& t, const char* key,
                const toml::node& owner) {
    const toml::node* n = t.get(key);
    if (!n || !n->is_string()) r.fail(n ? *n : owner, fmt::format("expected a string '{}'", key));
    std::string s(*n->as_string());
    if (s.empty()) r.fail(*n, fmt::format("'{}' must not be empty", key));
    return s;
}

} // namespace

CoherenceTable CoherenceTable::parse(const std::string& text, const std::string& source) {
    const toml::table root =
        base::rethrowTomlAs<DefinitionError>([&] { return base::parseToml(text, source); });
    const DefinitionReader r(source);
    r.checkKeys(root, {"coherent", "incoherent"}, "the coherence file");
    CoherenceTable table;
    auto entryFor = [&](const std::string& surface) -> CoherenceEntry& {
        for (auto& e : table.entries_)
            if (e.surface == surface) return e;
        table.entries_.push_back({surface, std::nullopt, {}});
        return table.entries_.back();
    };
    r.forEachTable(root, "coherent", [&](const toml::table& t, const toml::node& item) {
        r.checkKeys(t, {"surface", "soundscape"}, "[[coherent]]");
        CoherenceEntry& e = entryFor(str(r, t, "surface", item));
        if (e.coherent)
            r.fail(item, fmt::format("surface '{}' already has a coherent soundscape ('{}')",
                                     e.surface, *e.coherent));
        e.coherent = str(r, t, "soundscape", item);
    });
    r.forEachTable(root, "incoherent", [&](const toml::table& t, const toml::node& item) {
        r.checkKeys(t, {"surface", "soundscapes"}, "[[incoherent]]");
        CoherenceEntry& e = entryFor(str(r, t, "surface", item));
        const toml::node* s = t.get("soundscapes");
        const toml::array* list = s ? s->as_array() : nullptr;
        if (!list || list->empty())
            r.fail(s ? *s : item, "expected 'soundscapes' = a non-empty array of ids");
        for (const auto& id : *list) {
            if (!id.is_string()) r.fail(id, "soundscape ids must be strings");
            std::string v(*id.as_string());
            if (std::find(e.incoherent.begin(), e.incoherent.end(), v) != e.incoherent.end())
                r.fail(id, fmt::format("'{}' is listed twice for '{}'", v, e.surface));
            e.incoherent.push_back(std::move(v));
        }
    });
    for (const auto& e : table.entries_)
        for (const auto& inc : e.incoherent)
            if (e.coherent && inc == *e.coherent)
                throw DefinitionError(fmt::format("{}: '{}' is declared both coherent and "
                                                  "incoherent with surface '{}'",
                                                  source, inc, e.surface));
    return table;
}

CoherenceTable CoherenceTable::load(const std::string& path) {
    return parse(base::rethrowTomlAs<DefinitionError>(
                     [&] { return base::readTomlFile(path, "a readable TOML coherence table"); }),
                 path);
}

const CoherenceTable& CoherenceTable::builtin() {
    static const CoherenceTable table =
        load((std::filesystem::path(soundscapeDataDirectory()) / "coherence.toml").string());
    return table;
}

const CoherenceEntry* CoherenceTable::find(const std::string& surface) const {
    for (const auto& e : entries_)
        if (e.surface == surface) return &e;
    return nullptr;
}

std::optional<std::string> CoherenceTable::coherentSoundscapeFor(const std::string& surface) const {
    const CoherenceEntry* e = find(surface);
    return e ? e->coherent : std::nullopt;
}

std::vector<std::string>
CoherenceTable::incoherentSoundscapesFor(const std::string& surface) const {
    const CoherenceEntry* e = find(surface);
    return e ? e->incoherent : std::vector<std::string>{};
}

std::vector<std::string> CoherenceTable::surfacesCoherentWith(const std::string& soundscape) const {
    std::vector<std::string> out;
    for (const auto& e : entries_)
        if (e.coherent && *e.coherent == soundscape) out.push_back(e.surface);
    return out;
}

bool CoherenceTable::isCoherent(const std::string& surface, const std::string& soundscape) const {
    const auto c = coherentSoundscapeFor(surface);
    return c && *c == soundscape;
}

std::vector<std::string> CoherenceTable::soundscapes() const {
    std::set<std::string> all;
    for (const auto& e : entries_) {
        if (e.coherent) all.insert(*e.coherent);
        all.insert(e.incoherent.begin(), e.incoherent.end());
    }
    return {all.begin(), all.end()};
}

} // namespace underfoot::soundscapes
