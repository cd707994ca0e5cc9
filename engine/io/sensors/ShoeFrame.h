// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Readings of the FSR shoes (Turchet et al. 2010): two force-sensing resistors per sandal (heel,
/// toe), digitised by an Arduino at 1 kHz and streamed over serial (docs/reference/sensors.md,
/// "Shoes: the serial line protocol").
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace underfoot::engine {

/// Which shoe.
enum class Foot : std::uint8_t { Left = 0, Right = 1 };
/// Which sensor of a shoe.
enum class FootPart : std::uint8_t { Heel = 0, Toe = 1 };

/// The four pressure sensors, in the column order of the line protocol (lh, lt, rh, rt).
inline constexpr std::size_t kShoeSensorCount = 4;

/// Index of a sensor in ShoeFrame::raw (foot * 2 + part).
constexpr std::size_t shoeSensorIndex(Foot foot, FootPart part) noexcept {
    return static_cast<std::size_t>(foot) * 2 + static_cast<std::size_t>(part);
}
/// Foot of sensor index i (0..3).
constexpr Foot shoeSensorFoot(std::size_t i) noexcept {
    return i < 2 ? Foot::Left : Foot::Right;
}
/// Part of sensor index i (0..3).
constexpr FootPart shoeSensorPart(std::size_t i) noexcept {
    return i % 2 == 0 ? FootPart::Heel : FootPart::Toe;
}
/// Protocol/TOML name of sensor index i: "left_heel", "left_toe", "right_heel", "right_toe".
std::string_view shoeSensorName(std::size_t i) noexcept;
/// Short column name of sensor index i: "lh", "lt", "rh", "rt".
std::string_view shoeSensorColumn(std::size_t i) noexcept;
/// "left" / "right".
std::string_view footName(Foot foot) noexcept;
/// "heel" / "toe".
std::string_view footPartName(FootPart part) noexcept;

/// One line of the shoes' stream: the four raw ADC readings at one device instant.
struct ShoeFrame {
    double timeS = 0;           ///< host receive time, seconds on the sensor clock (SensorClock.h)
    std::uint32_t deviceMs = 0; ///< the sketch's sample clock (t_ms column), milliseconds
    std::uint64_t index = 0;    ///< frames accepted since the source started (0, 1, 2, ...)
    std::array<std::uint16_t, kShoeSensorCount> raw{}; ///< 10-bit pressures 0..1023, lh lt rh rt
};

} // namespace underfoot::engine
