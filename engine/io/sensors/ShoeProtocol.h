// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The line protocol of the FSR shoes (docs/reference/sensors.md, "Shoes: the serial line
/// protocol"), version 1:
///
///     # underfoot-shoes 1 rate_hz=1000 adc_bits=10
///     123456,12,8,640,702
///
/// ASCII, one frame per '\n'-terminated line ('\r' before it is ignored): the sketch's sample
/// clock in milliseconds and the raw ADC readings of left heel, left toe, right heel, right toe.
/// Lines starting with '#' are the header (the sketch sends it at start-up; it may come at any
/// time, `columns=` is optional and must read t_ms,lh,lt,rh,rt when present) or comments.
/// The parser never throws: a bad line is rejected with a reason naming its number and what was
/// expected, and the stream goes on.
#include "engine/io/sensors/ShoeFrame.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace underfoot::engine {

/// Protocol version this reader understands.
inline constexpr int kShoeProtocolVersion = 1;
/// Longest accepted line in bytes (a v1 frame is at most 30, the header about 70).
inline constexpr std::size_t kShoeMaxLineBytes = 128;

/// What one line was.
enum class ShoeLineKind : std::uint8_t { Frame, Header, Comment, Rejected };

/// Stateful parser of the shoes' lines (line numbers, header settings, device-clock gaps).
class ShoeLineParser {
  public:
    /// Parses one line (without its '\n'). On Frame, fills out.deviceMs and out.raw (not the
    /// host time or index). On Rejected, error() says why.
    ShoeLineKind parse(std::string_view line, ShoeFrame& out);
    /// Counts an over-long line (the reader discards its bytes up to the next '\n').
    void lineTooLong(std::size_t bytes);

    /// The reason of the last rejection: "line 812: expected 5 comma-separated fields
    /// t_ms,lh,lt,rh,rt, got 3 in \"12,40,x\"".
    const std::string& error() const noexcept { return error_; }
    std::uint64_t lineNumber() const noexcept { return line_; }
    bool headerSeen() const noexcept { return headerSeen_; }
    int version() const noexcept { return version_; }
    double rateHz() const noexcept { return rateHz_; }
    int adcBits() const noexcept { return adcBits_; }

    /// Frames missing between the previous frame and `deviceMs` judged by the device clock
    /// (the sketch samples every 1000 / rate_hz ms); 0 for the first frame or a clock restart.
    /// Updates the previous time; `why` describes a gap or restart (empty otherwise).
    std::uint64_t gapBefore(std::uint32_t deviceMs, std::string& why);

  private:
    bool reject(std::string_view line, std::string_view expected);
    std::string error_;
    std::uint64_t line_ = 0;
    bool headerSeen_ = false;
    int version_ = kShoeProtocolVersion;
    double rateHz_ = 1000;
    int adcBits_ = 10;
    bool havePrevious_ = false;
    std::uint32_t previousMs_ = 0;
};

/// Formats one v1 frame line (with '\n'), as the sketch does (used by tests and simulators).
std::string formatShoeLine(std::uint32_t deviceMs,
                           const std::array<std::uint16_t, kShoeSensorCount>& raw);
/// The v1 header line (with '\n').
std::string shoeHeaderLine(double rateHz = 1000, int adcBits = 10);

} // namespace underfoot::engine
