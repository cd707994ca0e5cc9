// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/AudioFile.h"

#include <gtest/gtest.h>
#include <sndfile.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <unistd.h>

#include "tests/common/ScratchDir.h"

using namespace underfoot::engine;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
    return underfoot::test::scratchDir("test_io");
}

AudioBuffer sine(double rateHz, double freqHz, double amplitude, std::size_t frames,
                 int channels = 1) {
    AudioBuffer b;
    b.sampleRateHz = rateHz;
    b.channels = channels;
    b.samples.resize(frames * static_cast<std::size_t>(channels));
    for (std::size_t i = 0; i < frames; ++i)
        for (int c = 0; c < channels; ++c)
            b.samples[i * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)] =
                static_cast<float>(amplitude * std::sin(2 * M_PI * freqHz * (c + 1) *
                                                        static_cast<double>(i) / rateHz));
    return b;
}

// Amplitude and phase of one frequency by least squares over [from, to) (a DFT bin that does not
// need to be on the grid, since the fit is exact for a pure sine).
double amplitudeAt(const std::vector<float>& x, double rateHz, double freqHz, std::size_t from,
                   std::size_t to) {
    double ss = 0, sc = 0, cc = 0, xs = 0, xc = 0;
    for (std::size_t i = from; i < to; ++i) {
        const double ph = 2 * M_PI * freqHz * static_cast<double>(i) / rateHz;
        const double s = std::sin(ph), c = std::cos(ph);
        ss += s * s, sc += s * c, cc += c * c, xs += x[i] * s, xc += x[i] * c;
    }
    const double det = ss * cc - sc * sc;
    const double a = (xs * cc - xc * sc) / det, b = (xc * ss - xs * sc) / det;
    return std::hypot(a, b);
}

// Frequency from the zero crossings (linear interpolation between samples).
double zeroCrossingFrequency(const std::vector<float>& x, double rateHz, std::size_t from,
                             std::size_t to) {
    double first = -1, last = -1;
    int count = 0;
    for (std::size_t i = from + 1; i < to; ++i) {
        if (x[i - 1] < 0 && x[i] >= 0) {
            const double t = static_cast<double>(i - 1) + x[i - 1] / (x[i - 1] - x[i]);
            if (first < 0)
                first = t;
            else
                ++count;
            last = t;
        }
    }
    return count * rateHz / (last - first);
}

template <typename F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const FileError& e) {
        return e.what();
    }
    return "(no FileError thrown)";
}

} // namespace

TEST(AudioFile, Float32WavRoundTripIsExact) {
    const auto path = (tempDir() / "f32.wav").string();
    AudioBuffer b = sine(48000, 440, 1.7, 4800, 2); // float files may exceed full scale
    writeAudioFile(path, b, SampleFormat::Float32);
    const AudioBuffer r = readAudioFile(path);
    EXPECT_EQ(r.sampleRateHz, 48000);
    ASSERT_EQ(r.channels, 2);
    ASSERT_EQ(r.frames(), 4800u);
    EXPECT_EQ(r.samples, b.samples);
    EXPECT_FLOAT_EQ(r.at(10, 1), b.samples[21]);
    EXPECT_EQ(r.channel(1)[10], b.samples[21]);
}

TEST(AudioFile, PcmRoundTripWithinQuantisationStep) {
    for (auto [fmt, ext, step] : {std::tuple{SampleFormat::Pcm24, ".wav", 1.0 / 8388608.0},
                                  std::tuple{SampleFormat::Pcm16, ".wav", 1.0 / 32768.0},
                                  std::tuple{SampleFormat::Pcm24, ".flac", 1.0 / 8388608.0},
                                  std::tuple{SampleFormat::Pcm16, ".flac", 1.0 / 32768.0}}) {
        const auto path = (tempDir() / (std::string("pcm") + ext)).string();
        AudioBuffer b = sine(44100, 1000, 0.999, 2000, 3);
        b.samples[0] = 1.0f; // exactly full scale is allowed
        b.samples[1] = -1.0f;
        writeAudioFile(path, b, fmt);
        const AudioBuffer r = readAudioFile(path);
        ASSERT_EQ(r.samples.size(), b.samples.size());
        EXPECT_EQ(r.sampleRateHz, 44100);
        double maxErr = 0;
        for (std::size_t i = 0; i < b.samples.size(); ++i)
            maxErr = std::max(maxErr, std::fabs(double(r.samples[i]) - double(b.samples[i])));
        EXPECT_LE(maxErr, step) << path; // rounding: half a step, +1 step at +full scale
    }
}

TEST(AudioFile, ReadsOggVorbis) {
    // Written through libsndfile's Vorbis encoder (lossy: compare level and frequency only).
    const auto path = (tempDir() / "sine.ogg").string();
    const AudioBuffer b = sine(48000, 440, 0.5, 48000);
    SF_INFO info{};
    info.samplerate = 48000;
    info.channels = 1;
    info.format = SF_FORMAT_OGG | SF_FORMAT_VORBIS;
    SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(f, nullptr) << sf_strerror(nullptr);
    sf_writef_float(f, b.samples.data(), 48000);
    sf_close(f);
    const AudioBuffer r = readAudioFile(path);
    EXPECT_EQ(r.sampleRateHz, 48000);
    ASSERT_GE(r.frames(), 47000u);
    const auto x = r.channel(0);
    EXPECT_NEAR(amplitudeAt(x, 48000, 440, 4800, 43200), 0.5, 0.01);
    EXPECT_NEAR(zeroCrossingFrequency(x, 48000, 4800, 43200), 440.0, 0.05);
}

TEST(AudioFile, PcmClippingIsAnErrorNamingThePlace) {
    const auto path = (tempDir() / "clip.wav").string();
    fs::remove(path);
    AudioBuffer b = sine(48000, 100, 0.5, 480);
    b.samples[240] = 1.25f;
    const std::string msg = errorOf([&] { writeAudioFile(path, b, SampleFormat::Pcm24); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("clip"), std::string::npos) << msg;
    EXPECT_NE(msg.find("frame 240"), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(path)); // nothing half-written
    EXPECT_NE(errorOf([&] { writeAudioFile(path, b, SampleFormat::Pcm16); }),
              "(no FileError thrown)");
    EXPECT_NO_THROW(writeAudioFile(path, b, SampleFormat::Float32));
}

TEST(AudioFile, RefusesNonFiniteOnWriteAndBadExtensions) {
    AudioBuffer b = sine(48000, 100, 0.5, 100);
    b.samples[7] = std::numeric_limits<float>::quiet_NaN();
    const auto path = (tempDir() / "nan.wav").string();
    EXPECT_NE(errorOf([&] { writeAudioFile(path, b, SampleFormat::Float32); }).find("non-finite"),
              std::string::npos);
    b.samples[7] = std::numeric_limits<float>::infinity();
    EXPECT_NE(errorOf([&] { writeAudioFile(path, b); }).find("frame 7"), std::string::npos);
    b.samples[7] = 0;
    EXPECT_NE(errorOf([&] { writeAudioFile((tempDir() / "x.mp3").string(), b); }).find(".wav"),
              std::string::npos);
    EXPECT_NE(errorOf([&] {
                  writeAudioFile((tempDir() / "x.flac").string(), b, SampleFormat::Float32);
              }).find("FLAC"),
              std::string::npos);
}

TEST(AudioFile, ReadRejectsMissingUnreadableEmptyAndNonFinite) {
    const auto missing = (tempDir() / "does_not_exist.wav").string();
    std::string msg = errorOf([&] { readAudioFile(missing); });
    EXPECT_NE(msg.find(missing), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;

    const auto text = (tempDir() / "text.wav").string();
    std::ofstream(text) << "this is not audio\n";
    msg = errorOf([&] { readAudioFile(text); });
    EXPECT_NE(msg.find(text), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected WAV"), std::string::npos) << msg;

    const auto zeroBytes = (tempDir() / "zero.wav").string();
    std::ofstream(zeroBytes).close();
    EXPECT_NE(errorOf([&] { readAudioFile(zeroBytes); }).find(zeroBytes), std::string::npos);

    const auto empty = (tempDir() / "empty.wav").string();
    {
        SF_INFO info{};
        info.samplerate = 48000;
        info.channels = 1;
        info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
        SNDFILE* f = sf_open(empty.c_str(), SFM_WRITE, &info);
        ASSERT_NE(f, nullptr);
        sf_close(f);
    }
    msg = errorOf([&] { readAudioFile(empty); });
    EXPECT_NE(msg.find("empty"), std::string::npos) << msg;

    // A float WAV holding a NaN and an Inf (written through libsndfile directly).
    const auto nanFile = (tempDir() / "nan_read.wav").string();
    {
        SF_INFO info{};
        info.samplerate = 48000;
        info.channels = 2;
        info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
        SNDFILE* f = sf_open(nanFile.c_str(), SFM_WRITE, &info);
        ASSERT_NE(f, nullptr);
        float data[8] = {0, 0, 0.1f, 0.2f, 0.3f, std::numeric_limits<float>::quiet_NaN(), 0, 0};
        sf_writef_float(f, data, 4);
        sf_close(f);
    }
    msg = errorOf([&] { readAudioFile(nanFile); });
    EXPECT_NE(msg.find("frame 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("channel 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
    EXPECT_NE(errorOf([&] { readAudioFile(tempDir().string()); }).find("directory"),
              std::string::npos);
}

TEST(AudioFile, ResampledSineKeepsFrequencyLevelAndScalesLength) {
    // 1 kHz at 0.5 (-6.02 dBFS), one second, resampled up and down.
    for (auto [from, to] : {std::pair{44100.0, 48000.0}, std::pair{48000.0, 44100.0},
                            std::pair{48000.0, 96000.0}, std::pair{96000.0, 22050.0}}) {
        const std::size_t n = static_cast<std::size_t>(from);
        const AudioBuffer in = sine(from, 1000, 0.5, n, 2);
        const AudioBuffer out = resample(in, to);
        EXPECT_EQ(out.sampleRateHz, to);
        ASSERT_EQ(out.channels, 2);
        EXPECT_EQ(out.frames(),
                  static_cast<std::size_t>(std::llround(static_cast<double>(n) * to / from)));
        for (int c = 0; c < 2; ++c) {
            const double f = 1000.0 * (c + 1);
            const auto x = out.channel(c);
            const std::size_t a = out.frames() / 10, b = out.frames() * 9 / 10; // skip edges
            EXPECT_NEAR(zeroCrossingFrequency(x, to, a, b), f, 0.01) << from << "->" << to;
            EXPECT_NEAR(20 * std::log10(amplitudeAt(x, to, f, a, b) / 0.5), 0.0, 0.01)
                << from << "->" << to;
            // The fit at the true frequency and phase leaves a residual below -100 dB: no delay.
            double err = 0;
            for (std::size_t i = a; i < b; ++i) {
                const double ref = 0.5 * std::sin(2 * M_PI * f * static_cast<double>(i) / to);
                err = std::max(err, std::fabs(x[i] - ref));
            }
            EXPECT_LT(err, 1e-4) << from << "->" << to << " ch " << c;
        }
    }
    const AudioBuffer same = sine(48000, 1000, 0.5, 100);
    EXPECT_EQ(resample(same, 48000).samples, same.samples);
    EXPECT_THROW(resample(same, -1), std::invalid_argument);
    EXPECT_THROW(resample(same, std::nan("")), std::invalid_argument);
}

TEST(AudioFile, ReadWithTargetRateResamples) {
    const auto path = (tempDir() / "r44.wav").string();
    writeAudioFile(path, sine(44100, 500, 0.25, 44100), SampleFormat::Float32);
    const AudioBuffer r = readAudioFile(path, 48000);
    EXPECT_EQ(r.sampleRateHz, 48000);
    EXPECT_EQ(r.frames(), 48000u);
    const auto x = r.channel(0);
    EXPECT_NEAR(amplitudeAt(x, 48000, 500, 4800, 43200), 0.25, 0.25 * 1e-3);
}
