// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Block-size independence of sleep decisions (docs/explanation/performance.md, "Block-size
/// independence"; docs/decisions/sleep-grid.md).
///
/// A layer that stops computing when it has rung out ("falls asleep") must take that decision
/// at moments that do not depend on how the host cuts the signal into blocks, or the same input
/// renders differently at 64 and 256 frames (the sleep resets a state that still rings at
/// -125 dBFS; a replay at another block size would then differ from the live trial). So every
/// such decision (and every state flush that changes the next samples' bits) is taken on a
/// fixed grid of kSleepGridSamples samples counted from reset: process() splits each host block
/// at the grid points and decides only at them, over what happened since the previous one.
/// Waking is per sample (at the first sample that needs work), never per block.
///
/// Why 64: the live engine runs 64-frame periods, so a live block is one grid span (no extra
/// split where the cost matters most) and 256/1024-frame blocks split into whole spans; the
/// convolver's tick is 64 input samples too. 64 samples is 1.3 ms at 48 kHz, short against
/// the tails a layer waits before sleeping (50-250 ms), so sleeping starts at most 1.3 ms later
/// than a per-sample decision would. A shorter grid (32) doubles the decisions for no audible
/// gain; a longer one delays sleep and splits 64-frame live blocks.
#include <algorithm>

namespace underfoot::engine {

inline constexpr int kSleepGridSamples = 64;

/// The position inside the grid, counted from reset. No allocation.
class SleepGrid {
  public:
    void reset() noexcept { phase_ = 0; }
    /// Splits n samples at the grid points: calls span(offset, length, atGridPoint) for each
    /// piece in order; `atGridPoint` is true when the piece ends on a grid point (where the
    /// caller takes its decisions).
    template <typename Span>
    void split(int n, Span&& span) noexcept {
        int done = 0;
        while (done < n) {
            const int len = std::min(n - done, kSleepGridSamples - phase_);
            phase_ += len;
            const bool atGridPoint = phase_ == kSleepGridSamples;
            if (atGridPoint) phase_ = 0;
            span(done, len, atGridPoint);
            done += len;
        }
    }
    /// Samples since the last grid point.
    int phase() const noexcept { return phase_; }

  private:
    int phase_ = 0;
};

} // namespace underfoot::engine
