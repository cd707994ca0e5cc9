// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Ground reaction force (GRF) signals and the files they come from.
///
/// Convention: a GRF is the vertical ground reaction force in NEWTONS, one channel per foot or
/// sensor, sampled at the engine's audio rate (control runs per sample).
///
/// File formats read by `loadGrfFile`:
///  - Audio (WAV/FLAC/OGG, mono or multichannel): force = sample value x `fullScaleNewtons`
///    (default 1000 N, i.e. a sample of 1.0 is 1000 N, about 1.5 body weights of a 70 kg person).
///    Channel names: "grf" for mono, "left"/"right" for stereo, "ch1".."chN" otherwise.
///  - CSV: a header `time_s,<name>[,<name>...]`, then one row per sample; values in newtons, or in
///    body weights when the column name ends with `_bw` (x bodyMassKg x g; the suffix is dropped
///    from the channel name). Time strictly increasing and roughly uniform (every step within
///    +-25 % of the median step); the first row is sample 0. Blank lines and lines starting with
///    '#' are skipped.
/// Checks (each a FileError naming file:line:column or file, channel and time, and what was
/// expected): NaN/Inf, non-numeric cells, empty files, non-increasing or irregular time,
/// clipped data (3 or more consecutive samples at digital full scale, |x| >= 0.9999, in audio
/// files; pass allowClipped to accept them), negative forces beyond noise (below -2 % of the
/// channel's peak; smaller negative values, the offset noise of force plates, are set to 0).
/// Limits (outside input is bounded before anything is allocated or rendered from it): the
/// file's sample rate (audio header, or 1 / median time step of a CSV) must lie in
/// [kMinGrfRateHz, kMaxGrfRateHz] and the GRF must last at most kMaxGrfSeconds; audio files
/// are further bounded by readAudioFile's limits and the file's real size.
/// The signal is resampled to `targetRateHz` (libsamplerate, best sinc); the resampler's ringing
/// below 0 N is clamped, since a ground reaction force never pulls.
#include "engine/io/AudioFile.h"

#include <string>
#include <vector>

namespace underfoot::engine {

/// Lowest and highest sample rate of a GRF file, Hz (force plates and FSR shoes sample at
/// 100 Hz to a few kHz; audio-rate recordings at up to 192 kHz).
inline constexpr double kMinGrfRateHz = 100.0;
inline constexpr double kMaxGrfRateHz = 192000.0;
/// Longest GRF file read, seconds (a trial or a recorded walk; a render from it is as long).
inline constexpr double kMaxGrfSeconds = 900.0;

/// A multichannel vertical GRF in newtons at one sample rate.
struct GrfSignal {
    double sampleRateHz = 0;
    std::vector<std::string> names;           ///< one per channel
    std::vector<std::vector<float>> channels; ///< newtons, all the same length
    /// Length in seconds (0 when there is no channel).
    double durationSeconds() const;
    /// Samples per channel.
    std::size_t frames() const { return channels.empty() ? 0 : channels.front().size(); }
};

/// How a GRF file is read.
struct GrfLoadOptions {
    double targetRateHz = 48000.0;    ///< output rate (the engine's audio rate)
    double fullScaleNewtons = 1000.0; ///< audio files: force of a sample of 1.0
    double bodyMassKg = 70.0;         ///< CSV columns in body weights (`*_bw`)
    bool allowClipped = false;        ///< accept flat tops at full scale in audio files
};

/// Loads a GRF from a .csv file or an audio file (WAV/FLAC/OGG). Throws FileError.
GrfSignal loadGrfFile(const std::string& path, const GrfLoadOptions& options = {});

/// Writes a GRF as a float WAV (sample = newtons / fullScaleNewtons), readable by loadGrfFile.
void writeGrfWav(const std::string& path, const GrfSignal& grf, double fullScaleNewtons = 1000.0);

} // namespace underfoot::engine
