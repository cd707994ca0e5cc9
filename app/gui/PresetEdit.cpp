// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/PresetEdit.h"

#include "base/TomlReader.h"

#include <toml++/toml.h>

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace underfoot::gui {

namespace fs = std::filesystem;

namespace {

struct Flat {
    toml::table root;
    /// First flattened layer index of each base file's layers, by file stem.
    std::map<std::string, std::size_t> offsets;
};

toml::table parse(const std::string& file) {
    return base::parseTomlFile(file, "a surface preset (TOML)"); // TomlError: a runtime_error
}

/// The preset with every base preset's layers copied in front of its own (the engine's order).
Flat flatten(const std::string& file, int depth) {
    if (depth > 4) throw std::runtime_error(file + ": too many nested `base` presets");
    Flat flat;
    flat.root = parse(file);
    toml::array layers;
    if (auto base = flat.root["base"].value<std::string>()) {
        const std::string baseFile = (fs::path(file).parent_path() / (*base + ".toml")).string();
        Flat inner = flatten(baseFile, depth + 1);
        for (auto& [stem, offset] : inner.offsets) flat.offsets[stem] = offset;
        flat.offsets[*base] = 0;
        if (auto* l = inner.root["layer"].as_array()) layers = *l;
        flat.root.erase("base");
    }
    const std::size_t own = layers.size();
    if (auto* l = flat.root["layer"].as_array())
        for (auto& node : *l) layers.push_back(node);
    flat.root.insert_or_assign("layer", std::move(layers));
    flat.offsets[""] = own;
    return flat;
}

/// "name[3]" -> ("name", 2); "name" -> ("name", npos).
std::pair<std::string, std::size_t> segment(const std::string& s) {
    const auto open = s.find('[');
    if (open == std::string::npos || s.back() != ']') return {s, std::string::npos};
    const std::size_t index = std::stoul(s.substr(open + 1, s.size() - open - 2));
    if (index == 0) throw std::runtime_error("index 0 in " + s + " (indices start at 1)");
    return {s.substr(0, open), index - 1};
}

} // namespace

std::string derivePresetToml(const std::string& presetFile, const ParamValues& values,
                             const std::string& id, const std::string& name) {
    Flat flat = flatten(presetFile, 0);
    for (const auto& [path, value] : values) {
        std::string rest = path;
        std::string stem;
        if (const auto colon = rest.find(':'); colon != std::string::npos) {
            stem = rest.substr(0, colon);
            rest = rest.substr(colon + 1);
            if (!rest.empty() && rest.front() == '.') rest.erase(0, 1);
        }
        const auto offset = flat.offsets.find(stem);
        if (offset == flat.offsets.end())
            throw std::runtime_error(presetFile + ": parameter " + path + " names preset '" + stem +
                                     "', which is not one of its bases");
        std::vector<std::string> parts;
        std::stringstream ss(rest);
        for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
        if (parts.empty()) throw std::runtime_error(presetFile + ": empty parameter path");
        toml::table* table = &flat.root;
        for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
            auto [key, index] = segment(parts[i]);
            if (i == 0 && key == "layer" && index != std::string::npos) index += offset->second;
            toml::node* node = table->get(key);
            if (index == std::string::npos) {
                if (!node) node = &table->insert_or_assign(key, toml::table{}).first->second;
                table = node->as_table();
            } else {
                auto* array = node ? node->as_array() : nullptr;
                table = array && index < array->size() ? array->get(index)->as_table() : nullptr;
            }
            if (!table)
                throw std::runtime_error(presetFile + ": parameter " + path +
                                         " does not match the preset's tables");
        }
        table->insert_or_assign(parts.back(), value);
    }
    flat.root.insert_or_assign("id", id);
    flat.root.insert_or_assign("name", name);
    std::ostringstream out;
    out << "# Surface preset saved by underfoot-gui's sound palette from "
        << fs::path(presetFile).filename().string() << ".\n"
        << flat.root << "\n";
    return out.str();
}

} // namespace underfoot::gui
