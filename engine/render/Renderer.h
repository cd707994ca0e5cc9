// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Offline rendering: runs a FootstepScene block by block exactly as the live callback does,
/// driven by a virtual walker or a GRF file. Same surface, GRF and seed: same samples.
#include "engine/control/GrfFile.h"
#include "engine/control/VirtualWalker.h"
#include "engine/io/AudioFile.h"
#include "engine/render/FootstepScene.h"
#include "engine/render/SafetyLimiter.h"

#include <cstdint>
#include <string>

namespace underfoot::engine {

struct RenderOptions {
    double sampleRateHz = 48000.0;
    int blockSize = 256;
    std::uint64_t seed = 1;
    SceneOptions scene;
    double tailSeconds = 0.0; ///< silence of the GRF appended so that rings and reverb decay
    /// Pass the output through the safety limiter. A caller that mixes more into the render
    /// (replay adds the soundscape, as the live engine does before its limiter) turns it off
    /// and limits the mix itself.
    bool limit = true;
};

struct RenderResult {
    AudioBuffer audio;         ///< stereo, float
    double cpuSeconds = 0;     ///< processing time of the scene
    double realTimeFactor = 0; ///< audio seconds per CPU second
    SceneCost cost;
    bool flushedDenormals = false; ///< FTZ/DAZ was in effect while the scene ran
    /// The output safety limiter (-0.3 dBFS ceiling, as on the live path): whether and how much
    /// it acted. When it did not, the samples are the scene's own, bit for bit.
    LimiterReport limiter;
};

/// CPU time consumed by the calling thread (immune to other processes on a shared machine).
double threadCpuSeconds() noexcept;

/// The walker's GRF (left, right feet): it walks for `seconds`, then finishes the stances under
/// way (so the signal may be a little longer) and stops.
GrfSignal walkerGrf(const WalkerParameters& walker, double seconds, double sampleRateHz,
                    std::uint64_t seed);

/// Renders `surface` driven by `grf` (1 channel: one centred voice; 2: left/right feet; more:
/// one voice each). Throws on a bad surface, IR or GRF rate.
RenderResult renderSurface(const std::string& surface, const GrfSignal& grf,
                           const RenderOptions& options);

} // namespace underfoot::engine
