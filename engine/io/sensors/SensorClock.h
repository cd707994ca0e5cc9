// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The clock every sensor thread stamps its frames with: std::chrono::steady_clock in seconds
/// (monotonic, shared by all threads of the process, unaffected by wall-clock changes). The
/// audio side maps it to sample positions by reading the same clock at each callback.
#include <chrono>

namespace underfoot::engine {

/// Seconds on the sensor clock (steady_clock since its epoch).
inline double sensorClockSeconds() noexcept {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

} // namespace underfoot::engine
