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
/// With `GrfLoadOptions::tare` = Apply (Off by default: replays read their recordings exactly as
/// they were written), each channel's force-plate zero is measured and taken off before resampling
/// (see GrfTare): the noise of an unloaded plate would otherwise cross the layers' contact
/// thresholds (5 N) in the air and start landings, grain bursts and splashes there.
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

/// A channel's force-plate zero, measured on the file's own samples near 0 N (those below 5 % of
/// the channel's peak: the foot in the air, the plate unloaded): its level (median) and its noise
/// (1.4826 x the median absolute deviation: the standard deviation of Gaussian noise). The zero
/// taken off is level + 4 x noise, and forces below it read as 0 N: 4 standard deviations leave
/// about one sample in 30,000 of the unloaded plate above it, and a step's load, hundreds of
/// newtons, loses a few (a contact threshold is then crossed a fraction of a millisecond
/// later). Nothing is taken off a clean channel (exact zeros in the air: level and noise 0), a
/// channel with too few samples near 0 to tell (under 1 % of them, or under 50: no swing phase),
/// or one whose zero would exceed 5 % of its peak (the "noise" is then load).
struct GrfTare {
    double levelN = 0.0;             ///< the unloaded plate's median reading
    double noiseN = 0.0;             ///< its noise, standard deviation
    double subtractedN = 0.0;        ///< the zero to take off every sample (0: none)
    std::size_t samplesNearZero = 0; ///< how many samples the estimate rests on
    bool applied = false;            ///< subtractedN was taken off (GrfTareMode::Apply)
};

/// A multichannel vertical GRF in newtons at one sample rate.
struct GrfSignal {
    double sampleRateHz = 0;
    std::vector<std::string> names;           ///< one per channel
    std::vector<std::vector<float>> channels; ///< newtons, all the same length
    std::vector<GrfTare> tare;                ///< per channel unless loaded with GrfTareMode::Off
    /// Length in seconds (0 when there is no channel).
    double durationSeconds() const;
    /// Samples per channel.
    std::size_t frames() const { return channels.empty() ? 0 : channels.front().size(); }
};

/// What the loader does with each channel's force-plate zero (GrfTare).
enum class GrfTareMode {
    Off,     ///< nothing (replays: they must read what was recorded)
    Measure, ///< measure it into GrfSignal::tare, leave the samples as they are (`grf info`)
    Apply,   ///< measure it and take it off (recorded force files: `render`, `live --grf`)
};

/// How a GRF file is read.
struct GrfLoadOptions {
    double targetRateHz = 48000.0;       ///< output rate (the engine's audio rate)
    double fullScaleNewtons = 1000.0;    ///< audio files: force of a sample of 1.0
    double bodyMassKg = 70.0;            ///< CSV columns in body weights (`*_bw`)
    bool allowClipped = false;           ///< accept flat tops at full scale in audio files
    GrfTareMode tare = GrfTareMode::Off; ///< each channel's force-plate zero (GrfTare)
};

/// Measures a channel's force-plate zero (GrfTare) from its samples in newtons (negative noise
/// included: measure before clamping at 0).
GrfTare measureGrfTare(const std::vector<float>& newtons);
/// Takes the zero off: x = max(0, x - tare.subtractedN).
void applyGrfTare(std::vector<float>& newtons, const GrfTare& tare);
/// One line per channel whose zero was taken off, for the user ("" when none was):
/// `file: channel "left": force-plate zero +0.1 N, noise 3.0 N rms: 12.2 N taken off ...`.
std::string describeGrfTare(const GrfSignal& grf, const std::string& file);

/// Loads a GRF from a .csv file or an audio file (WAV/FLAC/OGG). Throws FileError.
GrfSignal loadGrfFile(const std::string& path, const GrfLoadOptions& options = {});

/// Writes a GRF as a float WAV (sample = newtons / fullScaleNewtons), readable by loadGrfFile.
void writeGrfWav(const std::string& path, const GrfSignal& grf, double fullScaleNewtons = 1000.0);

} // namespace underfoot::engine
