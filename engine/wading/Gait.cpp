// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/wading/Gait.h"

#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace underfoot::engine {

namespace {
void checkRange(const char* name, double v, double lo, double hi, const char* unit) {
    if (!std::isfinite(v) || v < lo || v > hi)
        throw std::invalid_argument(
            fmt::format("virtual gait: {} = {} is outside [{:g}, {:g}] {}", name, v, lo, hi, unit));
}

/// Normalised beta-shaped bump on u in [0, 1]: integral 1.
double bump(double u, double p, double q) noexcept {
    if (!(u > 0.0) || !(u < 1.0)) return 0.0;
    const double beta = std::tgamma(p + 1) * std::tgamma(q + 1) / std::tgamma(p + q + 2);
    return std::pow(u, p) * std::pow(1.0 - u, q) / beta;
}

constexpr double kThighSwingP = 1.3, kThighSwingQ = 2.0;
constexpr double kShankSwingP = 2.0, kShankSwingQ = 1.6;
constexpr double kStanceP = 1.5, kStanceQ = 1.5;
constexpr double kShankToThigh = 1.6;
} // namespace

void VirtualGaitParameters::validate() const {
    if (!std::isfinite(cadenceStepsPerMin) ||
        (cadenceStepsPerMin != 0.0 && (cadenceStepsPerMin < 10 || cadenceStepsPerMin > 160)))
        throw std::invalid_argument(
            fmt::format("virtual gait: cadence = {} steps/min: expected 0 (standing) or [10, 160]",
                        cadenceStepsPerMin));
    if (strideM != 0.0) checkRange("stride", strideM, 0.2, 2.5, "m (or 0: from the cadence)");
    checkRange("leg length", legLengthM, 0.5, 1.2, "m");
    checkRange("variability", variability, 0.0, 0.2, "");
}

double VirtualGaitParameters::swingSeconds(double strideSeconds) noexcept {
    return std::min(0.4 * strideSeconds, 0.25 + 0.15 * strideSeconds);
}

double VirtualGaitParameters::thighExcursionDeg() const noexcept {
    return 2.0 * std::atan(effectiveStrideM() / (4.0 * legLengthM)) * 180.0 / kPi;
}

std::vector<GaitFrame> virtualGait(const VirtualGaitParameters& p, double seconds,
                                   std::uint64_t seed) {
    p.validate();
    if (!std::isfinite(seconds) || seconds < 0 || seconds > 24 * 3600)
        throw std::invalid_argument(
            fmt::format("virtual gait: duration {} s: expected [0, 86400]", seconds));
    const auto count = static_cast<std::size_t>(std::floor(seconds * kGaitFrameRateHz + 1e-9));
    std::vector<GaitFrame> frames(count);
    for (std::size_t k = 0; k < count; ++k)
        frames[k].timeS = static_cast<double>(k) / kGaitFrameRateHz;
    if (p.cadenceStepsPerMin == 0.0 || count == 0) return frames;

    Random random(Random::deriveSeed(seed, 0x6A17));
    const double sd = p.variability;
    auto jitter = [&] { return 1.0 + std::clamp(sd * random.gaussian(), -2 * sd, 2 * sd); };
    const double step = 60.0 / p.cadenceStepsPerMin;
    const double excursion = p.thighExcursionDeg();

    // Heel strikes: steps alternate left (even) / right (odd), from well before t = 0.
    struct Strike {
        double timeS;
        double amplitude; ///< swing amplitude factor of the swing that ends here
    };
    std::array<std::vector<Strike>, 2> strikes;
    double t = -4.0 * step;
    for (int k = 0; t < seconds + 4.0 * step; ++k) {
        strikes[static_cast<std::size_t>(k % 2)].push_back({t, jitter()});
        t += step * jitter();
    }
    for (std::size_t side = 0; side < 2; ++side) {
        const auto& s = strikes[side];
        std::size_t j = 0;
        const Limb thigh = side == 0 ? Limb::LeftThigh : Limb::RightThigh;
        const Limb shank = side == 0 ? Limb::LeftShank : Limb::RightShank;
        for (auto& frame : frames) {
            while (j + 2 < s.size() && s[j + 1].timeS <= frame.timeS) ++j;
            const double start = s[j].timeS, end = s[j + 1].timeS;
            const double stride = end - start;
            const double swing = VirtualGaitParameters::swingSeconds(stride);
            const double stance = stride - swing;
            const double a = s[j + 1].amplitude * excursion;
            const double swingStart = end - swing;
            double wThigh, wShank;
            if (frame.timeS >= swingStart) {
                const double u = (frame.timeS - swingStart) / swing;
                wThigh = a * bump(u, kThighSwingP, kThighSwingQ) / swing;
                wShank = kShankToThigh * a * bump(u, kShankSwingP, kShankSwingQ) / swing;
            } else {
                // Backward rotation during stance by the excursion of the swing before it.
                const double back = s[j].amplitude * excursion;
                const double u = (frame.timeS - start) / stance;
                wThigh = -back * bump(u, kStanceP, kStanceQ) / stance;
                wShank = -kShankToThigh * back * bump(u, kStanceP, kStanceQ) / stance;
            }
            frame[thigh] = wThigh;
            frame[shank] = wShank;
        }
    }
    return frames;
}

// ---------------------------------------------------------------------------------------------
// CSV

namespace {
std::string trim(std::string s) {
    const auto b = s.find_first_not_of(" \t\r");
    const auto e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<std::string> splitFields(const std::string& line) {
    std::vector<std::string> out;
    std::string field;
    std::istringstream in(line);
    while (std::getline(in, field, ',')) out.push_back(trim(field));
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
}

int columnIndex(const std::string& rawName) {
    std::string n = rawName;
    std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
    if (n == "time_s" || n == "time" || n == "t") return 0;
    const char* names[4] = {"left_thigh", "right_thigh", "left_shank", "right_shank"};
    for (int i = 0; i < 4; ++i)
        if (n == names[i] || n == std::string(names[i]) + "_dps") return i + 1;
    return -1;
}
} // namespace

std::vector<GaitFrame> parseGaitCsv(const std::string& text, const std::string& name,
                                    bool* hasShanks) {
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    std::vector<int> columns; // field index -> column (0 time, 1..4 limbs)
    std::array<int, 5> present{-1, -1, -1, -1, -1};
    std::vector<double> times;
    std::vector<std::array<double, 4>> rows;
    auto fail = [&](const std::string& what) -> void {
        throw GaitFileError(fmt::format("{}:{}: {}", name, lineNo, what));
    };
    const std::string expectedHeader =
        "a header of time_s, left_thigh_dps, right_thigh_dps[, left_shank_dps, right_shank_dps]";
    while (std::getline(in, line)) {
        ++lineNo;
        const std::string t = trim(line);
        if (t.empty() || t[0] == '#') continue;
        const auto fields = splitFields(t);
        if (columns.empty()) {
            for (std::size_t i = 0; i < fields.size(); ++i) {
                const int c = columnIndex(fields[i]);
                if (c < 0)
                    fail(fmt::format("unknown column \"{}\": expected {}", fields[i],
                                     expectedHeader));
                if (present[static_cast<std::size_t>(c)] >= 0)
                    fail(fmt::format("column \"{}\" appears twice", fields[i]));
                present[static_cast<std::size_t>(c)] = static_cast<int>(i);
                columns.push_back(c);
            }
            if (present[0] < 0 || present[1] < 0 || present[2] < 0)
                fail("expected " + expectedHeader + " (time and both thighs are required)");
            if ((present[3] < 0) != (present[4] < 0))
                fail("expected both shank columns (left_shank_dps and right_shank_dps) or none");
            continue;
        }
        if (fields.size() != columns.size())
            fail(fmt::format("expected {} comma-separated numbers, got {} fields", columns.size(),
                             fields.size()));
        std::array<double, 4> row{};
        double time = 0;
        for (std::size_t i = 0; i < fields.size(); ++i) {
            const std::string& f = fields[i];
            errno = 0;
            char* endp = nullptr;
            const double v = f.empty() ? 0.0 : std::strtod(f.c_str(), &endp);
            if (f.empty() || endp != f.c_str() + f.size())
                fail(fmt::format("field {} (\"{}\"): expected a number", i + 1, f));
            if (!std::isfinite(v) || errno == ERANGE)
                fail(fmt::format("field {} (\"{}\"): expected a finite number (NaN/Inf refused)",
                                 i + 1, f));
            const int c = columns[i];
            if (c == 0) {
                time = v;
            } else {
                if (std::fabs(v) > 5000)
                    fail(fmt::format("field {} ({} deg/s): expected an angular velocity within "
                                     "+-5000 deg/s",
                                     i + 1, v));
                row[static_cast<std::size_t>(c - 1)] = v;
            }
        }
        if (!times.empty() && !(time > times.back()))
            fail(fmt::format("time {} s: expected times to increase (previous {} s)", time,
                             times.back()));
        if (!times.empty() && time - times.back() > 1.0)
            fail(fmt::format("time {} s: a gap of {:.3f} s since the previous row; expected "
                             "readings at least every second",
                             time, time - times.back()));
        times.push_back(time);
        rows.push_back(row);
    }
    if (columns.empty()) {
        lineNo = std::max(lineNo, 1);
        fail("empty file: expected " + expectedHeader);
    }
    if (rows.size() < 2) fail("expected at least two rows of readings");
    if (hasShanks) *hasShanks = present[3] >= 0;

    // Resample onto 100 Hz frames from the first time (linear interpolation).
    const double t0 = times.front();
    const double span = times.back() - t0;
    const auto count = static_cast<std::size_t>(std::floor(span * kGaitFrameRateHz + 1e-6)) + 1;
    std::vector<GaitFrame> frames(count);
    std::size_t j = 0;
    for (std::size_t k = 0; k < count; ++k) {
        const double tk = t0 + static_cast<double>(k) / kGaitFrameRateHz;
        while (j + 2 < times.size() && times[j + 1] <= tk + 1e-9) ++j;
        double w = (tk - times[j]) / (times[j + 1] - times[j]);
        w = std::clamp(w, 0.0, 1.0);
        if (w < 1e-9) w = 0.0;
        if (w > 1.0 - 1e-9) w = 1.0;
        frames[k].timeS = static_cast<double>(k) / kGaitFrameRateHz;
        for (std::size_t l = 0; l < kLimbCount; ++l)
            frames[k].angularVelocityDps[l] = rows[j][l] + w * (rows[j + 1][l] - rows[j][l]);
    }
    return frames;
}

std::vector<GaitFrame> readGaitCsv(const std::string& path, bool* hasShanks) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw GaitFileError(fmt::format("{}: cannot open the gait file", path));
    std::ostringstream ss;
    ss << file.rdbuf();
    return parseGaitCsv(ss.str(), path, hasShanks);
}

void writeGaitCsv(const std::string& path, const std::vector<GaitFrame>& frames) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw GaitFileError(fmt::format("{}: cannot write the gait file", path));
    out << "# Underfoot gait: sagittal angular velocity (deg/s, positive = forward swing)\n";
    out << "time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,right_shank_dps\n";
    for (const auto& f : frames) {
        for (double v : f.angularVelocityDps)
            if (!std::isfinite(v))
                throw GaitFileError(fmt::format("{}: refusing to write a non-finite angular "
                                                "velocity at t = {} s",
                                                path, f.timeS));
        out << fmt::format("{:.4f},{:.6f},{:.6f},{:.6f},{:.6f}\n", f.timeS, f[Limb::LeftThigh],
                           f[Limb::RightThigh], f[Limb::LeftShank], f[Limb::RightShank]);
    }
    if (!out) throw GaitFileError(fmt::format("{}: write failed", path));
}

// ---------------------------------------------------------------------------------------------

void GaitFrameAssembler::reset() noexcept {
    held_ = GaitFrame{};
    nextFrameTimeS_ = -1.0;
    rejected_ = 0;
}

bool GaitFrameAssembler::push(const GyroSample& sample, GaitFrame& frame) noexcept {
    const auto limb = static_cast<std::size_t>(sample.limb);
    if (limb >= kLimbCount || !std::isfinite(sample.angularVelocityDps) ||
        std::fabs(sample.angularVelocityDps) > 5000.0 || !std::isfinite(sample.timeS)) {
        ++rejected_;
        return false;
    }
    held_.angularVelocityDps[limb] = sample.angularVelocityDps;
    const double period = 1.0 / kGaitFrameRateHz;
    if (nextFrameTimeS_ < 0.0) nextFrameTimeS_ = sample.timeS;
    if (sample.timeS + 1e-9 < nextFrameTimeS_) return false;
    held_.timeS = sample.timeS;
    frame = held_;
    nextFrameTimeS_ += period;
    if (nextFrameTimeS_ <= sample.timeS) nextFrameTimeS_ = sample.timeS + period; // fell behind
    return true;
}

} // namespace underfoot::engine
