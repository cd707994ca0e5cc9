// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A prepared surface driven by a GRF in host blocks of `block` frames (the last one shorter),
// as the engine's tests of layers and bounds render it.
#include "engine/surfaces/Surface.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace underfoot::test {

inline std::vector<float> processInBlocks(engine::Surface& s, const std::vector<float>& grf,
                                          double fs, int block, std::uint64_t seed) {
    s.prepare({fs, block});
    s.reset(seed);
    std::vector<float> out(grf.size(), 0.0f);
    const int n = static_cast<int>(grf.size());
    for (int done = 0; done < n; done += block)
        s.process(grf.data() + done, out.data() + done, std::min(block, n - done));
    return out;
}

} // namespace underfoot::test
