// SPDX-License-Identifier: GPL-3.0-or-later
// Audio settings TOML (engine/io/AudioDevice.h: parseAudioSettings); refusal:
// AudioSettingsError naming the file.
#include "FuzzSupport.h"
#include "engine/io/AudioDevice.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_audio.toml";
    fuzz::expectReadOrRefusal<engine::AudioSettingsError>(
        name, [&] { (void)engine::parseAudioSettings(fuzz::text(data, size), name); });
    return 0;
}
