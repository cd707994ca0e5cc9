// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/VirtualWalker.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string_view>

namespace underfoot::engine {

namespace {

// Cubic Hermite on one segment of width h from (p0, m0) to (p1, m1), at local u in [0, 1].
double hermite(double p0, double m0, double p1, double m1, double h, double u) noexcept {
    const double u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * h * m0 + (-2 * u3 + 3 * u2) * p1 +
           (u3 - u2) * h * m1;
}

// Slope at the ends of the stance, in BW per unit of stance time: 1.5x the mean slope of the
// first/last quarter (a monotone Hermite needs <= 3x; 1.5 gives the convex-then-concave loading
// ramp of measured curves).
constexpr double kEdgeSlopeFactor = 6.0;

double clampd(double v, double lo, double hi) noexcept {
    return std::min(hi, std::max(lo, v));
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

} // namespace

double StanceShape::forceBw(double s) const noexcept {
    if (!(s >= 0.0) || s >= 1.0) return 0.0;
    constexpr double h = 0.25;
    double f;
    if (s < 0.25)
        f = hermite(0.0, kEdgeSlopeFactor * heelPeakBw, heelPeakBw, 0.0, h, s / h);
    else if (s < 0.5)
        f = hermite(heelPeakBw, 0.0, valleyBw, 0.0, h, (s - 0.25) / h);
    else if (s < 0.75)
        f = hermite(valleyBw, 0.0, pushOffPeakBw, 0.0, h, (s - 0.5) / h);
    else
        f = hermite(pushOffPeakBw, 0.0, 0.0, -kEdgeSlopeFactor * pushOffPeakBw, h, (s - 0.75) / h);
    const double sD = transientSeconds / stanceSeconds;
    if (s < sD) f += transientBw * 0.5 * (1.0 - std::cos(kTwoPi * s / sD));
    return f;
}

double VirtualWalker::dutyFactor(double cadenceStepsPerMin) noexcept {
    return clampd(0.60 - 0.001 * (cadenceStepsPerMin - 110.0), 0.55, 0.66);
}

StanceShape VirtualWalker::shapeFor(const WalkerParameters& p, double stepSeconds,
                                    const StanceJitter& jitter) noexcept {
    StanceShape sh;
    const double c = p.cadenceStepsPerMin;
    const double duty = dutyFactor(c);
    sh.stanceSeconds = 2.0 * duty * stepSeconds;
    const double heel = clampd(1.20 + 0.004 * (c - 110.0), 1.05, 1.40);
    const double push = clampd(1.12 + 0.002 * (c - 110.0), 1.04, 1.25);
    // Heel-strike transient: 0.05 BW over 25 ms for a soft shoe up to 0.40 BW over 8 ms for a
    // hard one (Whittle 1999: larger and sharper with hard soles).
    sh.transientBw = 0.05 + 0.35 * p.shoeHardness;
    sh.transientSeconds = 0.025 - 0.017 * p.shoeHardness;
    // Force balance: integral of one stance = BW x step time, i.e. a mean of step / stance
    // = 1 / (2 duty) body weights over the stance. Integral of the Hermite pieces
    // (h (p0 + p1) / 2 + h^2 (m0 - m1) / 12 each) plus the bump (A D / 2), in units of stance.
    const double targetMean = stepSeconds / sh.stanceSeconds;
    const double bump = 0.5 * sh.transientBw * sh.transientSeconds / sh.stanceSeconds;
    constexpr double kPeakWeight = 0.125 + 0.0625 * kEdgeSlopeFactor / 12.0 + 0.125;
    const double valley = (targetMean - kPeakWeight * (heel + push) - bump) / 0.25;
    // Jitter, then scale the curve so that the balance holds again.
    const double h1 = heel * (1.0 + jitter.heel), p2 = push * (1.0 + jitter.pushOff);
    // The valley stays between 35 % and 90 % of the peaks, before the scaling (which keeps
    // ratios), so that every step is a double hump and the balance holds exactly.
    const double v =
        clampd(valley * (1.0 + jitter.valley), 0.35 * std::max(h1, p2), 0.9 * std::min(h1, p2));
    const double k = (targetMean - bump) / (kPeakWeight * (h1 + p2) + 0.25 * v);
    sh.heelPeakBw = k * h1;
    sh.pushOffPeakBw = k * p2;
    sh.valleyBw = k * v;
    return sh;
}

VirtualWalker::VirtualWalker(const WalkerParameters& parameters) {
    setParameters(parameters);
}

void VirtualWalker::setParameters(const WalkerParameters& parameters) {
    parameters.validate();
    params_ = parameters;
}

void VirtualWalker::prepare(const ProcessSpec& spec) {
    if (!(spec.sampleRateHz > 0) || !std::isfinite(spec.sampleRateHz))
        throw std::invalid_argument("VirtualWalker::prepare: sample rate must be positive");
    sampleRateHz_ = spec.sampleRateHz;
    reset(0x5eed);
}

void VirtualWalker::reset(std::uint64_t seed) noexcept {
    random_.setSeed(seed);
    sample_ = 0;
    const double step = 0.5 * strideSeconds();
    // Steady walking from the first sample: the right foot struck half a stride ago.
    stance_[1].startSample = -step * sampleRateHz_;
    stance_[1].shape = shapeFor(params_, step);
    stance_[1].lengthSamples = stance_[1].shape.stanceSeconds * sampleRateHz_;
    stance_[1].active = true;
    stance_[0] = Stance{};
    nextStepSample_ = 0.0;
    nextFoot_ = 0;
}

void VirtualWalker::scheduleStep(int foot) noexcept {
    const double v = params_.variability;
    // Step time: relative std = variability; shape: std = variability / 2 (peak forces vary
    // less than timing between steps); both clamped at 2 sigma.
    const double jitterTime = clampd(random_.gaussian(), -2.0, 2.0) * v;
    StanceJitter jitter;
    jitter.heel = clampd(random_.gaussian(), -2.0, 2.0) * 0.5 * v;
    jitter.valley = clampd(random_.gaussian(), -2.0, 2.0) * 0.5 * v;
    jitter.pushOff = clampd(random_.gaussian(), -2.0, 2.0) * 0.5 * v;
    const double step = 0.5 * strideSeconds() * (1.0 + jitterTime);
    Stance& st = stance_[foot];
    st.startSample = nextStepSample_;
    st.shape = shapeFor(params_, step, jitter);
    st.lengthSamples = st.shape.stanceSeconds * sampleRateHz_;
    st.active = true;
    nextStepSample_ += step * sampleRateHz_;
    nextFoot_ = 1 - foot;
}

void VirtualWalker::process(float* left, float* right, int n) noexcept {
    const double bw = bodyWeightNewtons();
    float* out[2] = {left, right};
    for (int i = 0; i < n; ++i, ++sample_) {
        const auto t = static_cast<double>(sample_);
        while (t >= nextStepSample_) scheduleStep(nextFoot_);
        for (int foot = 0; foot < 2; ++foot) {
            Stance& st = stance_[foot];
            double f = 0.0;
            if (st.active) {
                const double s = (t - st.startSample) / st.lengthSamples;
                if (s >= 1.0)
                    st.active = false;
                else
                    f = st.shape.forceBw(s) * bw;
            }
            out[foot][i] = static_cast<float>(f);
        }
    }
}

void WalkerParameters::validate() const {
    auto check = [](const char* name, double v, double lo, double hi, const char* unit) {
        if (!std::isfinite(v) || v < lo || v > hi)
            throw std::invalid_argument(fmt::format(
                "walker: {} = {} is outside the valid range [{}, {}] {}", name, v, lo, hi, unit));
    };
    check("mass", massKg, kMinMassKg, kMaxMassKg, "kg");
    check("cadence", cadenceStepsPerMin, kMinCadence, kMaxCadence, "steps/min");
    check("shoe", shoeHardness, 0.0, 1.0, "(0 soft .. 1 hard)");
    check("variability", variability, 0.0, kMaxVariability, "(relative std)");
}

std::string WalkerParameters::toString() const {
    return fmt::format("cadence={},mass={},shoe={},variability={}", cadenceStepsPerMin, massKg,
                       shoeHardness, variability);
}

WalkerParameters WalkerParameters::parse(const std::string& spec) {
    WalkerParameters p;
    const std::string_view all(spec);
    bool seen[4] = {false, false, false, false};
    static constexpr const char* kKeys[4] = {"cadence", "mass", "shoe", "variability"};
    std::size_t pos = 0;
    if (trim(all).empty())
        throw std::invalid_argument("walker spec is empty; expected e.g. "
                                    "\"cadence=100,mass=70,shoe=0.5,variability=0.03\"");
    while (pos <= all.size()) {
        const std::size_t comma = std::min(all.find(',', pos), all.size());
        const std::string_view item = all.substr(pos, comma - pos);
        const std::size_t column = pos + 1;
        const std::size_t eq = item.find('=');
        if (eq == std::string_view::npos)
            throw std::invalid_argument(fmt::format(
                "walker spec, column {}: expected key=value, got \"{}\" (keys: cadence, mass, "
                "shoe, variability)",
                column, item));
        const std::string_view key = trim(item.substr(0, eq));
        const std::string_view valueText = trim(item.substr(eq + 1));
        int index = -1;
        for (int k = 0; k < 4; ++k)
            if (key == kKeys[k]) index = k;
        if (index < 0)
            throw std::invalid_argument(fmt::format(
                "walker spec, column {}: unknown key \"{}\"; expected one of cadence, mass, shoe, "
                "variability",
                column, key));
        if (seen[index])
            throw std::invalid_argument(
                fmt::format("walker spec, column {}: \"{}\" given twice", column, key));
        seen[index] = true;
        double value = 0;
        const auto* first = valueText.data();
        const auto* last = valueText.data() + valueText.size();
        const auto [end, ec] = std::from_chars(first, last, value);
        if (valueText.empty() || ec != std::errc() || end != last || !std::isfinite(value))
            throw std::invalid_argument(fmt::format(
                "walker spec, column {}: value of {} is \"{}\"; expected a finite number",
                column + eq + 1, key, valueText));
        switch (index) {
        case 0:
            p.cadenceStepsPerMin = value;
            break;
        case 1:
            p.massKg = value;
            break;
        case 2:
            p.shoeHardness = value;
            break;
        default:
            p.variability = value;
            break;
        }
        pos = comma + 1;
    }
    try {
        p.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("walker spec \"{}\": {}", spec, e.what()));
    }
    return p;
}

} // namespace underfoot::engine
