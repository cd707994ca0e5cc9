// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Seeded random numbers for every stochastic process of the engine.
///
/// The project's one generator (base/Xoshiro.h: xoshiro256**, Blackman & Vigna, seeded through
/// SplitMix64), with the draws the engine's models need. The same seed gives the same sequence on
/// every platform (no std:: distributions, whose output is implementation-defined). All draws
/// are noexcept and allocation-free.
#include "base/Xoshiro.h"

#include <cmath>
#include <cstdint>

namespace underfoot::engine {

class Random {
  public:
    explicit Random(std::uint64_t seed = 0x5eed) noexcept : gen_(seed) {}

    void setSeed(std::uint64_t seed) noexcept { gen_.reseed(seed); }

    /// Derives an independent seed for a sub-component (e.g. one layer of a surface).
    static std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream) noexcept {
        return base::streamSeed(seed, stream);
    }

    std::uint64_t next() noexcept { return gen_.next(); }

    /// Uniform in [0, 1) with 53 random bits.
    double uniform() noexcept { return gen_.uniform(); }
    /// Uniform in (0, 1]: safe for log().
    double uniformOpen0() noexcept { return 1.0 - uniform(); }
    /// Uniform in [lo, hi).
    double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * uniform(); }
    /// Uniform in [-1, 1).
    double bipolar() noexcept { return 2.0 * uniform() - 1.0; }
    /// Exponential inter-arrival time with the given rate (events per unit): -ln(U)/rate.
    double exponential(double rate) noexcept { return -std::log(uniformOpen0()) / rate; }
    /// Standard normal (Box–Muller; one value per call for a fixed cost).
    double gaussian() noexcept { return gen_.gaussian(); }
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
    base::Xoshiro256 gen_;
};

} // namespace underfoot::engine
