// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/AudioDevice.h"

#include "base/TomlReader.h"

#include <RtAudio.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace underfoot::engine {

namespace {

std::string where(const std::string& file, const toml::source_region& r) {
    return base::sourcePlace(file, r);
}

std::string typeName(const toml::node& node) {
    return std::string(base::tomlTypeName(node));
}

/// An integer from a TOML node (rejects floats with a fraction, strings...).
long long integerAt(const toml::node& node, const std::string& file, const std::string& key) {
    if (auto v = node.as_integer()) return v->get();
    throw AudioSettingsError(fmt::format("{}: `{}` must be an integer, got a {}",
                                         where(file, node.source()), key, typeName(node)));
}

double numberAt(const toml::node& node, const std::string& file, const std::string& key) {
    if (auto v = node.as_integer()) return static_cast<double>(v->get());
    if (auto v = node.as_floating_point()) {
        if (!std::isfinite(v->get()))
            throw AudioSettingsError(
                fmt::format("{}: `{}` must be a finite number", where(file, node.source()), key));
        return v->get();
    }
    throw AudioSettingsError(fmt::format("{}: `{}` must be a number, got a {}",
                                         where(file, node.source()), key, typeName(node)));
}

std::string stringAt(const toml::node& node, const std::string& file, const std::string& key) {
    if (auto v = node.as_string()) return v->get();
    throw AudioSettingsError(fmt::format("{}: `{}` must be a string, got a {}",
                                         where(file, node.source()), key, typeName(node)));
}

/// A 1-based channel number in the file -> 0-based.
int channelAt(const toml::node& node, const std::string& file, const std::string& key) {
    const long long v = integerAt(node, file, key);
    if (v < 1 || v > 64)
        throw AudioSettingsError(fmt::format(
            "{}: `{}` = {}: expected a device channel number from 1 to 64 (1 = first channel)",
            where(file, node.source()), key, v));
    return static_cast<int>(v - 1);
}

void rejectUnknownKeys(const toml::table& table, const std::string& file,
                       std::initializer_list<std::string_view> known, const std::string& section) {
    base::rethrowTomlAs<AudioSettingsError>([&] {
        base::TomlReader(file, base::TomlReader::Mode::Throw).checkKeys(table, known, section);
    });
}

} // namespace

int ChannelMap::outputChannelCount() const noexcept {
    int top = std::max(headphonesLeft, headphonesRight);
    for (const auto& shoe : haptic) top = std::max({top, shoe.heel, shoe.toe});
    return top + 1;
}

int ChannelMap::inputChannelCount() const noexcept {
    int top = -1;
    for (int c : microphones) top = std::max(top, c);
    return top + 1;
}

bool ChannelMap::hasHaptics() const noexcept {
    for (const auto& shoe : haptic)
        if (shoe.heel >= 0 || shoe.toe >= 0) return true;
    return false;
}

void AudioSettings::validate(const std::string& w) const {
    if (sampleRateHz < 8000 || sampleRateHz > 384000)
        throw AudioSettingsError(
            fmt::format("{}: sample rate {} Hz; expected 8000 to 384000 Hz", w, sampleRateHz));
    if (blockSize < 16 || blockSize > 4096)
        throw AudioSettingsError(
            fmt::format("{}: block size {} frames; expected 16 to 4096", w, blockSize));
    if (!(crossfadeMs >= 0.0 && crossfadeMs <= 1000.0))
        throw AudioSettingsError(
            fmt::format("{}: crossfade {} ms; expected 0 to 1000 ms", w, crossfadeMs));
    const auto& c = channels;
    std::vector<std::pair<int, std::string>> outs{{c.headphonesLeft, "headphones left"},
                                                  {c.headphonesRight, "headphones right"}};
    const char* shoeName[2] = {"left", "right"};
    for (int s = 0; s < 2; ++s) {
        if (c.haptic[static_cast<std::size_t>(s)].heel >= 0)
            outs.emplace_back(c.haptic[static_cast<std::size_t>(s)].heel,
                              fmt::format("{} heel actuator", shoeName[s]));
        if (c.haptic[static_cast<std::size_t>(s)].toe >= 0)
            outs.emplace_back(c.haptic[static_cast<std::size_t>(s)].toe,
                              fmt::format("{} toe actuator", shoeName[s]));
    }
    for (std::size_t i = 0; i < outs.size(); ++i) {
        if (outs[i].first < 0 || outs[i].first > 63)
            throw AudioSettingsError(fmt::format("{}: {} on output channel {}; expected 1 to 64", w,
                                                 outs[i].second, outs[i].first + 1));
        for (std::size_t j = 0; j < i; ++j)
            if (outs[i].first == outs[j].first)
                throw AudioSettingsError(fmt::format(
                    "{}: {} and {} are both on output channel {}; expected distinct channels", w,
                    outs[j].second, outs[i].second, outs[i].first + 1));
    }
    if (c.outputChannelCount() > 16)
        throw AudioSettingsError(
            fmt::format("{}: output channel {} is beyond the 16 the engine meters and mixes", w,
                        c.outputChannelCount()));
    if (c.microphones.size() > 16)
        throw AudioSettingsError(
            fmt::format("{}: {} microphones; expected at most 16", w, c.microphones.size()));
    std::set<int> seen;
    for (int m : c.microphones) {
        if (m < 0 || m > 15)
            throw AudioSettingsError(
                fmt::format("{}: microphone on input channel {}; expected 1 to 16", w, m + 1));
        if (!seen.insert(m).second)
            throw AudioSettingsError(
                fmt::format("{}: input channel {} is listed twice as a microphone", w, m + 1));
    }
    if (clientName.empty())
        throw AudioSettingsError(fmt::format("{}: the JACK client name is empty", w));
}

AudioSettings parseAudioSettings(const std::string& text, const std::string& file) {
    const toml::table root =
        base::rethrowTomlAs<AudioSettingsError>([&] { return base::parseToml(text, file); });
    AudioSettings s;
    rejectUnknownKeys(root, file, {"audio", "channels"}, "the audio settings");
    if (auto* audio = root["audio"].as_table()) {
        rejectUnknownKeys(*audio, file,
                          {"api", "device", "input_device", "sample_rate", "block_size",
                           "crossfade_ms", "client_name", "connect_ports"},
                          "[audio]");
        for (const auto& [key, node] : *audio) {
            const std::string k(key.str());
            if (k == "api") {
                s.api = stringAt(node, file, k);
                if (!s.api.empty()) {
                    const auto apis = compiledAudioApis();
                    if (std::find(apis.begin(), apis.end(), s.api) == apis.end() &&
                        RtAudio::getCompiledApiByName(s.api) == RtAudio::UNSPECIFIED) {
                        std::string list;
                        for (const auto& a : apis) list += (list.empty() ? "" : ", ") + a;
                        throw AudioSettingsError(fmt::format(
                            "{}: api \"{}\" is not compiled into RtAudio; expected one of: {} "
                            "(or \"\" for the first that works)",
                            where(file, node.source()), s.api, list));
                    }
                }
            } else if (k == "device") {
                s.device = stringAt(node, file, k);
            } else if (k == "input_device") {
                s.inputDevice = stringAt(node, file, k);
            } else if (k == "client_name") {
                s.clientName = stringAt(node, file, k);
            } else if (k == "connect_ports") {
                auto b = node.as_boolean();
                if (!b)
                    throw AudioSettingsError(fmt::format(
                        "{}: `connect_ports` must be true or false", where(file, node.source())));
                s.portConnection = b->get() ? AudioSettings::PortConnection::Automatic
                                            : AudioSettings::PortConnection::Manual;
            } else {
                try {
                    if (k == "sample_rate") {
                        s.sampleRateHz = static_cast<int>(
                            std::clamp<long long>(integerAt(node, file, k), -1, 1'000'000));
                        AudioSettings probe;
                        probe.sampleRateHz = s.sampleRateHz;
                        probe.validate("sample_rate");
                    } else if (k == "block_size") {
                        s.blockSize = static_cast<int>(
                            std::clamp<long long>(integerAt(node, file, k), -1, 1'000'000));
                        AudioSettings probe;
                        probe.blockSize = s.blockSize;
                        probe.validate("block_size");
                    } else if (k == "crossfade_ms") {
                        s.crossfadeMs = numberAt(node, file, k);
                        AudioSettings probe;
                        probe.crossfadeMs = s.crossfadeMs;
                        probe.validate("crossfade_ms");
                    }
                } catch (const AudioSettingsError& e) {
                    // Rewrite "key: ..." into "file:line:col: ...".
                    std::string msg = e.what();
                    throw AudioSettingsError(
                        fmt::format("{}: {}", where(file, node.source()), msg));
                }
            }
        }
    } else if (root.contains("audio")) {
        throw AudioSettingsError(fmt::format("{}: `audio` must be a table ([audio])",
                                             where(file, root["audio"].node()->source())));
    }
    if (auto* ch = root["channels"].as_table()) {
        rejectUnknownKeys(*ch, file, {"headphones", "microphones", "haptic"}, "[channels]");
        if (auto* node = ch->get("headphones")) {
            auto* arr = node->as_array();
            if (!arr || arr->size() != 2)
                throw AudioSettingsError(fmt::format(
                    "{}: `headphones` must be an array of two output channels [left, right]",
                    where(file, node->source())));
            s.channels.headphonesLeft = channelAt(*arr->get(0), file, "headphones[0]");
            s.channels.headphonesRight = channelAt(*arr->get(1), file, "headphones[1]");
        }
        if (auto* node = ch->get("microphones")) {
            auto* arr = node->as_array();
            if (!arr)
                throw AudioSettingsError(fmt::format(
                    "{}: `microphones` must be an array of input channels, e.g. [1, 2, 3, 4]",
                    where(file, node->source())));
            for (std::size_t i = 0; i < arr->size(); ++i)
                s.channels.microphones.push_back(
                    channelAt(*arr->get(i), file, fmt::format("microphones[{}]", i)));
        }
        if (auto* node = ch->get("haptic")) {
            auto* h = node->as_table();
            if (!h)
                throw AudioSettingsError(
                    fmt::format("{}: `haptic` must be a table ([channels.haptic])",
                                where(file, node->source())));
            rejectUnknownKeys(*h, file, {"left_heel", "left_toe", "right_heel", "right_toe"},
                              "[channels.haptic]");
            for (const auto& [key, n] : *h) {
                const std::string k(key.str());
                const int c = channelAt(n, file, k);
                auto& shoe = s.channels.haptic[k.rfind("left", 0) == 0 ? 0u : 1u];
                (k.find("heel") != std::string::npos ? shoe.heel : shoe.toe) = c;
            }
        }
    } else if (root.contains("channels")) {
        throw AudioSettingsError(fmt::format("{}: `channels` must be a table ([channels])",
                                             where(file, root["channels"].node()->source())));
    }
    s.validate(file);
    return s;
}

AudioSettings loadAudioSettings(const std::string& path) {
    const std::string text = base::rethrowTomlAs<AudioSettingsError>([&] {
        return base::readTomlFile(path, "the audio settings (a TOML file written by `underfoot "
                                        "devices --save`)");
    });
    AudioSettings settings = parseAudioSettings(text, path);
    // An empty or truncated file is refused rather than silently read as the defaults
    //: the file `underfoot devices --save` writes always has an [audio] table.
    const toml::table root = base::parseToml(text, path); // parsed without error above
    const toml::table* audio = root["audio"].as_table();
    if (!audio || audio->empty())
        throw AudioSettingsError(fmt::format(
            "{}: {} has no [audio] table with the device settings; expected the file "
            "`underfoot devices --save` writes (was it emptied or cut short?)",
            path,
            text.find_first_not_of(" \t\r\n") == std::string::npos ? "the file is empty and"
                                                                   : "the file"));
    return settings;
}

std::string audioSettingsToToml(const AudioSettings& s) {
    auto q = [](const std::string& v) {
        std::string out = "\"";
        for (char c : v) {
            if (c == '"' || c == '\\') out += '\\';
            out += c;
        }
        return out + "\"";
    };
    std::string t =
        "# Underfoot audio settings (docs/reference/settings.md). Channel numbers start at 1.\n";
    t += "[audio]\n";
    t += fmt::format("api = {}\n", q(s.api));
    t += fmt::format("device = {}\n", q(s.device));
    t += fmt::format("input_device = {}\n", q(s.inputDevice));
    t += fmt::format("sample_rate = {}\n", s.sampleRateHz);
    t += fmt::format("block_size = {}\n", s.blockSize);
    t += fmt::format("crossfade_ms = {}\n", s.crossfadeMs);
    t += fmt::format("client_name = {}\n", q(s.clientName));
    t += fmt::format("connect_ports = {}\n",
                     s.portConnection == AudioSettings::PortConnection::Automatic);
    t += "\n[channels]\n";
    t += fmt::format("headphones = [{}, {}]\n", s.channels.headphonesLeft + 1,
                     s.channels.headphonesRight + 1);
    std::string mics;
    for (int m : s.channels.microphones)
        mics += fmt::format("{}{}", mics.empty() ? "" : ", ", m + 1);
    t += fmt::format("microphones = [{}]\n", mics);
    std::string hap;
    const char* shoe[2] = {"left", "right"};
    for (std::size_t i = 0; i < 2; ++i) {
        if (s.channels.haptic[i].heel >= 0)
            hap += fmt::format("{}_heel = {}\n", shoe[i], s.channels.haptic[i].heel + 1);
        if (s.channels.haptic[i].toe >= 0)
            hap += fmt::format("{}_toe = {}\n", shoe[i], s.channels.haptic[i].toe + 1);
    }
    if (!hap.empty()) t += "\n[channels.haptic]\n" + hap;
    return t;
}

void saveAudioSettings(const std::string& path, const AudioSettings& settings) {
    settings.validate(path);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << audioSettingsToToml(settings);
    out.close();
    if (!out)
        throw AudioSettingsError(fmt::format("{}: cannot write the audio settings file", path));
}

std::vector<std::string> compiledAudioApis() {
    std::vector<RtAudio::Api> apis;
    RtAudio::getCompiledApi(apis);
    std::vector<std::string> names;
    for (auto a : apis) names.push_back(RtAudio::getApiName(a));
    return names;
}

std::vector<AudioDeviceInfo> listAudioDevices(const std::string& api) {
    std::vector<RtAudio::Api> apis;
    if (api.empty()) {
        RtAudio::getCompiledApi(apis);
    } else {
        const auto a = RtAudio::getCompiledApiByName(api);
        if (a == RtAudio::UNSPECIFIED) {
            std::string list;
            for (const auto& n : compiledAudioApis()) list += (list.empty() ? "" : ", ") + n;
            throw AudioSettingsError(fmt::format(
                "audio API \"{}\" is not compiled into RtAudio; expected one of: {}", api, list));
        }
        apis.push_back(a);
    }
    std::vector<AudioDeviceInfo> out;
    for (auto a : apis) {
        try {
            RtAudio audio(a);
            audio.showWarnings(false);
            const unsigned count = audio.getDeviceCount();
            for (unsigned i = 0; i < count; ++i) {
                RtAudio::DeviceInfo info;
                try {
                    info = audio.getDeviceInfo(i);
                } catch (const RtAudioError&) {
                    continue;
                }
                if (!info.probed) continue;
                AudioDeviceInfo d;
                d.api = RtAudio::getApiName(a);
                d.name = info.name;
                d.inputChannels = static_cast<int>(info.inputChannels);
                d.outputChannels = static_cast<int>(info.outputChannels);
                d.duplexChannels = static_cast<int>(info.duplexChannels);
                for (unsigned r : info.sampleRates) d.sampleRatesHz.push_back(static_cast<int>(r));
                d.preferredSampleRateHz = static_cast<int>(info.preferredSampleRate);
                d.isDefaultInput = info.isDefaultInput;
                d.isDefaultOutput = info.isDefaultOutput;
                out.push_back(std::move(d));
            }
        } catch (const RtAudioError&) {
            // An API whose server is not running (JACK, Pulse) has no devices to list.
        }
    }
    return out;
}

} // namespace underfoot::engine
