// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Random.h"

namespace underfoot::experiment {

std::uint64_t deriveSeed(std::uint64_t seed,
                         std::initializer_list<std::uint64_t> streams) noexcept {
    std::uint64_t state = seed;
    std::uint64_t out = splitMix64(state);
    for (const std::uint64_t stream : streams) out = base::streamSeed(out, stream);
    return out;
}

std::uint64_t Rng::below(std::uint64_t bound) noexcept {
    // Lemire, "Fast random integer generation in an interval" (2019), with rejection.
    unsigned __int128 m = static_cast<unsigned __int128>(next()) * bound;
    auto low = static_cast<std::uint64_t>(m);
    if (low < bound) {
        const std::uint64_t threshold = (0 - bound) % bound;
        while (low < threshold) {
            m = static_cast<unsigned __int128>(next()) * bound;
            low = static_cast<std::uint64_t>(m);
        }
    }
    return static_cast<std::uint64_t>(m >> 64);
}

} // namespace underfoot::experiment
