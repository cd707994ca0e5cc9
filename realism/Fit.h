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
///    rates (events_per_* x 2^k, at most x 2 so that the cost stays bounded), the heel's thud
///    (gain_db + k of the onset-only layers, when there is one), crunch cascades (burst_events + k,
///    at least 0, on the layers of ongoing events) and their length (burst_ms x 2^k), balance of
///    the first layer against the others (+-k dB); on layers of noise bursts
///    (excitation = "noise"): their decay (noise_decay_ms x 2^k), colour (noise_corner_hz and
///    the tone filters x 2^k) and build-up (noise_attack_ratio + k);
///  - bubbles: bubble size (radius_min/max_mm x 2^k), splash noise band (splash_hz x 2^k),
///    level (splash_noise_db + k) and length (splash_ms, splash_decay_ms x 2^k), slosh level
///    (slosh_db + k).
/// The fitted preset keeps the original's loudness: its top-level gain_db is re-calibrated so
/// that the render's peak equals the original's.
///
/// Modal seed (solids, FitOptions::modalSeed, on by default): before the optimiser starts, the
/// impact layers' modes are replaced by the material's recorded modes (ModalSeed.h: matrix
/// pencil on the recordings' strongest steps, clustered across files and sources), as many as
/// the preset had (so the cost stays that of the original). Each seeded mode keeps the modal
/// mass of the original mode nearest in frequency and gets the contact-point gain g with
/// g^2 / m proportional to its recorded amplitude (a struck mode's velocity at the contact
/// point is g^2 J / m for an impulse J), scaled so that the sum of g^2 / m, the floor's
/// mobility at the contact, is the original's; where g would exceed the parameter's range
/// (10) the mass is lowered instead (same g^2 / m). With fewer recorded modes than the preset
/// has, the original modes above the highest recorded one fill the rest. Two seeds are made,
/// from the pencil on the signal and on its first difference (ModalSeedOptions::preEmphasis;
/// the first finds the strong low modes, the second the modes of the upper octaves). The preset
/// with its own modes is a third start; each is refined by the knobs with up to maxEvaluations
/// renders, and the best result is kept, so a seed never leaves the fit worse than the preset.
///
/// Contrastive objective (FitOptions::others, contrast, margin; `underfoot fit --contrast
/// LAMBDA --margin M`): minimising the distance to the own recordings alone can land a render
/// that is even closer to another material's recordings (sand fitted towards a hiss that the
/// water recordings have too). With recordings of other materials given, the fit minimises
///     J = d_own + LAMBDA x max(0, d_own - min over other materials d_other + M)
/// i.e. the plain distance while the render is at least M closer to its own material than to
/// the nearest other one, plus a hinge penalty otherwise. Each other material is compared on
/// the band its own recordings share with the render (as `underfoot compare --all` does), so
/// the nearest other material of the fit is the one `compare --all` reports for the same
/// render. LAMBDA = 0 (or no other recordings) is the plain fit, bit for bit.
///
/// Several render seeds (FitOptions::seeds; `underfoot fit --seeds 3,7,8,11`): a granular or
/// liquid surface is a random process, and a preset fitted on one realisation can sit on the
/// wrong side of a thin margin for another (beach sand own-closest with seeds 3, 8, 11, not 7).
/// With seeds given, every evaluation renders the walker once per seed and J is the mean of the
/// per-seed objectives (each with its own hinge, so every seed's margin counts); the reported
/// own and nearest distances are the means over the seeds and the nearest material is the one
/// of the seed with the thinnest margin; the loudness is re-calibrated on the first seed's
/// render. One seed (or none: spec.seed) is the single-seed fit with that seed, bit for bit.
///
/// A preset with a room ([reverb]: the palette fits a derived preset such as wood with reverb
/// through its flat copy) is fitted against the recordings, own and other materials', heard
/// through that room (throughRoom, Compare.h), as `underfoot compare` compares it.
#include "realism/Compare.h"
#include "realism/ModalSeed.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace underfoot::realism {

struct FitOptions {
    RenderSpec spec{"cadence=100", 6.0, 11, 48000};
    int maxEvaluations = 80;
    /// Called after every evaluation (evaluation number, the fit's whole budget of evaluations:
    /// maxEvaluations per starting point, its distance, best so far); return false to stop the
    /// fit early (cancellation).
    std::function<bool(int, int, double, double)> progress;
    /// Seed the impact layers' modes from the recordings (see above); false = refine the
    /// preset's own modes (`underfoot fit --no-modal-seed`).
    bool modalSeed = true;
    ModalSeedOptions seed; ///< maxModes is set to each impact layer's mode count
    /// Recordings of other materials (Recording::material set; those of the own material, if
    /// any, are ignored by name of `ownMaterial`). Empty: no contrast.
    std::vector<Recording> others;
    /// The own material's name, to skip it in `others` ("" = keep every other recording).
    std::string ownMaterial;
    double contrast = 0.0; ///< LAMBDA of the hinge penalty (see above); 0 = plain fit
    double margin = 0.1;   ///< M: how much closer to the own material than to any other
    /// Knobs held at their start (by name, e.g. "grain_band": a designed property the fit must
    /// keep); an unknown name throws std::invalid_argument naming the knobs there are.
    std::vector<std::string> keep;
    /// Starting points of the optimiser per starting preset (`underfoot fit --starts N`): the
    /// preset's own knobs (all 0) and the first N - 1 points of the Sobol sequence (Boost.Random
    /// `sobol`, Joe-Kuo direction numbers; a fixed, stated set: no seed to store) scaled into
    /// the knobs' box; each is refined by BOBYQA with up to maxEvaluations renders and the best
    /// result is kept. 1 (the default) is the local fit from the preset, bit for bit.
    int starts = 1;
    /// Render seeds the objective is averaged over (see above); empty = spec.seed alone.
    std::vector<std::uint64_t> seeds;
};

/// Distance of a render to its own recordings and to the nearest other material.
struct FitDistances {
    double own = 0;
    std::string nearestMaterial; ///< "" when no other material was given
    double nearest = 0;          ///< distance to it
    double objective = 0;        ///< J (see above)
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
    bool seedTried = false;   ///< recorded modes were tried as starts (a solid, modalSeed on)
    bool modalSeeded = false; ///< the result was refined from recorded modes (else its own)
    double distanceSeeded =
        0; ///< objective J of the seeded preset before refining (its distance without contrast)
    std::vector<RecordedMode> seededModes; ///< the recorded modes written into the preset
    std::vector<std::string> seedSkipped;  ///< recordings that yielded no mode
    std::string seedStart;                 ///< the starting point the result was refined from
    int startPoints = 1;    ///< knob starting points per starting preset (FitOptions::starts)
    int bestStartPoint = 0; ///< the one the result was refined from (0: the preset's own knobs)
    std::vector<double> startObjectives; ///< best objective reached from each starting point
    /// Contrast (FitOptions::contrast > 0 and other materials given): own distance, nearest
    /// other material and objective of the original preset and of the fitted one.
    bool contrastive = false;
    FitDistances before, after;
};

/// The knob vectors the fit starts from (FitOptions::starts): all zeros, then the first
/// `count - 1` Sobol points scaled into [lo, hi]. Throws std::invalid_argument when count < 1
/// or the bounds differ in size or are not ordered.
std::vector<std::vector<double>> fitStartPoints(int count, const std::vector<double>& lo,
                                                const std::vector<double>& hi);

/// The contrastive objective J = own + contrast x max(0, own - nearest + margin); `own` alone
/// when there is no other material (nearest < 0) or contrast is 0.
double contrastiveObjective(double own, double nearest, double contrast, double margin);

/// Fits a preset file (a surface with its own layers; a `base` preset is fitted through its
/// base). Throws std::invalid_argument when it has no fittable layer, engine::PresetError for
/// a broken preset, std::runtime_error when the recordings hold no step.
FitResult fitSurface(const std::string& presetFile, const std::vector<Recording>& real,
                     const FitOptions& options);

/// The preset's text with its impact layers' modes replaced by `modes` as the modal seed does
/// (see above). Throws std::invalid_argument when the preset has no impact layer or `modes`
/// is empty, engine::PresetError for a broken preset.
std::string modalSeededPreset(const std::string& presetFile,
                              const std::vector<RecordedMode>& modes);

} // namespace underfoot::realism
