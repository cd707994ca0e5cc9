// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Writing a new surface preset from an existing one with some parameters changed (the sound
/// palette's "save as"). The result is self-contained: the layers of `base` presets are copied
/// in, so it loads from any folder.
#include <map>
#include <string>

namespace underfoot::gui {

/// Parameter path (as engine::ParamInfo::path, e.g. "layer[2].stiffness" or
/// "wood:.layer[1].modes[3].freq_hz") -> new value.
using ParamValues = std::map<std::string, double>;

/// The TOML text of a preset derived from `presetFile`: `values` applied, `id` and `name` set.
/// Throws std::runtime_error naming the file and the parameter that could not be placed.
std::string derivePresetToml(const std::string& presetFile, const ParamValues& values,
                             const std::string& id, const std::string& name);

} // namespace underfoot::gui
