// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/Simd.h"

#include <cstdlib>
#include <cstring>

namespace underfoot::engine {
namespace {

enum class Limit { Sse2, Avx, Any, Invalid };

Limit readLimit() noexcept {
    const char* s = std::getenv("UNDERFOOT_SIMD");
    if (s == nullptr || *s == '\0') return Limit::Any;
    if (std::strcmp(s, "sse2") == 0) return Limit::Sse2;
    if (std::strcmp(s, "avx") == 0) return Limit::Avx;
    return Limit::Invalid; // refused by the programs (simdEnvironmentValid); no limit otherwise
}

Limit limitFromEnvironment() noexcept {
    static const Limit limit = readLimit(); // read once, before the first prepare()
    return limit;
}

} // namespace

bool simdAllowsAvx() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    static const bool allowed =
        limitFromEnvironment() != Limit::Sse2 && __builtin_cpu_supports("avx") != 0;
    return allowed;
#else
    return false;
#endif
}

bool simdAllowsAvx512() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    static const bool allowed = limitFromEnvironment() != Limit::Sse2 &&
                                limitFromEnvironment() != Limit::Avx &&
                                __builtin_cpu_supports("avx512f") != 0;
    return allowed;
#else
    return false;
#endif
}

bool simdEnvironmentValid() noexcept {
    return limitFromEnvironment() != Limit::Invalid;
}

} // namespace underfoot::engine
