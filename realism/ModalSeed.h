// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The modes of a material from its recordings: the starting point `underfoot fit` gives a
/// solid's modal parameters before it refines them on the realism distance
/// (docs/explanation/realism.md, "Fitting"; docs/decisions/realism-modal-seed.md).
///
/// 1. Per recording, the matrix pencil (Modal.h) estimates `modesPerStep` modes of each of its
///    `stepsPerFile` strongest steps (from the step's envelope peak on, at most `maxSamples` at
///    48 kHz, below 0.95 x the file's Nyquist). With `preEmphasis` the pencil sees the first
///    difference of the signal (+6 dB per octave, as in LPC analysis of speech): footstep
///    spectra fall steeply, and without it the K strongest modes all lie in the lowest octaves;
///    a linear filter leaves frequencies and decays as they are, and each mode's amplitude is
///    divided by the filter's gain at its frequency, 2 sin(pi f / fs), to undo it.
/// 2. Every estimated mode is one observation with a weight: each source weighs 1 in total,
///    shared equally by its files and by their steps (a library with many files does not
///    outvote one with few); its strength is its amplitude relative to the strongest mode of
///    its step (so loud files do not outvote quiet ones).
/// 3. Clusters in log frequency, greedily: the densest point of the weighted strength (a
///    Gaussian kernel of `kernelOctaves` on log2 f) becomes a cluster with every observation
///    within `clusterOctaves` of it; they are removed and the next densest is taken, until
///    `maxModes` clusters or no observation is left.
/// 4. Per cluster: frequency and T60 are the weighted medians of its members' (robust to a
///    stray estimate), its gain the sum of its members' weighted strengths relative to the
///    strongest cluster's (a mode found in every source and step is strong, one seen once is
///    weak), its support the share of the steps' total weight whose estimate holds it.
#include "realism/Modal.h"
#include "realism/Recordings.h"

#include <string>
#include <vector>

namespace underfoot::realism {

struct ModalSeedOptions {
    int modesPerStep = 12;             ///< K of the matrix pencil per step
    int stepsPerFile = 3;              ///< strongest steps analysed per recording
    int maxSamples = 1536;             ///< samples per analysed segment (32 ms at 48 kHz)
    double minHz = 40;                 ///< modes below are dropped (handling noise, rumble)
    double clusterOctaves = 1.0 / 6.0; ///< cluster half-width around its centre
    double kernelOctaves = 1.0 / 12.0; ///< smoothing of the density used to find centres
    int maxModes = 12;       ///< clusters kept (strongest first, then sorted by frequency)
    bool preEmphasis = true; ///< analyse the first difference (see above)
};

/// One mode of a material: where recordings of it ring, how long, how strongly.
struct RecordedMode {
    double frequencyHz = 0;
    double t60S = 0;
    double gain = 0;    ///< amplitude relative to the strongest recorded mode (linear, <= 1)
    double support = 0; ///< share of the steps' weight that found this mode (0..1]
    int observations = 0;
};

/// An estimated mode of one step of one recording (input of aggregateModes).
struct ModeObservation {
    double frequencyHz = 0, t60S = 0;
    double strength = 0; ///< amplitude relative to the strongest mode of its step
    double weight = 0;   ///< the step's share of its source's weight (see above)
    int step = -1;       ///< which step it came from (-1: an observation of its own)
};

/// The modes of each of the `steps` strongest steps of one recording, strongest step first
/// (each list strongest mode first). Throws engine::FileError for an unreadable file and
/// std::invalid_argument when it has no step.
std::vector<std::vector<Mode>> modesOfStrongestSteps(const std::string& path, int steps,
                                                     const ModalOptions& o = {},
                                                     bool preEmphasis = false);

/// Clusters observations into at most o.maxModes modes, sorted by frequency (step 3 and 4
/// above). Observations with a non-positive or non-finite value are ignored. Deterministic.
std::vector<RecordedMode> aggregateModes(const std::vector<ModeObservation>& observations,
                                         const ModalSeedOptions& o = {});

/// Steps 1 to 4 over a set of recordings (a file without a step or with too short a step is
/// skipped; its name goes to `skipped` when given). Throws engine::FileError for an
/// unreadable file, std::runtime_error when no recording yields a mode.
std::vector<RecordedMode> recordedModes(const std::vector<Recording>& recordings,
                                        const ModalSeedOptions& o = {},
                                        std::vector<std::string>* skipped = nullptr);

} // namespace underfoot::realism
