// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/AudioFile.h"

#include <fmt/format.h>
#include <samplerate.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <system_error>

namespace underfoot::engine {

namespace {

struct SndfileCloser {
    void operator()(SNDFILE* f) const noexcept { sf_close(f); }
};
using SndfilePtr = std::unique_ptr<SNDFILE, SndfileCloser>;

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

} // namespace

std::vector<float> AudioBuffer::channel(int ch) const {
    if (ch < 0 || ch >= channels)
        throw std::out_of_range(
            fmt::format("AudioBuffer::channel: channel {} of {}", ch, channels));
    const std::size_t n = frames();
    std::vector<float> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = at(i, ch);
    return out;
}

AudioBuffer readAudioFile(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw FileError(
            fmt::format("{}: file not found (expected an audio file: WAV, FLAC or OGG)", path));
    if (std::filesystem::is_directory(path, ec))
        throw FileError(fmt::format("{}: is a directory (expected an audio file)", path));
    SF_INFO info{};
    SndfilePtr file(sf_open(path.c_str(), SFM_READ, &info));
    if (!file)
        throw FileError(fmt::format("{}: cannot read as audio ({}); expected WAV, FLAC or OGG",
                                    path, sf_strerror(nullptr)));
    if (info.frames <= 0 || info.channels <= 0)
        throw FileError(
            fmt::format("{}: empty audio file (0 frames); expected at least one sample", path));
    if (info.samplerate < kMinAudioFileRateHz || info.samplerate > kMaxAudioFileRateHz)
        throw FileError(fmt::format("{}: sample rate {} Hz in the header; expected {} to {} Hz",
                                    path, info.samplerate, kMinAudioFileRateHz,
                                    kMaxAudioFileRateHz));
    if (info.channels > kMaxAudioFileChannels)
        throw FileError(fmt::format("{}: {} channels in the header; expected 1 to {}", path,
                                    info.channels, kMaxAudioFileChannels));
    const auto ch = static_cast<std::size_t>(info.channels);
    const std::size_t maxFrames = kMaxAudioFileSamples / ch;
    if (static_cast<std::uint64_t>(info.frames) > maxFrames)
        throw FileError(fmt::format("{}: the header claims {} frames of {} channels; expected at "
                                    "most {} samples in all (about {:.0f} s at this rate)",
                                    path, info.frames, info.channels, kMaxAudioFileSamples,
                                    static_cast<double>(maxFrames) / info.samplerate));
    AudioBuffer out;
    out.sampleRateHz = info.samplerate;
    out.channels = info.channels;
    const int subtype = info.format & SF_FORMAT_SUBMASK;
    out.floatingPoint = subtype == SF_FORMAT_FLOAT || subtype == SF_FORMAT_DOUBLE;
    // Read in chunks: memory follows the samples that are really there (a damaged header may
    // claim far more than the file holds), capped at the frames the header claims.
    constexpr sf_count_t kChunkFrames = 1 << 16;
    std::size_t got = 0;
    const auto claimed = static_cast<std::size_t>(info.frames);
    while (got < claimed) {
        const auto want =
            static_cast<sf_count_t>(std::min<std::size_t>(kChunkFrames, claimed - got));
        out.samples.resize((got + static_cast<std::size_t>(want)) * ch);
        const sf_count_t n = sf_readf_float(file.get(), out.samples.data() + got * ch, want);
        if (n <= 0) break;
        got += static_cast<std::size_t>(n);
        if (n < want) break;
    }
    if (got == 0)
        throw FileError(
            fmt::format("{}: could not read any sample ({})", path, sf_strerror(file.get())));
    out.samples.resize(got * ch);
    out.samples.shrink_to_fit();
    for (std::size_t i = 0; i < out.samples.size(); ++i) {
        if (!std::isfinite(out.samples[i])) {
            const std::size_t frame = i / static_cast<std::size_t>(out.channels);
            throw FileError(fmt::format(
                "{}: frame {} (t = {:.6f} s), channel {}: non-finite sample ({}); expected finite "
                "audio samples",
                path, frame, static_cast<double>(frame) / out.sampleRateHz,
                i % static_cast<std::size_t>(out.channels), out.samples[i]));
        }
    }
    return out;
}

AudioBuffer readAudioFile(const std::string& path, double targetRateHz) {
    AudioBuffer in = readAudioFile(path);
    if (in.sampleRateHz == targetRateHz) return in;
    // The header's rate is outside input: libsamplerate converts at most 256 x up or down, and
    // the resampled length (memory and work) is frames x target / source, so it stays within
    // the same limit of samples as a file read at its own rate (found by fuzz_audio_file).
    const double ratio = targetRateHz / in.sampleRateHz;
    if (std::isfinite(ratio) && ratio > 0 && !src_is_valid_ratio(ratio))
        throw FileError(
            fmt::format("{}: sample rate {} Hz cannot be resampled to {} Hz (at most "
                        "256 times up or down); expected {:.0f} to {:.0f} Hz",
                        path, in.sampleRateHz, targetRateHz, targetRateHz / 256.0,
                        std::min(256.0 * targetRateHz, static_cast<double>(kMaxAudioFileRateHz))));
    const double resampled = static_cast<double>(in.frames()) * ratio * in.channels;
    if (resampled > static_cast<double>(kMaxAudioFileSamples))
        throw FileError(fmt::format("{}: {} frames of {} channels at {} Hz resampled to {} Hz "
                                    "would be {:.0f} samples; expected at most {}",
                                    path, in.frames(), in.channels, in.sampleRateHz, targetRateHz,
                                    resampled, kMaxAudioFileSamples));
    AudioBuffer out = resample(in, targetRateHz);
    // Finite samples near the float range (a damaged float file) can overflow in the
    // resampler's filter sums: refused, naming the largest input sample (found by
    // fuzz_audio_file; regression input
    // tests/fuzz/regressions/audio_file/resample_overflow_huge_float_2000hz.wav).
    if (!std::all_of(out.samples.begin(), out.samples.end(),
                     [](float v) { return std::isfinite(v); })) {
        float largest = 0.0f;
        for (float v : in.samples) largest = std::max(largest, std::fabs(v));
        throw FileError(fmt::format("{}: resampling {} Hz to {} Hz overflows (largest sample "
                                    "{:g}); expected audio samples of a sensible magnitude "
                                    "(full scale is 1)",
                                    path, in.sampleRateHz, targetRateHz, largest));
    }
    return out;
}

AudioBuffer resample(const AudioBuffer& in, double targetRateHz) {
    if (!(targetRateHz > 0) || !std::isfinite(targetRateHz))
        throw std::invalid_argument(fmt::format("resample: target rate {} Hz is not a positive "
                                                "finite number",
                                                targetRateHz));
    if (!(in.sampleRateHz > 0) || in.channels <= 0)
        throw std::invalid_argument("resample: input buffer has no sample rate or no channels");
    if (in.sampleRateHz == targetRateHz) return in;
    const double ratio = targetRateHz / in.sampleRateHz;
    if (!src_is_valid_ratio(ratio))
        throw std::invalid_argument(fmt::format(
            "resample: ratio {} ({} Hz -> {} Hz) is outside libsamplerate's range [1/256, 256]",
            ratio, in.sampleRateHz, targetRateHz));
    const std::size_t inFrames = in.frames();
    const auto wantFrames =
        static_cast<std::size_t>(std::llround(static_cast<double>(inFrames) * ratio));
    AudioBuffer out;
    out.sampleRateHz = targetRateHz;
    out.channels = in.channels;
    out.floatingPoint = in.floatingPoint;
    const auto ch = static_cast<std::size_t>(in.channels);
    if (inFrames == 0) return out;
    // Room for everything libsamplerate may produce; the result is trimmed/padded to wantFrames.
    std::vector<float> buf((wantFrames + 64) * ch, 0.0f);
    int err = 0;
    std::unique_ptr<SRC_STATE, decltype(&src_delete)> state(
        src_new(SRC_SINC_BEST_QUALITY, in.channels, &err), &src_delete);
    if (!state) throw std::runtime_error(fmt::format("resample: {}", src_strerror(err)));
    std::size_t inPos = 0, outPos = 0;
    while (true) {
        SRC_DATA d{};
        d.data_in = in.samples.data() + inPos * ch;
        d.input_frames = static_cast<long>(inFrames - inPos);
        d.data_out = buf.data() + outPos * ch;
        d.output_frames = static_cast<long>(buf.size() / ch - outPos);
        d.end_of_input = 1;
        d.src_ratio = ratio;
        err = src_process(state.get(), &d);
        if (err != 0) throw std::runtime_error(fmt::format("resample: {}", src_strerror(err)));
        inPos += static_cast<std::size_t>(d.input_frames_used);
        outPos += static_cast<std::size_t>(d.output_frames_gen);
        if (d.output_frames_gen == 0 || outPos >= buf.size() / ch) break;
    }
    buf.resize(wantFrames * ch, 0.0f);
    out.samples = std::move(buf);
    return out;
}

void writeAudioFile(const std::string& path, const AudioBuffer& buffer, SampleFormat format) {
    const std::string ext = lowerExtension(path);
    int major = 0;
    if (ext == ".wav")
        major = SF_FORMAT_WAV;
    else if (ext == ".flac")
        major = SF_FORMAT_FLAC;
    else
        throw FileError(
            fmt::format("{}: unsupported extension '{}'; expected .wav or .flac", path, ext));
    if (buffer.channels <= 0 || !(buffer.sampleRateHz > 0) || !std::isfinite(buffer.sampleRateHz))
        throw FileError(fmt::format("{}: cannot write a buffer with {} channels at {} Hz", path,
                                    buffer.channels, buffer.sampleRateHz));
    if (buffer.samples.size() % static_cast<std::size_t>(buffer.channels) != 0)
        throw FileError(fmt::format("{}: buffer of {} samples is not a whole number of {}-channel "
                                    "frames",
                                    path, buffer.samples.size(), buffer.channels));
    if (std::fabs(buffer.sampleRateHz - std::round(buffer.sampleRateHz)) > 1e-9)
        throw FileError(fmt::format("{}: sample rate {} Hz is not an integer (files store integer "
                                    "rates)",
                                    path, buffer.sampleRateHz));
    int sub = 0;
    switch (format) {
    case SampleFormat::Float32:
        if (major == SF_FORMAT_FLAC)
            throw FileError(fmt::format("{}: FLAC cannot store 32-bit float; use Pcm24 or Pcm16, "
                                        "or a .wav file",
                                        path));
        sub = SF_FORMAT_FLOAT;
        break;
    case SampleFormat::Pcm24:
        sub = SF_FORMAT_PCM_24;
        break;
    case SampleFormat::Pcm16:
        sub = SF_FORMAT_PCM_16;
        break;
    }
    const auto ch = static_cast<std::size_t>(buffer.channels);
    std::size_t clipped = 0, firstClip = 0;
    float peak = 0.0f;
    for (std::size_t i = 0; i < buffer.samples.size(); ++i) {
        const float v = buffer.samples[i];
        if (!std::isfinite(v))
            throw FileError(fmt::format("{}: refusing to write non-finite sample ({}) at frame {}, "
                                        "channel {}",
                                        path, v, i / ch, i % ch));
        if (std::fabs(v) > 1.0f) {
            if (clipped == 0) firstClip = i;
            ++clipped;
        }
        peak = std::max(peak, std::fabs(v));
    }
    if (format != SampleFormat::Float32 && clipped > 0)
        throw FileError(fmt::format(
            "{}: {} samples would clip (first at frame {}, t = {:.6f} s; peak {:.4f} = {:+.2f} "
            "dBFS); expected samples within [-1, 1] for a PCM file: lower the gain or write "
            "Float32",
            path, clipped, firstClip / ch,
            static_cast<double>(firstClip / ch) / buffer.sampleRateHz, peak,
            20.0 * std::log10(peak)));
    SF_INFO info{};
    info.samplerate = static_cast<int>(std::lround(buffer.sampleRateHz));
    info.channels = buffer.channels;
    info.format = major | sub;
    if (!sf_format_check(&info))
        throw FileError(fmt::format("{}: libsndfile cannot write this format ({} channels, {} Hz)",
                                    path, buffer.channels, info.samplerate));
    // Write to a temporary file beside the target, then rename: no half-written file on failure.
    const std::string tmp = path + ".part";
    {
        SndfilePtr file(sf_open(tmp.c_str(), SFM_WRITE, &info));
        if (!file)
            throw FileError(
                fmt::format("{}: cannot open for writing ({})", path, sf_strerror(nullptr)));
        sf_command(file.get(), SFC_SET_CLIPPING, nullptr, SF_TRUE);
        // No PEAK chunk: it carries a timestamp, so the same samples would give different bytes
        // (a replayed trial must be byte-identical to its render).
        sf_command(file.get(), SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
        const auto frames = static_cast<sf_count_t>(buffer.frames());
        const sf_count_t written = sf_writef_float(file.get(), buffer.samples.data(), frames);
        if (written != frames) {
            const std::string why = sf_strerror(file.get());
            file.reset();
            std::error_code ec;
            std::filesystem::remove(tmp, ec);
            throw FileError(
                fmt::format("{}: wrote {} of {} frames ({})", path, written, frames, why));
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw FileError(fmt::format("{}: cannot move the written file into place", path));
    }
}

} // namespace underfoot::engine
