// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reading, writing and resampling audio files (libsndfile + libsamplerate).
///
/// Every function validates at the boundary: missing, unreadable or empty files, non-finite
/// samples and clipping on PCM output are reported as `FileError` naming the path and what was
/// expected. Samples are floats in [-1, 1] for PCM files; float files are returned as stored.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::engine {

/// An audio file could not be read or written; the message names the path and what was expected.
struct FileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Interleaved multichannel audio at one sample rate.
struct AudioBuffer {
    double sampleRateHz = 0;
    int channels = 0;
    std::vector<float> samples; ///< interleaved: frame f, channel c at samples[f * channels + c]
    /// Read from a floating-point file (values beyond ±1 are legitimate there, so full scale
    /// means nothing); false for integer PCM and compressed files, and for computed buffers.
    bool floatingPoint = false;

    /// Number of frames (samples per channel).
    std::size_t frames() const {
        return channels > 0 ? samples.size() / static_cast<std::size_t>(channels) : 0;
    }
    /// Sample of one channel at one frame (no bounds check beyond the vector's).
    float at(std::size_t frame, int ch) const {
        return samples[frame * static_cast<std::size_t>(channels) + static_cast<std::size_t>(ch)];
    }
    /// A copy of one channel (de-interleaved).
    std::vector<float> channel(int ch) const;
    /// Duration in seconds.
    double durationSeconds() const {
        return sampleRateHz > 0 ? static_cast<double>(frames()) / sampleRateHz : 0.0;
    }
};

/// Limits of what readAudioFile accepts (a header is outside input: what it claims is checked
/// against these and against the file's real size before anything is allocated).
inline constexpr int kMinAudioFileRateHz = 100;    ///< lowest sample rate read
inline constexpr int kMaxAudioFileRateHz = 768000; ///< highest sample rate read
inline constexpr int kMaxAudioFileChannels = 64;   ///< most channels read
/// Most samples (frames x channels) read from one file: 2^28 floats (1 GiB), e.g. 46 minutes
/// of stereo at 48 kHz.
inline constexpr std::size_t kMaxAudioFileSamples = std::size_t{1} << 28;

/// Reads a WAV/FLAC/OGG (anything libsndfile reads) file. Throws FileError for a missing,
/// unreadable or empty file, one that holds NaN/Inf samples, and one beyond the limits above
/// (rate, channels, length). Memory grows with the samples actually decoded, never with the
/// length a header claims.
AudioBuffer readAudioFile(const std::string& path);

/// Reads a file and resamples it to `targetRateHz` when its rate differs.
AudioBuffer readAudioFile(const std::string& path, double targetRateHz);

/// Resamples with libsamplerate (SRC_SINC_BEST_QUALITY). The output has
/// round(frames * target / source) frames, no added delay. Throws std::invalid_argument for a
/// non-positive or non-finite rate.
AudioBuffer resample(const AudioBuffer& in, double targetRateHz);

/// Sample format of written files.
enum class SampleFormat { Float32, Pcm24, Pcm16 };

/// Writes a .wav or .flac file (chosen by extension). Refuses non-finite samples; for PCM
/// formats a sample beyond [-1, 1] is clipping and is reported as a FileError (never silently
/// clipped). FLAC cannot hold Float32 (FileError).
void writeAudioFile(const std::string& path, const AudioBuffer& buffer,
                    SampleFormat format = SampleFormat::Pcm24);

} // namespace underfoot::engine
