// SPDX-License-Identifier: GPL-3.0-or-later
// Audio and GRF readers bound what they allocate and compute by the documented limits
// and the file's real size; headers claiming absurd rates or lengths are refused with a message.
#include "../common/ScratchDir.h"
#include "engine/control/GrfFile.h"
#include "engine/io/AudioFile.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

using namespace underfoot::engine;

namespace {

void put32(std::string& s, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put16(std::string& s, std::uint16_t v) {
    for (int i = 0; i < 2; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

/// A 16-bit PCM WAV whose header claims `claimedDataBytes` but holds `frames` real frames.
std::string writeWav(const std::string& name, std::uint32_t rate, std::uint16_t channels,
                     std::uint32_t frames, std::uint32_t claimedDataBytes) {
    std::string s = "RIFF";
    const std::uint32_t realBytes = frames * channels * 2u;
    put32(s, 36 + claimedDataBytes);
    s += "WAVEfmt ";
    put32(s, 16);
    put16(s, 1);
    put16(s, channels);
    put32(s, rate);
    put32(s, rate * channels * 2u);
    put16(s, static_cast<std::uint16_t>(channels * 2u));
    put16(s, 16);
    s += "data";
    put32(s, claimedDataBytes);
    for (std::uint32_t i = 0; i < realBytes / 2; ++i)
        put16(s, static_cast<std::uint16_t>(i % 3000));
    const auto path = (underfoot::test::scratchDir("io_limits") / name).string();
    std::ofstream(path, std::ios::binary) << s;
    return path;
}

std::string refusal(const std::string& path) {
    try {
        (void)loadGrfFile(path);
    } catch (const FileError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(IoLimits, GrfWavAtOneHertzIsRefusedNamingTheRate) {
    const auto path = writeWav("one_hz.wav", 1, 1, 200, 400);
    const std::string msg = refusal(path);
    ASSERT_FALSE(msg.empty()) << "a 1 Hz GRF was accepted";
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("sample rate 1 Hz"), std::string::npos) << msg;
}

TEST(IoLimits, HeaderClaimingGigabytesReadsOnlyWhatIsThere) {
    // The data chunk claims ~4 GB, the file holds 1000 frames: memory follows the real data.
    const auto path = writeWav("huge_claim.wav", 48000, 2, 1000, 0xfffffff0u);
    const AudioBuffer a = readAudioFile(path);
    EXPECT_EQ(a.channels, 2);
    EXPECT_LE(a.frames(), 1000u);
    EXPECT_GT(a.frames(), 0u);
}

TEST(IoLimits, GrfLongerThanTheLimitIsRefused) {
    // 100 Hz x 91,000 frames = 910 s > kMaxGrfSeconds.
    const auto path = writeWav("long.wav", 100, 1, 91000, 182000);
    const std::string msg = refusal(path);
    ASSERT_FALSE(msg.empty());
    EXPECT_NE(msg.find("at most 900 s"), std::string::npos) << msg;
}

TEST(IoLimits, AudioRateOutsideTheDocumentedRangeIsRefused) {
    const auto slow = writeWav("slow.wav", 50, 1, 100, 200);
    try {
        (void)readAudioFile(slow);
        FAIL() << "50 Hz accepted";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("expected 100 to 768000 Hz"), std::string::npos)
            << e.what();
    }
}

// Found by fuzz_audio_file (task fuzz4; regressions/audio_file/): a 100 Hz file read at the
// engine rate (lab clips, wading recordings) escaped as a bare std::invalid_argument from the
// resampler ("ratio 480 ... outside libsamplerate's range"), without the file's name.
TEST(IoLimits, AudioFileTooSlowToResampleIsRefusedNamingTheFile) {
    const auto slow = writeWav("resample_100hz.wav", 100, 1, 64, 128);
    try {
        (void)readAudioFile(slow, 48000.0);
        FAIL() << "a 100 Hz file was resampled x480";
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(slow), std::string::npos) << what;
        EXPECT_NE(what.find("sample rate 100 Hz cannot be resampled to 48000 Hz"),
                  std::string::npos)
            << what;
    }
    // Within libsamplerate's range the file is resampled: 64 frames at 1 kHz -> 3072 at 48 kHz.
    const auto ok = writeWav("resample_1khz.wav", 1000, 1, 64, 128);
    const AudioBuffer a = readAudioFile(ok, 48000.0);
    EXPECT_EQ(a.sampleRateHz, 48000.0);
    EXPECT_EQ(a.frames(), 3072u);
}

TEST(IoLimits, FloatSamplesThatOverflowTheResamplerAreRefusedNamingTheFile) {
    // Found by fuzz_audio_file: a 32-bit float WAV at 2 kHz whose finite samples lie near the
    // float range; resampled to 48 kHz, the filter's sums overflowed to infinity.
    std::string s = "RIFF";
    const std::uint32_t frames = 256, bytes = frames * 4u;
    put32(s, 36 + bytes);
    s += "WAVEfmt ";
    put32(s, 16);
    put16(s, 3); // IEEE float
    put16(s, 1);
    put32(s, 2000);
    put32(s, 2000 * 4u);
    put16(s, 4);
    put16(s, 32);
    s += "data";
    put32(s, bytes);
    for (std::uint32_t i = 0; i < frames; ++i) put32(s, i % 2 ? 0x7f7fffffu : 0xff7fffffu);
    const auto path = (underfoot::test::scratchDir("io_limits") / "huge_float.wav").string();
    std::ofstream(path, std::ios::binary) << s;
    EXPECT_EQ(readAudioFile(path).frames(), frames); // finite at its own rate: read as it is
    try {
        (void)readAudioFile(path, 48000.0);
        FAIL() << "the resampled file was accepted";
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path), std::string::npos) << what;
        EXPECT_NE(what.find("overflows"), std::string::npos) << what;
    }
}

TEST(IoLimits, GrfCsvWithHugeTimeStepIsRefusedBeforeResampling) {
    const auto path = (underfoot::test::scratchDir("io_limits") / "slow.csv").string();
    std::ofstream(path) << "time_s,left\n0,100\n1000000,200\n2000000,300\n";
    const std::string msg = refusal(path);
    ASSERT_FALSE(msg.empty());
    EXPECT_NE(msg.find("1 / the median time step"), std::string::npos) << msg;
}

TEST(IoLimits, ShippedGrfStillLoads) {
    const auto g = loadGrfFile(std::string(UNDERFOOT_SOURCE_DIR) + "/engine/data/grf/heel_1.wav");
    EXPECT_GT(g.frames(), 0u);
}

// Empty or truncated settings and calibration files are refused with the file and
// what is missing, never silently read as defaults.
#include "engine/control/StepCalibration.h"
#include "engine/io/AudioDevice.h"

TEST(IoLimits, EmptyOrTruncatedSettingsAndCalibrationFilesAreRefused) {
    const auto dir = underfoot::test::scratchDir("io_limits");
    const auto empty = (dir / "empty_audio.toml").string();
    std::ofstream(empty) << "\n";
    try {
        (void)loadAudioSettings(empty);
        FAIL() << "an empty audio settings file was read as defaults";
    } catch (const AudioSettingsError& e) {
        EXPECT_NE(std::string(e.what()).find(empty + ": the file is empty"), std::string::npos)
            << e.what();
    }
    const auto cut = (dir / "cut_audio.toml").string();
    std::ofstream(cut) << "# written by underfoot devices --save\n";
    EXPECT_THROW((void)loadAudioSettings(cut), AudioSettingsError);

    StepThresholds t;
    t.participant = "P07";
    const auto full = (dir / "P07.toml").string();
    saveStepThresholds(full, t);
    std::ifstream in(full);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto truncated = (dir / "P07_cut.toml").string();
    std::ofstream(truncated) << text.substr(0, text.find("[left_toe]"));
    try {
        (void)loadStepThresholds(truncated);
        FAIL() << "a truncated calibration file was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(truncated), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("left_toe"), std::string::npos) << e.what();
    }
    const auto emptyCal = (dir / "P07_empty.toml").string();
    std::ofstream(emptyCal) << "";
    EXPECT_THROW((void)loadStepThresholds(emptyCal), std::runtime_error);
    // A float version too large for an integer was cast unchecked by toml++ (undefined
    // behaviour, regressions/calibration/ of task fuzz4): now refused as any other version.
    for (const char* version : {"1.8e91", "1.0", "\"1\""}) {
        const auto odd = (dir / "P07_version.toml").string();
        std::string changed = text;
        changed.replace(changed.find("version = 1"), 11, std::string("version = ") + version);
        std::ofstream(odd) << changed;
        try {
            (void)loadStepThresholds(odd);
            FAIL() << "version = " << version << " was accepted";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find("version: expected 1"), std::string::npos)
                << e.what();
        }
    }
}
