// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Objective descriptors of a rendered sound, used to tune and to test that every surface sounds
/// like itself (levels, spectral balance, temporal texture) without listening.
#include "engine/io/AudioFile.h"

#include <vector>

namespace underfoot::engine {

struct AudioFeatures {
    double peakDb = -999;       ///< sample peak, dBFS (all channels)
    double rmsDb = -999;        ///< RMS over the active frames, dBFS
    double leqDb = -999;        ///< RMS over the whole buffer (equivalent level), dBFS
    double centroidHz = 0;      ///< energy-weighted spectral centroid of the active frames
    double rolloff85Hz = 0;     ///< frequency below which 85 % of the energy lies
    double lowShare = 0;        ///< energy share below 500 Hz
    double highShare = 0;       ///< energy share above 4 kHz
    double activeShare = 0;     ///< share of 10 ms frames within 40 dB of the loudest frame
    double eventsPerSecond = 0; ///< transient onsets per second (spectral-flux peaks)
    double crestDb = 0;         ///< peak / RMS, dB
    double decayMsMedian = 0;   ///< median time for a frame-energy peak to fall by 20 dB
};

/// Computes the features of a buffer's mono mix (FFT frames of 1024 with hop 480 at 48 kHz).
AudioFeatures computeFeatures(const AudioBuffer& audio);

/// Magnitude spectrogram in dB (frames x bins), for plots and the sound palette.
std::vector<std::vector<float>> spectrogramDb(const AudioBuffer& audio, int fftSize, int hop);

} // namespace underfoot::engine
