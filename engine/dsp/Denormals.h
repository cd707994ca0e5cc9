// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Flush-to-zero / denormals-are-zero for the current thread, for the lifetime of the guard.
/// The audio callback and the offline render loop hold one; `active()` checks that it took effect.
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define UNDERFOOT_HAS_MXCSR 1
#endif

namespace underfoot::engine {

class ScopedFlushDenormals {
  public:
    ScopedFlushDenormals() noexcept {
#ifdef UNDERFOOT_HAS_MXCSR
        saved_ = _mm_getcsr();
        _mm_setcsr(saved_ | 0x8040u); // FTZ (bit 15) | DAZ (bit 6)
#endif
    }
    ~ScopedFlushDenormals() {
#ifdef UNDERFOOT_HAS_MXCSR
        _mm_setcsr(saved_);
#endif
    }
    ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
    ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

    /// True when denormal floats are flushed on this thread right now (measured, not assumed).
    static bool active() noexcept {
        volatile float tiny = 1e-38f;
        volatile float r = tiny * 1e-3f; // would be a denormal
        return r == 0.0f;
    }

  private:
    unsigned saved_ = 0;
};

} // namespace underfoot::engine
