// SPDX-License-Identifier: GPL-3.0-or-later
// Recordings manifest `manifest.csv` of the recordings cache (realism/Recordings.h:
// loadManifest, a file written by scripts/fetch-recordings.sh); refusal: std::runtime_error
// naming the file.
#include "FuzzSupport.h"
#include "realism/Recordings.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    static const std::string dir = [] {
        const auto d = fuzz::scratchDir() / "recordings";
        std::filesystem::create_directories(d);
        return d.string();
    }();
    const std::string path = fuzz::writeInput("recordings/manifest.csv", data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(path, [&] {
        for (const auto& r : realism::loadManifest(dir))
            if (r.file.empty() || r.source.empty() || r.material.empty())
                fuzz::fail("accepted a row with an empty file, source or material");
    });
    return 0;
}
