// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Listener-only features of a footstep measured on fixed windows after its contact transient
/// (docs/explanation/realism.md, "The listener"). They do not enter `underfoot compare`'s distance.
///
/// The game libraries differ in what a "footstep file" is (a heel strike alone, a whole step
/// with its scuff, trimmed or with tails); the descriptors of realism/Descriptors.h see the
/// whole step and so see that more than the material. These features look only at the first
/// 30, 80 and 150 ms after the contact (the attack point: the first 1 ms frame within 20 dB of
/// the step's loudest one, so pre-roll and a soft scuff before the heel do not move the
/// windows): spectral centroid, the slope of the third-octave envelope (dB per octave), the
/// high/low ratio (above 2 kHz over 200 Hz-2 kHz), flatness, the band balance of the first 80
/// ms, and the temporal fine structure of the first 150 ms (micro-onsets = grains, the share of
/// its energy in the first 30 ms, the fall 20-40 ms after the peak, the crest factor of the
/// first 80 ms). Every feature is level-invariant and uses only the band below
/// AnalysisOptions::maxHz.
#include "realism/Descriptors.h"

#include <string>
#include <vector>

namespace underfoot::realism {

struct OnsetFeatureInfo {
    const char* key;  ///< short name (CSV column)
    const char* name; ///< what it is
    double floor;     ///< smallest spread the listener standardises by (feature's unit)
};

/// The onset features, in the order onsetFeatures() returns them.
const std::vector<OnsetFeatureInfo>& onsetFeatureInfo();

/// The onset features of one step of a mono signal at rate fs. Throws std::invalid_argument
/// when the span is empty, outside the signal, or silent in the analysed band.
std::vector<double> onsetFeatures(const std::vector<float>& x, double fs, StepSpan span,
                                  const AnalysisOptions& o);

/// The onset features of every step of a buffer (same segmentation as describeSteps; silent
/// steps are left out).
std::vector<std::vector<double>> onsetFeaturesOfSteps(const engine::AudioBuffer& audio,
                                                      const AnalysisOptions& o);

} // namespace underfoot::realism
