// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A walkable surface: a preset file (TOML, physical units) whose layers are summed.
///
/// Preset format (engine/data/surfaces/<id>.toml):
///   id = "gravel"                 # must match the file name
///   name = "Gravel"
///   category = "aggregate"        # solid | aggregate | liquid
///   description = "one line: what it sounds like"
///   gain_db = 0.0                 # calibration of the whole surface
///   base = "wood"                 # optional: start from another preset's layers
///   [reverb]                      # optional: rendered through a room impulse response
///   ir = "wooden_room"  wet_db = -8.0  dry_db = 0.0
///   [[layer]]
///   type = "impact"               # a kind from layerKinds()
///   purpose = "what this layer is for"
///   ...                           # the kind's parameters, each with unit and range
#include "engine/surfaces/Layer.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::engine {

enum class SurfaceCategory { Solid, Aggregate, Liquid };
const char* toString(SurfaceCategory c) noexcept;

struct ReverbSpec {
    std::string impulseResponse; ///< a name from engine/data/ir or a file path
    double wetDb = -8.0;
    double dryDb = 0.0;
};

struct SurfaceInfo {
    std::string id, name, description, file;
    SurfaceCategory category = SurfaceCategory::Solid;
    std::optional<ReverbSpec> reverb;
    std::vector<std::string> layerPurposes; ///< "type: purpose" per layer
};

class Surface {
  public:
    /// Loads a preset file. Throws PresetError naming file:line:column and what was expected.
    static std::unique_ptr<Surface> load(const std::string& file,
                                         const AccuracyOptions& options = {});
    /// Loads engine/data/surfaces/<id>.toml (or a path when `idOrPath` ends in .toml).
    static std::unique_ptr<Surface> loadById(const std::string& idOrPath,
                                             const AccuracyOptions& options = {});

    void prepare(const ProcessSpec& spec);
    void reset(std::uint64_t seed) noexcept;
    /// Writes n samples (overwrites `out`) driven by the vertical GRF in newtons.
    void process(const float* grfNewtons, float* out, int n) noexcept;
    bool isSleeping() const noexcept;

    const SurfaceInfo& info() const noexcept { return info_; }
    /// Every numeric parameter read from the preset, with unit and documented range.
    const std::vector<ParamInfo>& parameters() const noexcept { return params_; }
    int layerCount() const noexcept { return static_cast<int>(layers_.size()); }
    const SurfaceLayer& layer(int i) const { return *layers_.at(static_cast<std::size_t>(i)); }

    /// Builds a surface from a parsed preset (`file` names it in errors).
    static std::unique_ptr<Surface> fromTable(const toml::table& root, const std::string& file,
                                              const AccuracyOptions& options = {});

  private:
    Surface() = default;
    void loadLayers(const std::string& file, const toml::table& root,
                    const AccuracyOptions& options, int depth);
    SurfaceInfo info_;
    double gain_ = 1.0;
    std::vector<std::unique_ptr<SurfaceLayer>> layers_;
    std::vector<ParamInfo> params_;
};

/// Folder holding the bundled surface presets ($UNDERFOOT_SURFACES_DIR, else as
/// base::dataDirectory finds it).
std::string surfacesDirectory();
/// All bundled surfaces, sorted by id (loads each preset's header; throws on a broken preset).
std::vector<SurfaceInfo> listSurfaces();
/// Parses a preset held in a string (for tests and the sound palette); `file` names it in errors.
std::unique_ptr<Surface> loadSurfaceFromString(const std::string& text, const std::string& file,
                                               const AccuracyOptions& options = {});

} // namespace underfoot::engine
