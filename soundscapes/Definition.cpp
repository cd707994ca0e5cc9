// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Definition.h"

#include "base/TomlReader.h"
#include "soundscapes/DefinitionReader.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace underfoot::soundscapes {
namespace {

bool validId(const std::string& s) {
    if (s.empty()) return false;
    for (char c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
    return true;
}

std::string resolvePath(const std::string& file, const std::string& base) {
    std::filesystem::path p(file);
    if (p.is_absolute() || base.empty()) return p.lexically_normal().string();
    return (std::filesystem::path(base) / p).lexically_normal().string();
}

LayerDefinition parseLayer(const DefinitionReader& r, const toml::table& t, const toml::node& node,
                           LayerKind kind, const std::string& base) {
    const std::string context = kind == LayerKind::Bed ? "[[bed]]" : "[[event]]";
    std::set<std::string> allowed{"name",     "generator", "file",   "files",
                                  "level_db", "params",    "enabled"};
    if (kind == LayerKind::Bed)
        allowed.insert("crossfade_s");
    else
        allowed.insert({"rate_per_minute", "mean_interval_s", "jitter", "gain_db", "pan",
                        "max_voices", "first_onset_s"});
    r.checkKeys(t, allowed, context);

    LayerDefinition layer;
    layer.kind = kind;
    layer.location = r.where(node);
    layer.name = r.string(t, "name", context, node, true);
    if (!validId(layer.name))
        r.fail(*t.get("name"), "layer name must be letters, digits or '_' (it names the layer "
                               "in messages and statistics)");
    layer.levelDb = r.number(t, "level_db", -80.0, 40.0, 0.0);

    const toml::node* gen = t.get("generator");
    const toml::node* file = t.get("file");
    const toml::node* files = t.get("files");
    const int sources = (gen ? 1 : 0) + (file ? 1 : 0) + (files ? 1 : 0);
    if (sources != 1)
        r.fail(node, fmt::format("layer '{}' needs exactly one of 'generator', 'file' or 'files'",
                                 layer.name));
    if (gen) {
        layer.source = LayerSource::Procedural;
        layer.generator = r.string(t, "generator", context, node, true);
        const GeneratorInfo* info = findGenerator(layer.generator);
        if (!info || info->kind != kind) {
            std::string list;
            for (const auto& g : generatorCatalogue())
                if (g.kind == kind) list += (list.empty() ? "" : ", ") + g.name;
            r.fail(*gen,
                   fmt::format("unknown {} generator '{}' (expected one of: {})",
                               kind == LayerKind::Bed ? "bed" : "event", layer.generator, list));
        }
        layer.params.setGenerator(info);
        if (const toml::node* params = t.get("params")) {
            const toml::table* pt = params->as_table();
            if (!pt) r.fail(*params, "'params' must be a table, e.g. params = { pitch_hz = 500 }");
            for (const auto& [key, value] : *pt) {
                const ParamInfo* pi = nullptr;
                for (const auto& p : info->params)
                    if (p.name == key.str()) pi = &p;
                if (!pi) {
                    std::string list;
                    for (const auto& p : info->params) list += (list.empty() ? "" : ", ") + p.name;
                    r.fail(value, fmt::format("generator '{}' has no parameter '{}' (expected "
                                              "one of: {})",
                                              layer.generator, key.str(), list));
                }
                layer.params.set(pi->name, r.number(value, key.str(), pi->minValue, pi->maxValue));
            }
        }
    } else {
        if (t.get("params")) r.fail(*t.get("params"), "'params' applies to generators only");
        layer.source = LayerSource::Recording;
        if (file) {
            layer.files.push_back(resolvePath(r.string(t, "file", context, node, true), base));
        } else {
            const toml::array* a = files->as_array();
            if (!a || a->empty()) r.fail(*files, "'files' must be a non-empty array of paths");
            for (const auto& f : *a) {
                if (!f.is_string()) r.fail(f, "'files' entries must be strings (paths)");
                layer.files.push_back(resolvePath(std::string(*f.as_string()), base));
            }
            if (kind == LayerKind::Bed && layer.files.size() != 1)
                r.fail(*files, "a bed loops one recording: use 'file'");
        }
    }
    if (const toml::node* en = t.get("enabled"); en && !en->is_boolean())
        r.fail(*en, "'enabled' must be true or false");

    if (kind == LayerKind::Bed) {
        layer.crossfadeSeconds = r.number(t, "crossfade_s", 0.0, 60.0, 2.0);
    } else {
        const toml::node* rate = t.get("rate_per_minute");
        const toml::node* interval = t.get("mean_interval_s");
        if ((rate ? 1 : 0) + (interval ? 1 : 0) != 1)
            r.fail(node, fmt::format("event layer '{}' needs exactly one of 'rate_per_minute' "
                                     "or 'mean_interval_s'",
                                     layer.name));
        layer.ratePerMinute = rate ? r.number(*rate, "rate_per_minute", 0.01, 6000.0)
                                   : 60.0 / r.number(*interval, "mean_interval_s", 0.01, 6000.0);
        layer.jitter = r.number(t, "jitter", 0.0, 1.0, 1.0);
        if (const toml::node* g = t.get("gain_db"))
            std::tie(layer.gainDbMin, layer.gainDbMax) = r.range(*g, "gain_db", -80.0, 40.0);
        if (const toml::node* p = t.get("pan"))
            std::tie(layer.panMin, layer.panMax) = r.range(*p, "pan", -1.0, 1.0);
        layer.maxVoices = static_cast<int>(r.number(t, "max_voices", 1.0, 64.0, 4.0));
        if (const toml::node* f = t.get("first_onset_s"))
            layer.firstOnsetSeconds = r.range(*f, "first_onset_s", 0.0, 3600.0);
    }
    return layer;
}

} // namespace

SoundscapeDefinition parseSoundscapeDefinition(std::string_view text, const std::string& sourceName,
                                               const std::string& baseDirectory) {
    const toml::table root =
        base::rethrowTomlAs<DefinitionError>([&] { return base::parseToml(text, sourceName); });
    DefinitionReader r(sourceName);
    r.checkKeys(root, {"soundscape", "bed", "event"}, "the file");

    const toml::node* head = root.get("soundscape");
    if (!head || !head->is_table())
        throw DefinitionError(fmt::format("{}:1:1: expected a [soundscape] table (id, name, "
                                          "description, target_level_dbfs, "
                                          "footstep_reference_gain_db)",
                                          sourceName));
    const toml::table& h = *head->as_table();
    r.checkKeys(h, {"id", "name", "description", "target_level_dbfs", "footstep_reference_gain_db"},
                "[soundscape]");
    SoundscapeDefinition def;
    def.id = r.string(h, "id", "[soundscape]", *head, true);
    if (!validId(def.id)) r.fail(*h.get("id"), "id must be letters, digits or '_'");
    def.name = r.string(h, "name", "[soundscape]", *head, true);
    def.description = r.string(h, "description", "[soundscape]", *head, false);
    if (!h.get("target_level_dbfs"))
        r.fail(*head, "[soundscape] needs 'target_level_dbfs' (long-term RMS level of the mix)");
    def.targetLevelDbfs = r.number(h, "target_level_dbfs", -90.0, -3.0, -30.0);
    def.footstepReferenceGainDb = r.number(h, "footstep_reference_gain_db", -60.0, 20.0, -10.0);

    std::set<std::string> names;
    for (const auto& section :
         {std::pair{"bed", LayerKind::Bed}, std::pair{"event", LayerKind::Event}}) {
        r.forEachTable(root, section.first, [&](const toml::table& t, const toml::node& item) {
            LayerDefinition layer = parseLayer(r, t, item, section.second, baseDirectory);
            if (!names.insert(layer.name).second)
                r.failAt(layer.location, fmt::format("duplicate layer name '{}'", layer.name));
            const toml::node* en = t.get("enabled");
            if (en && !en->as_boolean()->get()) return; // declared off: never computed
            def.layers.push_back(std::move(layer));
        });
    }
    if (def.layers.empty())
        throw DefinitionError(fmt::format("{}: a soundscape needs at least one enabled [[bed]] or "
                                          "[[event]] layer",
                                          sourceName));
    return def;
}

SoundscapeDefinition loadSoundscapeDefinition(const std::string& path) {
    const std::string text = base::rethrowTomlAs<DefinitionError>(
        [&] { return base::readTomlFile(path, "a readable TOML soundscape definition"); });
    const std::string directory = std::filesystem::path(path).parent_path().string();
    SoundscapeDefinition def = parseSoundscapeDefinition(text, path, directory);
    def.sourcePath = path;
    return def;
}

} // namespace underfoot::soundscapes
