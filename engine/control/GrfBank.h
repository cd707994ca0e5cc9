// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A bank of heel and toe GRFs for sensor-triggered playback (the haptic shoes of Turchet et al.
/// 2010: when a heel or toe pressure sensor fires, one of five recorded heel or toe GRFs is
/// played).
///
/// Made from single stances of the VirtualWalker: the vertical force of a stance is split between
/// heel and forefoot by the progression of the centre of pressure, w_heel(s) = 1 up to 30 % of
/// stance, cos^2 down to 0 at 60 % (heel-off occurs around mid-stance and the forefoot carries the
/// push-off; Perry & Burnfield 2010, ch. 2, "rockers"). heel = F w_heel, toe = F (1 - w_heel),
/// so heel + toe = F exactly. Each heel GRF starts at heel strike; each toe GRF starts where the
/// forefoot force first exceeds 1 % of its peak, so that firing it is immediate.
#include "engine/control/GrfFile.h"
#include "engine/control/VirtualWalker.h"

#include <cstdint>
#include <vector>

namespace underfoot::engine {

/// Heel share of the vertical force at stance-normalised time s.
double heelShare(double s) noexcept;

struct GrfBank {
    std::vector<GrfSignal> heel; ///< one mono GRF ("heel") per entry, newtons
    std::vector<GrfSignal> toe;  ///< one mono GRF ("toe") per entry, newtons
};

/// `count` heel and `count` toe GRFs from consecutive left-foot stances of a walker with the
/// given parameters (use some variability so that they differ) and seed.
GrfBank makeGrfBank(const WalkerParameters& walker, int count, std::uint64_t seed,
                    double sampleRateHz);

} // namespace underfoot::engine
