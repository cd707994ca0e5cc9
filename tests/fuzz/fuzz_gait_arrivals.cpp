// SPDX-License-Identifier: GPL-3.0-or-later
// Gait arrivals side file of a live wading trial, `<gait>.csv.arrivals.csv` (engine/scene/
// WadingNode.h: parseGaitArrivals, read by `underfoot replay`); refusal: GaitFileError naming it.
#include "FuzzSupport.h"
#include "engine/scene/WadingNode.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_gait.csv.arrivals.csv";
    fuzz::expectReadOrRefusal<engine::GaitFileError>(name, [&] {
        const auto arrivals = engine::parseGaitArrivals(fuzz::text(data, size), name);
        // What the replay relies on: a positive run length, frames in order within it.
        if (arrivals.samples <= 0) fuzz::fail("accepted a run of no samples");
        std::int64_t last = 0;
        for (const auto& f : arrivals.frames) {
            if (f.sample < last || f.sample >= arrivals.samples)
                fuzz::fail("accepted a frame out of order or outside the run");
            last = f.sample;
        }
    });
    return 0;
}
