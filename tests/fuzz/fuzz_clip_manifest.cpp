// SPDX-License-Identifier: GPL-3.0-or-later
// Clip manifest `clips.csv` of a listening test's clip folder (experiment/Clips.h:
// readClipManifest, a file); refusal: std::runtime_error naming the file.
#include "FuzzSupport.h"
#include "experiment/Clips.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    static const std::string dir = [] {
        const auto d = fuzz::scratchDir() / "clips";
        std::filesystem::create_directories(d);
        return d.string();
    }();
    const std::string path = fuzz::writeInput("clips/clips.csv", data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(path, [&] {
        for (const auto& r : experiment::readClipManifest(dir))
            if (!std::isfinite(r.seconds) || !std::isfinite(r.sampleRateHz))
                fuzz::fail("accepted a non-finite number");
    });
    return 0;
}
