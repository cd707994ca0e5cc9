// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// `underfoot fit`: analysis by synthesis. A few physically meaningful knobs of a preset are
/// moved by a derivative-free optimiser (NLopt's BOBYQA) to minimise the realism distance
/// (Distance.h) between the surface's render and recordings of its material. Every evaluation
/// renders the same walker with the same seed, so the fit is deterministic.
///
/// Knobs, by the preset's layers (each a multiplier or offset applied to every layer of that
/// type, clamped to the parameters' documented ranges):
///  - impact: mode decay (every t60_s x 2^k), contact stiffness (x 10^k), spectral tilt of
///    the mode gains (gain x (f / 1 kHz)^k);
///  - grains: resonance band (freq_min/max_hz x 2^k), resonance Q (q_min/max x 2^k), event
///    rates (events_per_* x 2^k, at most x 2 so that the cost stays bounded), balance of the first
///    layer against the others (+-k dB);
///  - bubbles: bubble size (radius_min/max_mm x 2^k), splash noise band (splash_hz x 2^k) and
///    level (splash_noise_db + k), slosh level (slosh_db + k).
/// The fitted preset keeps the original's loudness: its top-level gain_db is re-calibrated so
/// that the render's peak equals the original's.
#include "realism/Compare.h"

#include <functional>
#include <string>
#include <vector>

namespace underfoot::realism {

struct FitOptions {
    RenderSpec spec{"cadence=100", 6.0, 11, 48000};
    int maxEvaluations = 80;
    /// Called after every evaluation (evaluation number, its distance, best so far); return
    /// false to stop the fit early (cancellation).
    std::function<bool(int, double, double)> progress;
};

struct FitKnob {
    std::string name, meaning;
    double lo = 0, hi = 0, start = 0, value = 0;
};

struct FitResult {
    std::string presetText; ///< the fitted preset (TOML, with [provenance])
    double distanceBefore = 0, distanceAfter = 0;
    int evaluations = 0;
    double seconds = 0; ///< wall-clock time of the fit
    std::vector<FitKnob> knobs;
    std::string optimiser;
};

/// Fits a preset file (a surface with its own layers; a `base` preset is fitted through its
/// base). Throws std::invalid_argument when it has no fittable layer, engine::PresetError for
/// a broken preset, std::runtime_error when the recordings hold no step.
FitResult fitSurface(const std::string& presetFile, const std::vector<Recording>& real,
                     const FitOptions& options);

} // namespace underfoot::realism
