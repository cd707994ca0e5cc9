// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Seeded, portable random numbers for experiment plans and simulated participants.
///
/// The project's one generator (base/Xoshiro.h: xoshiro256** seeded through SplitMix64), with
/// the draws plans need: unbiased bounded integers (Lemire 2019) and shuffles. No std::
/// distributions: the same seed gives the same plan with every compiler and standard library.
#include "base/Xoshiro.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace underfoot::experiment {

/// One SplitMix64 step: advances `state` and returns a well-mixed 64-bit value.
using base::splitMix64;

/// Derives an independent 64-bit seed from a seed and a list of stream numbers (e.g. study seed,
/// participant index, purpose).
std::uint64_t deriveSeed(std::uint64_t seed, std::initializer_list<std::uint64_t> streams) noexcept;

/// xoshiro256** generator.
class Rng {
  public:
    /// Seeds the 256-bit state from `seed` through SplitMix64.
    explicit Rng(std::uint64_t seed) noexcept : gen_(seed) {}
    /// Next raw 64-bit output.
    std::uint64_t next() noexcept { return gen_.next(); }
    /// Uniform integer in [0, bound) without modulo bias (Lemire's method); bound must be > 0.
    std::uint64_t below(std::uint64_t bound) noexcept;
    /// Uniform double in [0, 1) with 53 random bits.
    double uniform() noexcept { return gen_.uniform(); }
    /// Standard normal deviate (Box–Muller, one value per call).
    double gaussian() noexcept { return gen_.gaussian(); }
    /// Fisher–Yates shuffle.
    template <typename T>
    void shuffle(std::vector<T>& values) noexcept {
        for (std::size_t i = values.size(); i > 1; --i) {
            const auto j = static_cast<std::size_t>(below(i));
            std::swap(values[i - 1], values[j]);
        }
    }

  private:
    base::Xoshiro256 gen_;
};

} // namespace underfoot::experiment
