// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Which vector instructions the engine's kernels may use on this machine.
///
/// The modal bank and the convolver choose their kernels at run time (prepare()); every kernel
/// does the same IEEE operations per lane (no FMA), so the samples do not depend on the choice.
/// Setting the environment variable UNDERFOOT_SIMD=sse2 before the program starts limits every
/// kernel to SSE2, the x86-64 baseline: rendering once with it and once without is how the
/// identity is checked end to end (tests/engine/simd_identical.sh).

/// Marks a kernel compiled for AVX (chosen at run time; nothing on other architectures). On a
/// member of a class template that is not itself a template, put it on the declaration too: GCC
/// ignores it on the out-of-class definition alone.
#if defined(__x86_64__) || defined(__i386__)
#define UNDERFOOT_TARGET_AVX __attribute__((target("avx")))
#else
#define UNDERFOOT_TARGET_AVX
#endif

namespace underfoot::engine {

/// True when the CPU and the OS support AVX and UNDERFOOT_SIMD does not say "sse2". Read once.
bool simdAllowsAvx() noexcept;
/// True when the CPU and the OS support AVX-512F and UNDERFOOT_SIMD does not say "sse2" or "avx".
bool simdAllowsAvx512() noexcept;
/// False when UNDERFOOT_SIMD is set to something other than "sse2" or "avx" (the programs then
/// refuse to start and say so, rather than ignore a typo).
bool simdEnvironmentValid() noexcept;

} // namespace underfoot::engine
