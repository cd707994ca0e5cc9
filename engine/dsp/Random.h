// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Seeded random numbers for every stochastic process of the engine.
///
/// xoshiro256** (Blackman & Vigna 2018, "Scrambled linear pseudorandom number generators"),
/// seeded through SplitMix64 so that any 64-bit seed gives a well-mixed state. The same seed gives
/// the same sequence on every platform (no std:: distributions, whose output is
/// implementation-defined). All draws are noexcept and allocation-free.
#include <cmath>
#include <cstdint>

namespace underfoot::engine {

class Random {
  public:
    explicit Random(std::uint64_t seed = 0x5eed) noexcept { setSeed(seed); }

    void setSeed(std::uint64_t seed) noexcept {
        std::uint64_t x = seed;
        for (auto& word : s_) word = splitMix64(x);
    }

    /// Derives an independent seed for a sub-component (e.g. one layer of a surface).
    static std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream) noexcept {
        std::uint64_t x = seed ^ (0x9E3779B97F4A7C15ull * (stream + 1));
        return splitMix64(x);
    }

    std::uint64_t next() noexcept {
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
    double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Uniform in (0, 1]: safe for log().
    double uniformOpen0() noexcept { return 1.0 - uniform(); }
    /// Uniform in [lo, hi).
    double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * uniform(); }
    /// Uniform in [-1, 1).
    double bipolar() noexcept { return 2.0 * uniform() - 1.0; }
    /// Exponential inter-arrival time with the given rate (events per unit): -ln(U)/rate.
    double exponential(double rate) noexcept { return -std::log(uniformOpen0()) / rate; }
    /// Standard normal (Box–Muller; one value per call for a fixed cost).
    double gaussian() noexcept {
        const double u1 = uniformOpen0();
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }
    /// Draw from p(x) ~ x^gamma on [lo, hi] (inverse-CDF sampling; gamma may be negative).
    double powerLaw(double gamma, double lo, double hi) noexcept {
        const double u = uniform();
        if (std::fabs(gamma + 1.0) < 1e-9) return lo * std::pow(hi / lo, u);
        const double g1 = gamma + 1.0;
        const double a = std::pow(lo, g1), b = std::pow(hi, g1);
        return std::pow(a + (b - a) * u, 1.0 / g1);
    }
    /// Integer uniform in [0, n).
    std::uint32_t below(std::uint32_t n) noexcept {
        return static_cast<std::uint32_t>((static_cast<unsigned __int128>(next() >> 32) * n) >> 32);
    }

  private:
    static std::uint64_t rotl(std::uint64_t x, int k) noexcept {
        return (x << k) | (x >> (64 - k));
    }
    static std::uint64_t splitMix64(std::uint64_t& x) noexcept {
        std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    std::uint64_t s_[4]{};
};

} // namespace underfoot::engine
