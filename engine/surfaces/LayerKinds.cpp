// SPDX-License-Identifier: GPL-3.0-or-later
// The table of layer kinds. Each kind's factory lives beside its layer.
#include "engine/surfaces/GranularLayers.h"
#include "engine/surfaces/Layer.h"
#include "engine/surfaces/LiquidLayers.h"
#include "engine/surfaces/SolidLayers.h"

namespace underfoot::engine {

const std::vector<LayerKind>& layerKinds() {
    static const std::vector<LayerKind> kinds = {
        {"impact", &makeImpactLayer,
         "Hunt-Crossley impacts of the sole on a modal floor, struck at each GRF onset"},
        {"friction", &makeFrictionLayer,
         "elasto-plastic (Dupont) stick-slip of boards driven by the load's changes (creaks)"},
        {"grains", &makeGrainsLayer,
         "stochastic aggregate (PhISM/crumpling): Poisson micro-impacts with power-law energies, "
         "each ringing at random resonances, driven by the load and its changes"},
        {"bubbles", &makeBubblesLayer,
         "van den Doel bubble stream with splash and slosh noise, driven by the foot landing, "
         "moving and leaving the water"},
    };
    return kinds;
}

} // namespace underfoot::engine
