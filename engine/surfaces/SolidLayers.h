// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Layers of solid floors: "impact" (Hunt–Crossley strikes of the sole on a modal floor) and
/// "friction" (elasto-plastic stick–slip for creaking boards). See the .cpp files for the
/// parameters each reads from a preset, with units and ranges.
#include "engine/surfaces/Layer.h"

namespace underfoot::engine {

std::unique_ptr<SurfaceLayer> makeImpactLayer(PresetReader& reader, const AccuracyOptions& options);
std::unique_ptr<SurfaceLayer> makeFrictionLayer(PresetReader& reader,
                                                const AccuracyOptions& options);

} // namespace underfoot::engine
