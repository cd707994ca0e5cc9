// SPDX-License-Identifier: GPL-3.0-or-later
// Wading depth preset TOML (engine/wading/WadingScene.h: parseWadingPreset); refusal: PresetError
// naming it.
#include "FuzzSupport.h"
#include "engine/wading/WadingScene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_wading.toml";
    fuzz::expectReadOrRefusal<engine::PresetError>(
        name, [&] { (void)engine::parseWadingPreset(fuzz::text(data, size), name); });
    return 0;
}
