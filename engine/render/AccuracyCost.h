// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// What accuracy costs in time: every accuracy knob of the engine measured against a
/// high-accuracy reference in one run (the table printed by `underfoot bench`).
///
///  - impact: solver (explicit / Newton with n iterations), oversampling (1, 2, 4), float vs
///    double state, against 8x oversampled double Newton (50 iterations): error of contact time,
///    restitution and spectrum (1/3-octave log-spectral distance), CPU ns per output sample,
///    median and worst 64-sample block;
///  - modes: a surface's resonator truncated to its n lowest modes, against all of them;
///  - particle event cap: a granular surface's events per second capped, against a high cap;
///  - surfaces: real-time factor of one voice of every bundled surface.
/// Timings are wall-clock on this machine and noisy: read them as ratios within one run.
#include "engine/models/Friction.h"
#include "engine/models/Impact.h"

#include <string>
#include <vector>

namespace underfoot::engine {

struct ImpactSetting {
    std::string name;
    ImpactSolver solver = ImpactSolver::Newton;
    int iterations = 6;
    int oversampling = 1;
    bool floatState = false;
    int contactSubsteps = 1; ///< sub-steps of the samples in contact (ImpactParams)
};

struct ImpactMeasurement {
    ImpactSetting setting;
    double contactTimeErrorPct = 0; ///< |t_c - t_ref| / t_ref
    double restitutionError = 0;    ///< |e - e_ref|
    double spectralDistanceDb = 0;  ///< RMS difference of 1/3-octave band levels, 50 Hz..16 kHz
    double nsPerSample = 0;         ///< mean over a train of strikes (per-block minimum of 5 runs)
    double medianBlockNs = 0;       ///< 64-sample blocks
    double p99BlockNs = 0;
    double maxBlockNs = 0;
    double contactTimeMs = 0, restitution = 0;
};

struct KnobMeasurement {
    std::string knob, setting;
    double spectralDistanceDb = 0; ///< against the knob's most accurate setting (or reference)
    double nsPerSample = 0;
};

/// The settings compared (explicit, Newton 1/2/4/6 at 1x, Newton 6 at 2x/4x, float, and contact
/// sub-steps 2/4/8/16; the shipped default is Newton 6 at 1x with 8 contact sub-steps).
std::vector<ImpactSetting> defaultImpactSettings();

/// The benchmark's impact: a 0.1 kg sole, k = 2e9 N/m^1.5, mu = 0.6 s/m, 3 floor modes
/// (180, 620, 1900 Hz), struck at 0.5 m/s, at 48 kHz.
ImpactMeasurement measureImpact(const ImpactSetting& setting, double strikesSeconds = 5.0);

/// 1/3-octave log-spectral distance between two signals at a rate (dB RMS over bands within
/// 80 dB of the reference's loudest band).
double spectralDistanceDb(const std::vector<float>& a, const std::vector<float>& reference,
                          double sampleRateHz);

/// Mode-count and event-cap knobs on bundled surfaces, and the friction solve's Newton stop
/// (FrictionParams::newtonStepTolerance) on the friction-creak scenario against the converged
/// 50-pass reference.
std::vector<KnobMeasurement> measureKnobs(double seconds = 4.0);

/// The six model scenarios of the cost table, each the model alone at 48 kHz in 64-sample blocks
/// (their parameters are the presets' layers when the table was made):
///   impact-strikes  3 modes (the bench impact), a 0.5 m/s strike every 0.25 s;
///   impact-pressed  the same with 300 N pressing the sole: the contact never opens;
///   impact-metal    the metal preset's 14 modes, k and mu, a 0.45 m/s strike every 0.25 s;
///   friction-creak  the creaking-wood friction layer (5 modes), 105 N normal force, its drive
///                   spring's anchor moving at 0.05 m/s;
///   aggregate-gravel the gravel preset's sharp grains layer at 1000 events/s;
///   bubbles         a bubble stream at 500 bubbles/s with 48 voices (default radii 0.5-5 mm);
///   aggregate-gravel-1voice the same grains with one voice and no bursts: like for like with
///                   SDT's crumpling patch (one resonator retriggered by every event).
const std::vector<std::string>& scenarioIds();

/// The friction-creak scenario's model, configured (creaking_wood.toml's friction layer:
/// bristle and Stribeck parameters, 5 modes) and prepared at 48 kHz, reset with seed 7; `p`
/// may override the solver's options (its physical parameters are replaced). Drive it with
/// processSample(105.0, 0.0, anchor, 0.05), the anchor advancing 0.05 m/s.
void configureCreakScenario(ElastoPlasticFriction& f, FrictionParams p = {});

struct ScenarioMeasurement {
    std::string id;
    double nsPerSample = 0; ///< per-block minimum over the repeats, summed
    double medianBlockNs = 0, p99BlockNs = 0, maxBlockNs = 0;
    double budgetShare = 0; ///< worst block / 1333 us (64 frames at 48 kHz)
    double checksum = 0;    ///< sum of |output|, so that the work cannot be optimised away
};

/// Runs scenario `id` for `seconds` of audio, `repeats` times (per-block minimum). Throws
/// std::invalid_argument for an unknown id.
ScenarioMeasurement measureScenario(const std::string& id, double seconds, int repeats = 5);

/// How the cost grows: ns per output sample against simultaneous impact voices
/// (1..256, the impact-strikes voice, strikes staggered), modes per voice (3..64, one voice) and
/// grain events per second (250..16000, the aggregate-gravel layer). `perUnit` divides by the
/// voices, the modes or the thousands of events per second.
struct ScalingPoint {
    std::string axis;
    int value = 0;
    double nsPerSample = 0, perUnit = 0;
};
std::vector<ScalingPoint> measureScaling(double seconds = 2.0, int repeats = 3);

} // namespace underfoot::engine
