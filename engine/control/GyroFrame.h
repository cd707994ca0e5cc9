// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Angular-velocity readings of the legs (the wading study; docs/explanation/studies.md): the
/// common currency between the gyroscope inputs (OSC receiver, recorded gait files, the virtual
/// gait) and the controls that use them (the wading simulation). Sagittal-plane angular velocity in
/// degrees per second, positive when the limb swings forward.
#include <array>
#include <cstddef>
#include <cstdint>

namespace underfoot::engine {

/// The four instrumented limbs, in the order of recorded gait files.
enum class Limb : std::uint8_t { LeftThigh = 0, RightThigh = 1, LeftShank = 2, RightShank = 3 };
inline constexpr std::size_t kLimbCount = 4;

/// One reading of one limb's sensor (OSC sends one packet per limb).
struct GyroSample {
    double timeS = 0; ///< receive (or recording) time, seconds on the session clock
    Limb limb = Limb::LeftThigh;
    double angularVelocityDps = 0;
    std::uint32_t sequence = 0; ///< per-limb packet counter (0 when the source has none)
};

/// All four limbs at one instant (recorded gait files, virtual gait, resampled live input).
struct GaitFrame {
    double timeS = 0;
    std::array<double, kLimbCount> angularVelocityDps{}; ///< indexed by Limb
    double& operator[](Limb limb) noexcept {
        return angularVelocityDps[static_cast<std::size_t>(limb)];
    }
    double operator[](Limb limb) const noexcept {
        return angularVelocityDps[static_cast<std::size_t>(limb)];
    }
};

} // namespace underfoot::engine
