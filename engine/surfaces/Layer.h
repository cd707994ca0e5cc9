// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A surface is a sum of layers (docs/explanation/models.md): impact and friction layers for solid
/// floors, stochastic granular layers for aggregates, bubble layers for liquids. Every layer is
/// driven by the same control signal, the vertical ground reaction force in newtons, sample by
/// sample, and adds its sound into a mono buffer.
///
/// Lifecycle: the layer is built from its preset table (may throw PresetError), `prepare()`
/// allocates, `reset(seed)` restores the initial state with a seed for its random processes,
/// `process()` runs on the audio thread: noexcept, no allocation, no locks, no I/O.
#include "engine/dsp/ProcessSpec.h"
#include "engine/surfaces/Preset.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace underfoot::engine {

/// Options that trade accuracy for speed, applied to every layer that has such a knob.
struct AccuracyOptions {
    int oversampling = 1;          ///< impact/friction contact rate multiple (1, 2, 4, 8)
    int newtonIterations = 6;      ///< impact solver iteration cap
    bool explicitImpact = false;   ///< explicit (SDT-like) impact force instead of Newton
    int maxModes = 64;             ///< at most this many modes per resonator (lowest kept)
    int maxEventsPerSecond = 4000; ///< cap of granular events per second per layer
};

class SurfaceLayer {
  public:
    virtual ~SurfaceLayer() = default;
    virtual void prepare(const ProcessSpec& spec) = 0;
    virtual void reset(std::uint64_t seed) noexcept = 0;
    /// Adds n samples of this layer's sound, driven by `grfNewtons`, into `out`.
    virtual void process(const float* grfNewtons, float* out, int n) noexcept = 0;
    /// True when the layer is silent and costs (almost) nothing until the GRF changes.
    virtual bool isSleeping() const noexcept = 0;
    /// The layer's kind as written in presets ("impact", "friction", "grains", "bubbles").
    virtual const char* kind() const noexcept = 0;
};

/// Builds a layer of one kind from its preset table.
using LayerFactory = std::unique_ptr<SurfaceLayer> (*)(PresetReader& reader,
                                                       const AccuracyOptions& options);

struct LayerKind {
    const char* name;        ///< as written in presets: type = "impact"
    LayerFactory make;       ///< builds one from its table (throws PresetError)
    const char* description; ///< one line for `underfoot surfaces --layers`
};

/// Every layer kind the engine knows (engine/surfaces/LayerKinds.cpp holds the table).
const std::vector<LayerKind>& layerKinds();

/// A [lo, hi] range read as two parameters; a reversed pair is accepted and swapped (the
/// stability sweeps draw the two ends independently).
inline std::pair<double, double> orderedPair(double a, double b) noexcept {
    return {std::min(a, b), std::max(a, b)};
}

} // namespace underfoot::engine
