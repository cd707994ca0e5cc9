// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/ShoeSimulator.h"
#include "engine/dsp/ProcessSpec.h"

#include <algorithm>
#include <cmath>

namespace underfoot::engine {

ShoeScript::ShoeScript(ShoeWalkOptions options, std::uint64_t seed) : o_(options), jitter_(seed) {
    // Standing on both feet from before the start.
    for (std::size_t s = 0; s < kShoeSensorCount; ++s) {
        ShoeContact c;
        c.sensor = s;
        c.onMs = -1000;
        c.peak = shoeSensorPart(s) == FootPart::Heel ? o_.standHeel : o_.standToe;
        contacts_.push_back(c);
        open_[s] = contacts_.size();
    }
}

void ShoeScript::stand(double ms) {
    standing_ = {true, true};
    endMs_ += ms;
}

void ShoeScript::bump(std::size_t sensor, double afterMs, double amount) {
    bumps_.push_back({sensor, endMs_ + afterMs, amount});
}

void ShoeScript::lift(double ms) {
    for (std::size_t s = 0; s < kShoeSensorCount; ++s)
        if (open_[s]) {
            contacts_[open_[s] - 1].offMs = endMs_;
            open_[s] = 0;
        }
    standing_ = {false, false};
    endMs_ += ms;
}

void ShoeScript::walk(int steps, Foot first) {
    const double t0 = endMs_ + o_.swingMs;
    for (int k = 0; k < steps; ++k) {
        const Foot foot = (k % 2 == 0) == (first == Foot::Left) ? Foot::Left : Foot::Right;
        const double strike = t0 + k * o_.stepIntervalMs;
        const auto f = static_cast<std::size_t>(foot);
        for (FootPart part : {FootPart::Heel, FootPart::Toe}) {
            const std::size_t s = shoeSensorIndex(foot, part);
            if (open_[s]) { // lift the foot for its swing
                ShoeContact& c = contacts_[open_[s] - 1];
                c.offMs = std::max(c.onMs + 1, strike - o_.swingMs);
                open_[s] = 0;
            }
        }
        standing_[f] = false;
        const double j1 = 1 + o_.peakJitter * jitter_.bipolar();
        const double j2 = 1 + o_.peakJitter * jitter_.bipolar();
        const bool last = k + 2 >= steps; // the last step of each foot stays down
        ShoeContact heel{shoeSensorIndex(foot, FootPart::Heel), strike, strike + o_.heelStanceMs,
                         o_.heelPeak * j1};
        ShoeContact toe{shoeSensorIndex(foot, FootPart::Toe), strike + o_.toeDelayMs,
                        strike + o_.toeDelayMs + o_.toeStanceMs, o_.toePeak * j2};
        if (last) {
            heel.offMs = toe.offMs = std::numeric_limits<double>::infinity();
            heel.peak = o_.standHeel * j1;
            toe.peak = o_.standToe * j2;
        }
        contacts_.push_back(heel);
        if (last) open_[heel.sensor] = contacts_.size();
        contacts_.push_back(toe);
        if (last) open_[toe.sensor] = contacts_.size();
    }
    endMs_ = t0 + (steps - 1) * o_.stepIntervalMs + o_.toeDelayMs + o_.toeStanceMs;
}

std::vector<ShoeContact> ShoeScript::strikes() const {
    std::vector<ShoeContact> out;
    for (const ShoeContact& c : contacts_)
        if (c.onMs >= 0 && c.onMs < endMs_) out.push_back(c);
    std::sort(out.begin(), out.end(),
              [](const ShoeContact& a, const ShoeContact& b) { return a.onMs < b.onMs; });
    return out;
}

std::array<std::uint16_t, kShoeSensorCount> ShoeScript::sample(std::size_t frame,
                                                               Random& random) const {
    const double t = static_cast<double>(frame);
    std::array<double, kShoeSensorCount> x{};
    for (const ShoeContact& c : contacts_) {
        if (t < c.onMs || t >= c.offMs + o_.fallMs) continue;
        double shape = 1;
        if (t < c.onMs + o_.riseMs) shape = 0.5 * (1 - std::cos(kPi * (t - c.onMs) / o_.riseMs));
        if (t >= c.offMs) shape *= 0.5 * (1 + std::cos(kPi * (t - c.offMs) / o_.fallMs));
        const double phase = shoeSensorPart(c.sensor) == FootPart::Heel ? 0 : kPi;
        const double sway = 1 + o_.swayDepth * std::sin(2 * kPi * o_.swayHz * t * 0.001 + phase);
        x[c.sensor] += c.peak * shape * sway;
    }
    for (const ShoeBump& b : bumps_) {
        if (t < b.atMs) continue;
        const double u = t - b.atMs;
        const double rise = u < 20 ? 0.5 * (1 - std::cos(kPi * u / 20)) : 1;
        x[b.sensor] += b.amount * rise * std::exp(-std::max(0.0, u - 20) / 300);
    }
    std::array<std::uint16_t, kShoeSensorCount> raw{};
    for (std::size_t s = 0; s < kShoeSensorCount; ++s) {
        const int noise =
            o_.noiseLsb > 0
                ? static_cast<int>(random.below(static_cast<std::uint32_t>(2 * o_.noiseLsb + 1))) -
                      o_.noiseLsb
                : 0;
        const double v = std::round(o_.restLevel + x[s]) + noise;
        raw[s] = static_cast<std::uint16_t>(std::clamp(v, 0.0, 1023.0));
    }
    return raw;
}

ShoeScript defaultWalkScript(std::uint64_t seed, const ShoeWalkOptions& options) {
    ShoeScript s(options, seed);
    s.stand(1000);
    s.walk(8);
    s.bump(shoeSensorIndex(Foot::Left, FootPart::Heel), 700);
    s.bump(shoeSensorIndex(Foot::Right, FootPart::Toe), 1300);
    s.stand(2000);
    s.walk(6, Foot::Right);
    s.stand(1000);
    return s;
}

} // namespace underfoot::engine
