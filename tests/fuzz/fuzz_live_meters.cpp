// SPDX-License-Identifier: GPL-3.0-or-later
// The `.meters.toml` side file of a live trial's recording, read by `underfoot replay` for the
// live rate and block size (app/wiring/Replay.h: parseLiveMeters); refusal: ReplayError naming it.
#include "FuzzSupport.h"
#include "app/wiring/Replay.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_grf.wav.meters.toml";
    fuzz::expectReadOrRefusal<wiring::ReplayError>(name, [&] {
        const auto m = wiring::parseLiveMeters(fuzz::text(data, size), name);
        if (m.sampleRateHz && !(*m.sampleRateHz > 0)) fuzz::fail("accepted a rate <= 0 or NaN");
        if (m.blockSize && (*m.blockSize < 1 || *m.blockSize > 65536))
            fuzz::fail("accepted a block size outside 1..65536");
    });
    return 0;
}
