// SPDX-License-Identifier: GPL-3.0-or-later
// The table of layer kinds. Each kind's factory lives beside its layer.
#include "engine/surfaces/Layer.h"
#include "engine/surfaces/SolidLayers.h"

namespace underfoot::engine {

const std::vector<LayerKind>& layerKinds() {
    static const std::vector<LayerKind> kinds = {
        {"impact", &makeImpactLayer,
         "Hunt-Crossley impacts of the sole on a modal floor, struck at each GRF onset"},
        {"friction", &makeFrictionLayer,
         "elasto-plastic (Dupont) stick-slip of boards driven by the load's changes (creaks)"},
    };
    return kinds;
}

} // namespace underfoot::engine
