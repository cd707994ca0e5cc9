// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/ShoeProtocol.h"

#include <fmt/core.h>

#include <charconv>
#include <cmath>

namespace underfoot::engine {

std::string_view shoeSensorName(std::size_t i) noexcept {
    constexpr std::string_view names[] = {"left_heel", "left_toe", "right_heel", "right_toe"};
    return i < kShoeSensorCount ? names[i] : "unknown";
}
std::string_view shoeSensorColumn(std::size_t i) noexcept {
    constexpr std::string_view names[] = {"lh", "lt", "rh", "rt"};
    return i < kShoeSensorCount ? names[i] : "?";
}
std::string_view footName(Foot foot) noexcept {
    return foot == Foot::Left ? "left" : "right";
}
std::string_view footPartName(FootPart part) noexcept {
    return part == FootPart::Heel ? "heel" : "toe";
}

namespace {

/// Printable excerpt of a bad line (non-printable bytes as \xNN, at most 40 characters).
std::string excerpt(std::string_view line) {
    std::string out;
    for (char c : line.substr(0, 40)) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f && c != '"')
            out += c;
        else
            out += fmt::format("\\x{:02x}", u);
    }
    if (line.size() > 40) out += "...";
    return out;
}

bool parseUnsigned(std::string_view s, std::uint64_t max, std::uint64_t& value) {
    if (s.empty() || s.size() > 10) return false;
    for (char c : s)
        if (c < '0' || c > '9') return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), value);
    return r.ec == std::errc() && r.ptr == s.data() + s.size() && value <= max;
}

} // namespace

bool ShoeLineParser::reject(std::string_view line, std::string_view expected) {
    error_ = fmt::format("line {}: expected {}, got \"{}\"", line_, expected, excerpt(line));
    return false;
}

void ShoeLineParser::lineTooLong(std::size_t bytes) {
    ++line_;
    error_ = fmt::format("line {}: expected a line of at most {} bytes, got {} bytes without '\\n'",
                         line_, kShoeMaxLineBytes, bytes);
}

ShoeLineKind ShoeLineParser::parse(std::string_view line, ShoeFrame& out) {
    ++line_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.size() > kShoeMaxLineBytes) {
        reject(line, fmt::format("a line of at most {} bytes", kShoeMaxLineBytes));
        return ShoeLineKind::Rejected;
    }
    if (!line.empty() && line.front() == '#') {
        constexpr std::string_view tag = "# underfoot-shoes ";
        if (line.substr(0, tag.size()) != tag) return ShoeLineKind::Comment;
        // "# underfoot-shoes <version> key=value ..."
        std::string_view rest = line.substr(tag.size());
        int version = 0;
        double rate = 1000;
        int bits = 10;
        std::size_t field = 0;
        while (!rest.empty()) {
            const std::size_t sp = rest.find(' ');
            const std::string_view tok = rest.substr(0, sp);
            rest = sp == std::string_view::npos ? std::string_view{} : rest.substr(sp + 1);
            if (tok.empty()) continue;
            std::uint64_t v = 0;
            if (field++ == 0) {
                if (!parseUnsigned(tok, 1000, v)) {
                    reject(line, "a protocol version number after \"# underfoot-shoes\"");
                    return ShoeLineKind::Rejected;
                }
                version = static_cast<int>(v);
            } else if (tok.substr(0, 8) == "rate_hz=") {
                if (!parseUnsigned(tok.substr(8), 100000, v) || v == 0) {
                    reject(line, "rate_hz=<1..100000>");
                    return ShoeLineKind::Rejected;
                }
                rate = static_cast<double>(v);
            } else if (tok.substr(0, 9) == "adc_bits=") {
                if (!parseUnsigned(tok.substr(9), 16, v) || v < 8) {
                    reject(line, "adc_bits=<8..16>");
                    return ShoeLineKind::Rejected;
                }
                bits = static_cast<int>(v);
            } else if (tok.substr(0, 8) == "columns=") {
                if (tok.substr(8) != "t_ms,lh,lt,rh,rt") {
                    reject(line, "columns=t_ms,lh,lt,rh,rt");
                    return ShoeLineKind::Rejected;
                }
            } // unknown keys are ignored (forward compatible)
        }
        if (version != kShoeProtocolVersion) {
            error_ = fmt::format("line {}: expected protocol version {}, got {} (update Underfoot "
                                 "or flash the matching sketch)",
                                 line_, kShoeProtocolVersion, version);
            return ShoeLineKind::Rejected;
        }
        headerSeen_ = true;
        version_ = version;
        rateHz_ = rate;
        adcBits_ = bits;
        return ShoeLineKind::Header;
    }
    std::string_view fields[5];
    std::size_t count = 0;
    std::string_view rest = line;
    while (true) {
        const std::size_t comma = rest.find(',');
        if (count < 5) fields[count] = rest.substr(0, comma);
        ++count;
        if (comma == std::string_view::npos) break;
        rest = rest.substr(comma + 1);
    }
    if (count != 5) {
        reject(line, fmt::format("5 comma-separated fields t_ms,lh,lt,rh,rt (found {})", count));
        return ShoeLineKind::Rejected;
    }
    std::uint64_t t = 0;
    if (!parseUnsigned(fields[0], 0xffffffffull, t)) {
        reject(line, "t_ms (field 1) as an unsigned 32-bit integer");
        return ShoeLineKind::Rejected;
    }
    const std::uint64_t maxAdc = (1ull << adcBits_) - 1;
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        std::uint64_t v = 0;
        if (!parseUnsigned(fields[i + 1], maxAdc, v)) {
            reject(line, fmt::format("{} (field {}) as an integer 0..{}", shoeSensorColumn(i),
                                     i + 2, maxAdc));
            return ShoeLineKind::Rejected;
        }
        out.raw[i] = static_cast<std::uint16_t>(v);
    }
    out.deviceMs = static_cast<std::uint32_t>(t);
    return ShoeLineKind::Frame;
}

std::uint64_t ShoeLineParser::gapBefore(std::uint32_t deviceMs, std::string& why) {
    why.clear();
    const double periodMs = 1000.0 / rateHz_;
    std::uint64_t lost = 0;
    if (havePrevious_) {
        const std::uint32_t delta = deviceMs - previousMs_; // modulo 2^32 (millis() wraps)
        if (delta == 0 || delta > 0x80000000u) {
            why = fmt::format("t_ms {} -> {}: device clock restarted", previousMs_, deviceMs);
        } else {
            const auto steps = static_cast<std::uint64_t>(std::llround(delta / periodMs));
            if (steps > 1) {
                lost = steps - 1;
                why = fmt::format("t_ms {} -> {}: {} frame{} lost", previousMs_, deviceMs, lost,
                                  lost == 1 ? "" : "s");
            }
        }
    }
    havePrevious_ = true;
    previousMs_ = deviceMs;
    return lost;
}

std::string formatShoeLine(std::uint32_t deviceMs,
                           const std::array<std::uint16_t, kShoeSensorCount>& raw) {
    return fmt::format("{},{},{},{},{}\n", deviceMs, raw[0], raw[1], raw[2], raw[3]);
}

std::string shoeHeaderLine(double rateHz, int adcBits) {
    return fmt::format("# underfoot-shoes {} rate_hz={:.0f} adc_bits={} columns=t_ms,lh,lt,rh,rt\n",
                       kShoeProtocolVersion, rateHz, adcBits);
}

} // namespace underfoot::engine
