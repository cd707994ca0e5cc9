// SPDX-License-Identifier: GPL-3.0-or-later
// Surface preset TOML (engine/surfaces: loadSurfaceFromString); refusal: PresetError naming it.
#include "FuzzSupport.h"
#include "engine/surfaces/Preset.h"
#include "engine/surfaces/Surface.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_surface.toml";
    fuzz::expectReadOrRefusal<engine::PresetError>(
        name, [&] { (void)engine::loadSurfaceFromString(fuzz::text(data, size), name); });
    return 0;
}
