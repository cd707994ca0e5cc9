// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Coherence.h"

#include "base/TomlReader.h"

#include "soundscapes/Definition.h"
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

std::string where(const std::string& source, const toml::node& n) {
    return fmt::format("{}:{}:{}", source, n.source().begin.line, n.source().begin.column);
}
[[noreturn]] void fail(const std::string& source, const toml::node& n, const std::string& what) {
    throw DefinitionError(fmt::format("{}: {}", where(source, n), what));
}
std::string str(const std::string& source, const toml::table& t, const char* key,
                const toml::node& owner) {
    const toml::node* n = t.get(key);
    if (!n || !n->is_string())
        fail(source, n ? *n : owner, fmt::format("expected a string '{}'", key));
    std::string s(*n->as_string());
    if (s.empty()) fail(source, *n, fmt::format("'{}' must not be empty", key));
    return s;
}
void onlyKeys(const std::string& source, const toml::table& t, std::set<std::string> allowed,
              const char* context) {
    base::rethrowTomlAs<DefinitionError>([&] {
        base::TomlReader(source, base::TomlReader::Mode::Throw)
            .checkKeys(t, std::vector<std::string>(allowed.begin(), allowed.end()), context);
    });
}

// Calls each(entry, node) for every entry of the array of tables [[key]] of root (if present),
// each entry checked to be a table with only the allowed keys.
template <class Each>
void forEachEntry(const std::string& source, const toml::table& root, const char* key,
                  const std::set<std::string>& allowed, Each each) {
    const toml::node* n = root.get(key);
    if (!n) return;
    const std::string context = fmt::format("[[{}]]", key);
    const toml::array* arr = n->as_array();
    if (!arr) fail(source, *n, fmt::format("'{}' must be an array of tables: {}", key, context));
    for (const auto& item : *arr) {
        const toml::table* t = item.as_table();
        if (!t) fail(source, item, context + " entries must be tables");
        onlyKeys(source, *t, allowed, context.c_str());
        each(*t, item);
    }
}

} // namespace

CoherenceTable CoherenceTable::parse(const std::string& text, const std::string& source) {
    const toml::table root =
        base::rethrowTomlAs<DefinitionError>([&] { return base::parseToml(text, source); });
    onlyKeys(source, root, {"coherent", "incoherent"}, "the coherence file");
    CoherenceTable table;
    auto entryFor = [&](const std::string& surface) -> CoherenceEntry& {
        for (auto& e : table.entries_)
            if (e.surface == surface) return e;
        table.entries_.push_back({surface, std::nullopt, {}});
        return table.entries_.back();
    };
    forEachEntry(source, root, "coherent", {"surface", "soundscape"},
                 [&](const toml::table& t, const toml::node& item) {
                     CoherenceEntry& e = entryFor(str(source, t, "surface", item));
                     if (e.coherent)
                         fail(source, item,
                              fmt::format("surface '{}' already has a coherent soundscape ('{}')",
                                          e.surface, *e.coherent));
                     e.coherent = str(source, t, "soundscape", item);
                 });
    forEachEntry(
        source, root, "incoherent", {"surface", "soundscapes"},
        [&](const toml::table& t, const toml::node& item) {
            CoherenceEntry& e = entryFor(str(source, t, "surface", item));
            const toml::node* s = t.get("soundscapes");
            const toml::array* list = s ? s->as_array() : nullptr;
            if (!list || list->empty())
                fail(source, s ? *s : item, "expected 'soundscapes' = a non-empty array of ids");
            for (const auto& id : *list) {
                if (!id.is_string()) fail(source, id, "soundscape ids must be strings");
                std::string v(*id.as_string());
                if (std::find(e.incoherent.begin(), e.incoherent.end(), v) != e.incoherent.end())
                    fail(source, id, fmt::format("'{}' is listed twice for '{}'", v, e.surface));
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
