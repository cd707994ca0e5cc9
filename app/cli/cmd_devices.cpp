// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot devices`: the audio devices RtAudio sees, their channels and rates; --save writes
// an audio settings file (docs/reference/settings.md) for the chosen device with a default channel
// map.
//   devices [--api jack]
//   devices --save settings.toml [--api jack] [--device system] [--rate 48000] [--block 64]
#include "app/cli/CommandRegistry.h"
#include "engine/io/AudioDevice.h"

#include <fmt/core.h>

#include <algorithm>
#include <memory>

namespace underfoot::cli::devices_command {
namespace {
namespace eng = underfoot::engine;

struct DevicesArgs {
    std::string api, save, device, inputDevice;
    int rate = 48000, block = 64;
};

int runDevices(const DevicesArgs& a) {
    std::vector<eng::AudioDeviceInfo> devices;
    try {
        devices = eng::listAudioDevices(a.api);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("devices: ") + e.what());
    }
    std::string apis;
    for (const auto& n : eng::compiledAudioApis()) apis += (apis.empty() ? "" : ", ") + n;
    fmt::print("audio APIs compiled into RtAudio: {}\n", apis);
    if (devices.empty())
        fmt::print("no device found{} (is the sound server running? JACK: start jackd)\n",
                   a.api.empty() ? "" : " for API " + a.api);
    for (const auto& d : devices) {
        std::string rates;
        for (int r : d.sampleRatesHz) rates += fmt::format("{}{}", rates.empty() ? "" : " ", r);
        fmt::print("{:6} \"{}\": {} in, {} out ({} duplex); rates {}{}{}\n", d.api, d.name,
                   d.inputChannels, d.outputChannels, d.duplexChannels, rates,
                   d.isDefaultInput ? "; default input" : "",
                   d.isDefaultOutput ? "; default output" : "");
    }
    if (a.save.empty()) return 0;

    // The device to save: the named one, else the default output of the API, else the first.
    const eng::AudioDeviceInfo* chosen = nullptr;
    for (const auto& d : devices)
        if (a.device.empty() ? d.isDefaultOutput && d.outputChannels >= 2 : d.name == a.device) {
            chosen = &d;
            break;
        }
    if (!chosen && a.device.empty())
        for (const auto& d : devices)
            if (d.outputChannels >= 2) {
                chosen = &d;
                break;
            }
    if (!chosen)
        throw UserError(
            a.device.empty()
                ? std::string("devices --save: no device with two outputs to save settings for")
                : fmt::format("devices --save: no device named \"{}\"{} (names are listed above)",
                              a.device, a.api.empty() ? "" : " on API " + a.api));
    eng::AudioSettings s;
    s.api = chosen->api;
    s.device = chosen->name;
    s.inputDevice = a.inputDevice;
    s.sampleRateHz = a.rate;
    s.blockSize = a.block;
    // Default map: headphones on 1-2, actuators on 3-6 when the card has them, up to four
    // microphones on the first inputs.
    if (chosen->outputChannels >= 6) {
        s.channels.haptic[0] = {2, 3};
        s.channels.haptic[1] = {4, 5};
    }
    for (int m = 0; m < std::min(4, chosen->inputChannels); ++m)
        s.channels.microphones.push_back(m);
    try {
        eng::saveAudioSettings(a.save, s);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("devices --save: ") + e.what());
    }
    fmt::print("saved {} (device \"{}\" on {}, {} Hz, {} frames; edit [channels] to match the "
               "wiring)\n",
               a.save, s.device, s.api, s.sampleRateHz, s.blockSize);
    return 0;
}

CommandRegistrar reg("devices", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<DevicesArgs>();
    auto* cmd = app.add_subcommand("devices", "List audio devices; --save writes audio settings");
    cmd->add_option("--api", args->api, "audio API (jack, alsa, pulse); default: all");
    cmd->add_option("--save", args->save, "write an audio settings file (TOML)");
    cmd->add_option("--device", args->device, "device to save (default: the default output)");
    cmd->add_option("--input-device", args->inputDevice, "input device when it differs");
    cmd->add_option("--rate", args->rate, "sample rate to save, Hz")->capture_default_str();
    cmd->add_option("--block", args->block, "block size to save, frames")->capture_default_str();
    cmd->callback([args, &exitCode] { exitCode = runDevices(*args); });
});

} // namespace
} // namespace underfoot::cli::devices_command
