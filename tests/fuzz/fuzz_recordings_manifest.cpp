// SPDX-License-Identifier: GPL-3.0-or-later
// The recordings cache's manifests (realism/Recordings.h: loadManifest): `manifest.csv`, written
// by scripts/fetch-recordings.sh, and `lab-manifest.csv`, a lab's own recordings
// (realism/LabRecordings.h), which a lab may edit by hand. Each input is read as either file;
// refusal: std::runtime_error naming the file.
#include "FuzzSupport.h"
#include "realism/Recordings.h"

#include <algorithm>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    static const std::string dir = [] {
        const auto d = fuzz::scratchDir() / "recordings";
        std::filesystem::create_directories(d);
        return d.string();
    }();
    static const std::string labDir = [] {
        const auto d = fuzz::scratchDir() / "lab_recordings";
        std::filesystem::create_directories(d);
        return d.string();
    }();
    auto check = [](const std::string& cache) {
        for (const auto& r : realism::loadManifest(cache))
            if (r.file.empty() || r.source.empty() || r.material.empty())
                fuzz::fail("accepted a row with an empty file, source or material");
    };
    const std::string path = fuzz::writeInput("recordings/manifest.csv", data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(path, [&] { check(dir); });
    const std::string labPath = fuzz::writeInput("lab_recordings/lab-manifest.csv", data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(labPath, [&] {
        const auto& fetched = realism::fetchedSources();
        for (const auto& r : realism::loadManifest(labDir))
            if (std::find(fetched.begin(), fetched.end(), r.source) != fetched.end())
                fuzz::fail("accepted a fetched source in the lab's manifest");
        check(labDir);
    });
    return 0;
}
