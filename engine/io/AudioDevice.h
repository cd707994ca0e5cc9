// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Audio devices (RtAudio 5.2, kept inside AudioDevice.cpp / LiveEngine.cpp) and the user's
/// audio settings: API, device, rate, block size and the channel map that routes headphones,
/// haptic actuators (per shoe, heel / toe) and microphones to device channels.
///
/// Settings file (TOML, written by `underfoot devices --save`, documented in
/// docs/reference/settings.md). Channel numbers in the file are 1-based, as printed on sound cards
/// and in `underfoot devices`; in AudioSettings they are 0-based.
///
///     [audio]
///     api = "jack"            # jack, alsa, pulse, oss, dummy, or "" (first that works)
///     device = "system"       # output (and duplex) device name; "" = the API's default
///     input_device = ""       # "" = same as device
///     sample_rate = 48000
///     block_size = 64
///     crossfade_ms = 10       # scene swaps
///     [channels]
///     headphones = [1, 2]     # left, right
///     microphones = [1, 2, 3, 4]
///     [channels.haptic]       # optional, each key optional
///     left_heel = 3
///     left_toe = 4
///     right_heel = 5
///     right_toe = 6
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::engine {

/// A settings file or a device request the user can fix; the message names the file:line:column
/// (or the device) and what was expected.
struct AudioSettingsError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A device as RtAudio reports it.
struct AudioDeviceInfo {
    std::string api;  ///< short API name: "jack", "alsa", "pulse", "oss", "dummy"
    std::string name; ///< the name to put in AudioSettings::device
    int inputChannels = 0;
    int outputChannels = 0;
    int duplexChannels = 0;
    std::vector<int> sampleRatesHz;
    int preferredSampleRateHz = 0;
    bool isDefaultInput = false;
    bool isDefaultOutput = false;
};

/// Short names of the audio APIs compiled into RtAudio, in RtAudio's order of preference.
std::vector<std::string> compiledAudioApis();

/// Every device of `api` ("" = of every compiled API). Devices that cannot be probed are left
/// out. Throws AudioSettingsError for an unknown API name.
std::vector<AudioDeviceInfo> listAudioDevices(const std::string& api = "");

/// The two actuator outputs of one shoe (0-based device output channels; -1 = not connected).
struct HapticShoeChannels {
    int heel = -1;
    int toe = -1;
};

/// Which device channel carries what (0-based).
struct ChannelMap {
    int headphonesLeft = 0;
    int headphonesRight = 1;
    /// [0] left shoe, [1] right shoe.
    std::array<HapticShoeChannels, 2> haptic{};
    /// Input channels whose loudest envelope drives microphone-controlled scenes.
    std::vector<int> microphones;

    /// Number of output channels to open: highest used output channel + 1.
    int outputChannelCount() const noexcept;
    /// Number of input channels to open: highest microphone channel + 1 (0 without mics).
    int inputChannelCount() const noexcept;
    /// Whether any actuator channel is mapped.
    bool hasHaptics() const noexcept;
};

/// Everything needed to open the live stream.
struct AudioSettings {
    std::string api;         ///< "" = first compiled API that opens
    std::string device;      ///< output / duplex device; "" = default output
    std::string inputDevice; ///< "" = same as device
    int sampleRateHz = 48000;
    int blockSize = 64;
    double crossfadeMs = 10.0;
    ChannelMap channels;
    /// JACK client name (several engines on one server need different names).
    std::string clientName = "underfoot";
    /// Whether RtAudio connects our JACK ports to the device's ports (tests connect by hand).
    enum class PortConnection { Automatic, Manual } portConnection = PortConnection::Automatic;

    /// Throws AudioSettingsError (prefixed by `where`) when a value is out of range: rate
    /// 8000..384000 Hz, block 16..4096 frames, crossfade 0..1000 ms, channels 0..63, distinct
    /// outputs, at most 16 microphones.
    void validate(const std::string& where = "audio settings") const;
};

/// Parses settings text; `sourceName` names the file in errors (file:line:column).
AudioSettings parseAudioSettings(const std::string& text, const std::string& sourceName);
/// Reads a settings file. Throws AudioSettingsError (also for a missing file).
AudioSettings loadAudioSettings(const std::string& path);
/// The settings as TOML text (parseAudioSettings reads it back identically).
std::string audioSettingsToToml(const AudioSettings& settings);
/// Writes the settings file. Throws AudioSettingsError when it cannot be written.
void saveAudioSettings(const std::string& path, const AudioSettings& settings);

} // namespace underfoot::engine
