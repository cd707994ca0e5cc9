// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Library.h"

#include "base/DataDir.h"
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

namespace underfoot::soundscapes {

std::string soundscapeDataDirectory() {
    return base::dataDirectory(base::DataKind::Soundscapes);
}

std::vector<std::string> builtinSoundscapeIds() {
    std::vector<std::string> ids;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(soundscapeDataDirectory(), ec)) {
        const auto& p = entry.path();
        if (p.extension() == ".toml" && p.stem() != "coherence") ids.push_back(p.stem().string());
    }
    std::sort(ids.begin(), ids.end());
    return ids;
}

SoundscapeDefinition loadSoundscape(const std::string& idOrPath) {
    const bool isPath = idOrPath.find('/') != std::string::npos ||
                        (idOrPath.size() > 5 && idOrPath.ends_with(".toml"));
    if (isPath) return loadSoundscapeDefinition(idOrPath);
    const auto ids = builtinSoundscapeIds();
    if (std::find(ids.begin(), ids.end(), idOrPath) == ids.end())
        throw DefinitionError(fmt::format("unknown soundscape '{}' (expected one of: {}, or a "
                                          "path to a .toml definition)",
                                          idOrPath, fmt::join(ids, ", ")));
    return loadSoundscapeDefinition(
        (std::filesystem::path(soundscapeDataDirectory()) / (idOrPath + ".toml")).string());
}

} // namespace underfoot::soundscapes
