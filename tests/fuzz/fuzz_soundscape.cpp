// SPDX-License-Identifier: GPL-3.0-or-later
// Soundscape definition (soundscapes/Definition.h); refusal: DefinitionError naming the file.
#include "FuzzSupport.h"
#include "soundscapes/Definition.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_soundscape.toml";
    fuzz::expectReadOrRefusal<soundscapes::DefinitionError>(
        name, [&] { (void)soundscapes::parseSoundscapeDefinition(fuzz::text(data, size), name); });
    return 0;
}
