// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The shipped soundscape definitions (soundscapes/data/<id>.toml) and how to find them.
#include "soundscapes/Definition.h"

#include <string>
#include <vector>

namespace underfoot::soundscapes {

/// The folder of the shipped definitions: $UNDERFOOT_SOUNDSCAPES_DIR when set, else as
/// base::dataDirectory finds it (installed share/underfoot/soundscapes or the source tree).
std::string soundscapeDataDirectory();
/// Ids of the shipped soundscapes (file names without .toml, coherence.toml excluded), sorted.
std::vector<std::string> builtinSoundscapeIds();
/// Loads a shipped soundscape by id, or a definition file when the argument names one (ends in
/// .toml or contains a '/'). Throws DefinitionError (an unknown id lists the known ones).
SoundscapeDefinition loadSoundscape(const std::string& idOrPath);

} // namespace underfoot::soundscapes
