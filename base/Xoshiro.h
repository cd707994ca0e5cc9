// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The one seeded generator of the project: xoshiro256** (Blackman & Vigna 2021, "Scrambled
/// linear pseudorandom number generators", ACM TOMS 47(4)), its 256-bit state filled by SplitMix64
/// (Steele, Lea & Flood 2014) so that any 64-bit seed gives a well-mixed state. The engine's
/// Random (engine/dsp/Random.h) and the experiment's Rng (experiment/Random.h) draw from it.
/// No std:: distributions (their output is implementation-defined): the same seed gives the same
/// sequence with every compiler and platform, so a stored seed replays the same trials and samples.
/// Header-only, noexcept and allocation-free (the audio thread draws from it).
#include <cmath>
#include <cstdint>

namespace underfoot::base {

/// One SplitMix64 step: advances `state` and returns a well-mixed 64-bit value.
constexpr std::uint64_t splitMix64(std::uint64_t& state) noexcept {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// An independent seed for stream number `stream` of `seed` (one SplitMix64 step from the seed
/// mixed with the stream number).
constexpr std::uint64_t streamSeed(std::uint64_t seed, std::uint64_t stream) noexcept {
    std::uint64_t state = seed ^ (0x9E3779B97F4A7C15ull * (stream + 1));
    return splitMix64(state);
}

/// xoshiro256** with the draws both parts use.
class Xoshiro256 {
  public:
    explicit constexpr Xoshiro256(std::uint64_t seed) noexcept { reseed(seed); }

    /// Fills the state from `seed` through SplitMix64.
    constexpr void reseed(std::uint64_t seed) noexcept {
        for (auto& word : s_) word = splitMix64(seed);
    }

    /// Next raw 64-bit output.
    constexpr std::uint64_t next() noexcept {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }

    /// Uniform in [0, 1) with 53 random bits.
    constexpr double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

    /// Standard normal deviate (Box–Muller, one value per call for a fixed cost).
    double gaussian() noexcept {
        const double u1 = 1.0 - uniform(); // (0, 1]: safe for log()
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }

  private:
    static constexpr std::uint64_t rotl(std::uint64_t x, int k) noexcept {
        return (x << k) | (x >> (64 - k));
    }
    std::uint64_t s_[4]{};
};

} // namespace underfoot::base
