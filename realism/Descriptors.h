// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Per-step descriptors of footstep audio, recorded or synthetic.
///
/// A recording (or a render) is mixed to mono at the analysis rate, cut into steps by an energy
/// onset detector, and every step gets the same scalar descriptors (spectral shape, band
/// balance, tonality, grain density, crest factor, decay, temporal envelope) plus a
/// third-octave envelope. Every descriptor is level-invariant (ratios, shapes, times), and the
/// spectral ones only look below `maxHz`, so a recording at 22.05 kHz and a render at 48 kHz
/// are compared on the band they share (bandwidth-aware).
#include "engine/io/AudioFile.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::realism {

struct AnalysisOptions {
    double analysisRateHz = 48000; ///< every input is resampled to this rate first
    double minHz = 20;             ///< lower edge of the spectral descriptors
    double maxHz = 16000;          ///< upper edge: at most 0.95 x the lowest Nyquist compared
    double stepThresholdDb = 35;   ///< a step starts where the 5 ms envelope rises within this
                                   ///< many dB of the loudest point of the file
    double minStepGapS = 0.25;     ///< two onsets closer than this are one step
    double maxStepS = 0.8;         ///< a step is cut after this long (or at the next onset)
    /// White noise this many dB below the loudest 2 ms (mean square over 2 ms windows, 1 ms
    /// apart) of the signal is added before analysis (see above); 0: none.
    double noiseFloorDb = 60;
    std::uint64_t noiseSeed = 1; ///< seed of the floor's noise (the same for every file)
};

/// The scalar descriptors, in this order. Their values are in the units named by
/// descriptorInfo(); `logScale` ones are compared in octaves (log2).
enum Descriptor : int {
    kCentroid,         ///< spectral centroid, Hz
    kRolloff,          ///< 85 % spectral roll-off, Hz
    kFlatness,         ///< spectral flatness (geometric / arithmetic mean power), dB
    kBandLow,          ///< energy 20-250 Hz relative to the whole band, dB
    kBandLowMid,       ///< 250 Hz-1 kHz, dB re whole band
    kBandMid,          ///< 1-4 kHz, dB re whole band
    kBandHigh,         ///< 4-16 kHz (or up to maxHz), dB re whole band
    kPeakiness,        ///< spectral crest: highest bin over mean bin power (tonality), dB
    kGrainRate,        ///< micro-events (grains, clicks, bubbles) per second of active step
    kCrest,            ///< crest factor: sample peak over RMS of the active step, dB
    kDecay20,          ///< time from the envelope peak to 20 dB below it, s
    kAttack,           ///< time from 30 dB below the peak to the peak, s
    kActive,           ///< time the envelope stays within 30 dB of its peak, s
    kTemporalCentroid, ///< energy-weighted time centroid after the onset, s
    kDescriptorCount
};

struct DescriptorInfo {
    const char* key;  ///< short name used in tables and files
    const char* name; ///< what it is
    const char* unit; ///< "Hz", "dB", "s", "1/s"
    bool logScale;    ///< compared in octaves (log2) instead of linearly
    double floor;     ///< smallest spread used by the distance (octaves or dB)
};
const DescriptorInfo& descriptorInfo(int d);

/// A step: [begin, end) in frames of the analysed mono signal.
struct StepSpan {
    std::size_t begin = 0, end = 0;
};

struct StepDescriptors {
    std::array<double, kDescriptorCount> value{};
    std::vector<double> thirdOctaveDb; ///< band level re the whole band, dB (thirdOctaveCentres)
    std::vector<double> spectrumDb;    ///< averaged power spectrum (dB, 1024-point bins)
};

/// Third-octave centre frequencies (50 Hz upwards) whose upper edge lies below maxHz.
std::vector<double> thirdOctaveCentres(double maxHz);

/// Mono mix of an audio buffer, resampled to the analysis rate when needed, with the noise floor
/// added (addNoiseFloor).
std::vector<float> analysisSignal(const engine::AudioBuffer& audio, const AnalysisOptions& o);

/// Adds the noise floor of `o` to a mono signal at rate fs: Gaussian white noise of RMS
/// 10^(-noiseFloorDb / 20) x the RMS of the signal's loudest 2 ms, drawn from noiseSeed.
/// Returns that RMS (0 when noiseFloorDb is 0 or the signal is silent: nothing is added).
double addNoiseFloor(std::vector<float>& x, double fs, const AnalysisOptions& o);

/// Steps of a mono signal at rate fs (onset detection on a 5 ms energy envelope).
std::vector<StepSpan> segmentSteps(const std::vector<float>& x, double fs,
                                   const AnalysisOptions& o);

/// Grain events in x[from, to): peaks of the first difference's energy in frames of `hop`
/// samples that rise 6 dB above the previous trough, within 30 dB of the loudest frame (clicks,
/// grains, bubbles).
int countGrainEvents(const std::vector<float>& x, std::size_t from, std::size_t to,
                     std::size_t hop);

/// Descriptors of one step of a mono signal at rate fs. Throws std::invalid_argument when the
/// span is empty or the step is silent.
StepDescriptors describeStep(const std::vector<float>& x, double fs, StepSpan span,
                             const AnalysisOptions& o);

/// f(x, fs, span) for every step of a buffer (analysisSignal, then segmentSteps), collected in
/// order; a step f rejects with std::invalid_argument (silent in the analysed band) is left out.
template <class F>
auto forEachStep(const engine::AudioBuffer& audio, const AnalysisOptions& o, F f) {
    const auto x = analysisSignal(audio, o);
    std::vector<decltype(f(x, o.analysisRateHz, StepSpan{}))> out;
    for (const auto& s : segmentSteps(x, o.analysisRateHz, o)) {
        try {
            out.push_back(f(x, o.analysisRateHz, s));
        } catch (const std::invalid_argument&) {
            // a step silent inside the analysed band carries no descriptors
        }
    }
    return out;
}

/// Every step of a buffer, described (segmentation + description).
std::vector<StepDescriptors> describeSteps(const engine::AudioBuffer& audio,
                                           const AnalysisOptions& o);

} // namespace underfoot::realism
