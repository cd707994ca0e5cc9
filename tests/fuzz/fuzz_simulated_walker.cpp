// SPDX-License-Identifier: GPL-3.0-or-later
// A simulated participant's stored control stream, read back from a study by `underfoot replay`
// (experiment/Simulation.h: parseSimulatedWalker: `simulated-walker:SECONDS` or the inline
// table form); refusal: std::invalid_argument naming the stored control stream.
#include "FuzzSupport.h"
#include "experiment/Simulation.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    fuzz::expectReadOrRefusal<std::invalid_argument>("stored control stream", [&] {
        const auto w = experiment::parseSimulatedWalker(fuzz::text(data, size));
        if (w && !(w->seconds > 0 && w->seconds <= 3600))
            fuzz::fail("accepted a walk of " + std::to_string(w->seconds) + " s");
    });
    return 0;
}
