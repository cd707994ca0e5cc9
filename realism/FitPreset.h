// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Internal to realism/: what `underfoot fit` (realism/Fit.h) does to a surface preset's TOML:
/// the knobs it may move and how each rewrites the layers, the recorded modes written into the
/// impact layers (the modal seed), and the preset's readable text.
#include "realism/Fit.h"

#include <toml++/toml.h>

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace underfoot::realism::fitpreset {

/// Each knob's admissible range per preset key (the presets' declared ranges).
using Ranges = std::map<std::string, std::pair<double, double>>;

/// A knob of the fit: its name, meaning, range and value (Fit.h), and how a value k rewrites
/// the preset (clamped to the keys' ranges).
struct Knob {
    FitKnob info;
    std::function<void(toml::table& root, double k, const Ranges& ranges)> apply;
};

/// The preset parsed; a syntax error throws std::invalid_argument naming the file and place.
toml::table parsePreset(const std::string& presetFile);
/// Whether the preset has a layer of that type (and how many, into *count).
bool hasLayer(const toml::table& root, const std::string& type, int* count = nullptr);
/// The knobs the fit moves for this preset, each with its range and meaning.
std::vector<Knob> knobsFor(const toml::table& root);
/// TOML text with every long decimal written with 6 significant digits.
std::string toText(const toml::table& t);
/// The most modes of any impact layer.
int impactModeCount(const toml::table& root);
/// Replaces every impact layer's modes by the recorded ones (Fit.h, "Modal seed").
void seedImpactModes(toml::table& root, const std::vector<RecordedMode>& recorded,
                     double clusterOctaves);

} // namespace underfoot::realism::fitpreset
