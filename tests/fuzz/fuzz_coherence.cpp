// SPDX-License-Identifier: GPL-3.0-or-later
// Surface/soundscape coherence table TOML (soundscapes/Coherence.h: CoherenceTable::parse);
// refusal: DefinitionError naming it.
#include "FuzzSupport.h"
#include "soundscapes/Coherence.h"
#include "soundscapes/Definition.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_coherence.toml";
    fuzz::expectReadOrRefusal<soundscapes::DefinitionError>(
        name, [&] { (void)soundscapes::CoherenceTable::parse(fuzz::text(data, size), name); });
    return 0;
}
