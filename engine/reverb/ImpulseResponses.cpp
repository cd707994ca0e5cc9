// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/ImpulseResponses.h"

#include "base/DataDir.h"
#include "engine/io/AudioFile.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

namespace underfoot::engine {

namespace fs = std::filesystem;

std::string impulseResponseDirectory() {
    return base::dataDirectory(base::DataKind::ImpulseResponses);
}

std::vector<std::string> availableImpulseResponses() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(impulseResponseDirectory(), ec)) {
        if (!entry.is_regular_file(ec)) continue;
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (ext == ".wav") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

std::string findImpulseResponse(const std::string& nameOrPath) {
    std::error_code ec;
    const fs::path p(nameOrPath);
    const bool looksLikePath = p.has_parent_path() || p.has_extension();
    if (looksLikePath) {
        if (fs::is_regular_file(p, ec)) return nameOrPath;
    } else if (!nameOrPath.empty()) {
        const fs::path shipped = fs::path(impulseResponseDirectory()) / (nameOrPath + ".wav");
        if (fs::is_regular_file(shipped, ec)) return shipped.string();
    }
    std::string names;
    for (const auto& n : availableImpulseResponses()) names += (names.empty() ? "" : ", ") + n;
    throw FileError(fmt::format(
        "impulse response \"{}\" not found; expected a path to an audio file or one of the names "
        "in {}: {}",
        nameOrPath, impulseResponseDirectory(), names.empty() ? "(none installed)" : names));
}

} // namespace underfoot::engine
