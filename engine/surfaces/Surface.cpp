// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/surfaces/Surface.h"

#include "base/DataDir.h"
#include "base/Suggest.h"
#include "base/TomlReader.h"
#include "engine/dsp/Random.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace underfoot::engine {
namespace fs = std::filesystem;

const char* toString(SurfaceCategory c) noexcept {
    switch (c) {
    case SurfaceCategory::Solid:
        return "solid";
    case SurfaceCategory::Aggregate:
        return "aggregate";
    case SurfaceCategory::Liquid:
        return "liquid";
    }
    return "?";
}

std::string surfacesDirectory() {
    return base::dataDirectory(base::DataKind::Surfaces);
}

namespace {
toml::table parseFile(const std::string& file) {
    return base::rethrowTomlAs<PresetError>(
        [&] { return base::parseTomlFile(file, "a surface preset (TOML)"); });
}
} // namespace

void Surface::loadLayers(const std::string& file, const toml::table& root,
                         const AccuracyOptions& options, int depth) {
    // Parameters of a base preset's layers are named "<base id>:layer[i]...".
    const std::string prefix = depth == 0 ? "" : fs::path(file).stem().string() + ":";
    PresetReader top(file, root, prefix, &params_);
    // Header keys are read by loadSurfaceFromString() for the outermost file.
    for (const char* k : {"id", "name", "category", "description", "gain_db", "reverb"})
        top.allow(k);
    top.allow("code", "the code of the published tables (two capital letters, e.g. \"BS\")");
    top.allow("base", "the id of another preset whose layers come first (a string)");
    top.allow("provenance", "a free table recording where the values came from (not read)");
    if (const auto* baseNode = root.get("base")) {
        const auto base = baseNode->value<std::string>();
        if (!base) top.fail("base", "expected the id of another preset (a string)");
        if (depth > 4) top.fail("base", "too many nested `base` presets (a cycle?)");
        const std::string baseFile = (fs::path(file).parent_path() / (*base + ".toml")).string();
        if (!fs::exists(baseFile))
            top.fail("base",
                     fmt::format("expected the id of another preset; there is no {}", baseFile));
        loadLayers(baseFile, parseFile(baseFile), options, depth + 1);
    }
    auto layerTables =
        top.tables("layer", "the layers, one sound source each (at least one, or a `base`)");
    if (layerTables.empty() && layers_.empty())
        top.fail("", "expected at least one [[layer]] table (or a `base` preset)");
    for (auto& reader : layerTables) {
        const std::string type = reader.string(
            "type", "", {}, "the layer's kind, which decides its other keys (required)");
        const std::string purpose =
            reader.string("purpose", "", {}, "one line: what this layer is for (required)");
        if (purpose.empty())
            reader.fail("purpose", "expected a one-line `purpose`: what this layer is for");
        const auto& kinds = layerKinds();
        auto it = std::find_if(kinds.begin(), kinds.end(),
                               [&](const LayerKind& k) { return type == k.name; });
        if (it == kinds.end()) {
            std::string names;
            for (const auto& k : kinds) names += (names.empty() ? "" : ", ") + std::string(k.name);
            reader.fail("type", fmt::format("expected a layer type ({}), got \"{}\"", names, type));
        }
        auto layer = it->make(reader, options);
        reader.finish();
        layers_.push_back(std::move(layer));
        info_.layerPurposes.push_back(type + ": " + purpose);
    }
    top.finish();
}

std::unique_ptr<Surface> loadSurfaceFromString(const std::string& text, const std::string& file,
                                               const AccuracyOptions& options) {
    const toml::table root =
        base::rethrowTomlAs<PresetError>([&] { return base::parseToml(text, file); });
    return Surface::fromTable(root, file, options);
}

std::unique_ptr<Surface> Surface::fromTable(const toml::table& root, const std::string& file,
                                            const AccuracyOptions& options) {
    auto surface = std::unique_ptr<Surface>(new Surface());
    PresetReader top(file, root, "", &surface->params_);
    auto& info = surface->info_;
    info.file = file;
    info.id = top.string("id", "", {}, "the surface id; must match the file name (required)");
    if (info.id.empty()) top.fail("", "expected `id`: the surface id (e.g. \"gravel\")");
    info.name =
        top.string("name", info.id, {}, "the name shown to the experimenter (default: the id)");
    info.description =
        top.string("description", "", {}, "one line: what it sounds like (required)");
    if (info.description.empty())
        top.fail("", "missing key `description`: one line saying what the surface sounds like");
    const std::string category = top.string("category", "", {"solid", "aggregate", "liquid"},
                                            "the kind of ground (required)");
    if (category.empty())
        top.fail("", "expected `category`: \"solid\", \"aggregate\" or \"liquid\"");
    info.category = category == "solid"       ? SurfaceCategory::Solid
                    : category == "aggregate" ? SurfaceCategory::Aggregate
                                              : SurfaceCategory::Liquid;
    surface->gain_ = dbToGain(
        top.number("gain_db", 0.0, -60.0, 60.0, "dB", "calibration of the whole surface's level"));
    if (auto reverb = top.table("reverb", "optional: a room the surface is heard in")) {
        ReverbSpec spec;
        spec.impulseResponse = reverb->string(
            "ir", "", {}, "an impulse response of engine/data/ir or a .wav file (required)");
        if (spec.impulseResponse.empty())
            reverb->fail("",
                         "expected `ir`: an impulse response name (e.g. \"wooden_room\") or file");
        spec.wetDb = reverb->number("wet_db", -8.0, -60.0, 12.0, "dB", "reverberated level");
        spec.dryDb = reverb->number("dry_db", 0.0, -60.0, 12.0, "dB", "direct sound level");
        reverb->finish();
        info.reverb = spec;
    }
    surface->loadLayers(file, root, options, 0);
    return surface;
}

std::unique_ptr<Surface> Surface::load(const std::string& file, const AccuracyOptions& options) {
    return fromTable(parseFile(file), file, options);
}

std::unique_ptr<Surface> Surface::loadById(const std::string& idOrPath,
                                           const AccuracyOptions& options) {
    if (idOrPath.size() > 5 && idOrPath.substr(idOrPath.size() - 5) == ".toml")
        return load(idOrPath, options);
    const std::string file = surfacesDirectory() + "/" + idOrPath + ".toml";
    if (!fs::exists(file)) {
        // Sorted, with the closest id suggested.
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(surfacesDirectory()))
            if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
        throw PresetError(
            fmt::format("unknown surface \"{}\": expected one of {} (or a .toml file)", idOrPath,
                        base::sortedIdsWithSuggestion(idOrPath, names)));
    }
    return load(file, options);
}

void Surface::prepare(const ProcessSpec& spec) {
    for (auto& l : layers_) l->prepare(spec);
}

void Surface::reset(std::uint64_t seed) noexcept {
    for (std::size_t i = 0; i < layers_.size(); ++i) layers_[i]->reset(Random::deriveSeed(seed, i));
}

void Surface::process(const float* grf, float* out, int n) noexcept {
    std::fill(out, out + n, 0.0f);
    for (auto& l : layers_) l->process(grf, out, n);
    const float g = static_cast<float>(gain_);
    for (int i = 0; i < n; ++i) out[i] *= g;
}

bool Surface::isSleeping() const noexcept {
    return std::all_of(layers_.begin(), layers_.end(),
                       [](const auto& l) { return l->isSleeping(); });
}

std::vector<SurfaceInfo> listSurfaces() {
    std::vector<SurfaceInfo> out;
    for (const auto& e : fs::directory_iterator(surfacesDirectory())) {
        if (e.path().extension() != ".toml") continue;
        out.push_back(Surface::load(e.path().string())->info());
    }
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    return out;
}

} // namespace underfoot::engine
