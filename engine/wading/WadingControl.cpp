// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/wading/WadingControl.h"
#include "engine/dsp/ProcessSpec.h"

#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

namespace {
std::size_t idx(Limb l) {
    return static_cast<std::size_t>(l);
}
} // namespace

GyroFilter parseGyroFilter(const std::string& name) {
    if (name == "butterworth_5hz") return GyroFilter::Butterworth5Hz;
    if (name == "butterworth_0_8hz") return GyroFilter::Butterworth0_8Hz;
    if (name == "asymmetric") return GyroFilter::Asymmetric;
    throw std::invalid_argument("filter \"" + name +
                                "\": expected butterworth_5hz, butterworth_0_8hz or asymmetric");
}

std::string gyroFilterName(GyroFilter filter) {
    switch (filter) {
    case GyroFilter::Butterworth5Hz:
        return "butterworth_5hz";
    case GyroFilter::Butterworth0_8Hz:
        return "butterworth_0_8hz";
    case GyroFilter::Asymmetric:
        return "asymmetric";
    }
    return "?";
}

WadingAlgorithm parseWadingAlgorithm(const std::string& name) {
    if (name == "v1") return WadingAlgorithm::V1;
    if (name == "v2") return WadingAlgorithm::V2;
    throw std::invalid_argument("algorithm \"" + name + "\": expected v1 or v2");
}

void WadingControl::configure(WadingAlgorithm algorithm, GyroFilter filter,
                              const WadingMapping& mapping, double frameRateHz) {
    algorithm_ = algorithm;
    mapping_ = mapping;
    for (std::size_t l = 0; l < kLimbCount; ++l) {
        const bool left = l == idx(Limb::LeftThigh) || l == idx(Limb::LeftShank);
        const bool slow =
            filter == GyroFilter::Butterworth0_8Hz || (filter == GyroFilter::Asymmetric && !left);
        lowpass_[l].design(frameRateHz, slow ? 0.8 : 5.0, slow ? kSlowFilterMakeUpGain : 1.0);
    }
    const double releases[kWadingLayerCount] = {mapping.c1ReleaseMs, mapping.c2ReleaseMs,
                                                mapping.c3ReleaseMs};
    for (std::size_t k = 0; k < kWadingLayerCount; ++k) {
        sumEnv_[k].setTimesMs(mapping.attackMs, releases[k], frameRateHz);
        for (auto& e : sideEnv_[k]) e.setTimesMs(mapping.attackMs, releases[k], frameRateHz);
    }
    splashDelay_.prepare(mapping.splashDelayMs * 1e-3, frameRateHz);
    for (auto& d : splashSideDelay_) d.prepare(mapping.splashDelayMs * 1e-3, frameRateHz);
    reset();
}

void WadingControl::reset() noexcept {
    for (auto& f : lowpass_) f.reset();
    last_.fill(0.0);
    for (auto& e : sumEnv_) e.reset();
    for (auto& s : sideEnv_)
        for (auto& e : s) e.reset();
    splashDelay_.reset();
    for (auto& d : splashSideDelay_) d.reset();
    out_ = WadingControls{};
    rejected_ = 0;
}

double WadingControl::restGain(double db, double control) const noexcept {
    const double fade = mapping_.restFade > 0 ? std::min(1.0, control / mapping_.restFade) : 1.0;
    return control > 0 ? dbToGain(db) * fade : 0.0;
}

const WadingControls& WadingControl::push(const GaitFrame& frame) noexcept {
    std::array<double, kLimbCount> n{};
    for (std::size_t l = 0; l < kLimbCount; ++l) {
        double w = frame.angularVelocityDps[l];
        if (!std::isfinite(w) || std::fabs(w) > 5000.0) {
            ++rejected_;
            w = last_[l];
        }
        last_[l] = w;
        n[l] = normaliseForward(lowpass_[l].processSample(w), mapping_.normaliseRangeDps);
    }
    out_.normalised = n;
    const double lt = n[idx(Limb::LeftThigh)], rt = n[idx(Limb::RightThigh)];
    const double ls = n[idx(Limb::LeftShank)], rs = n[idx(Limb::RightShank)];
    auto split = [](double total, double left, double right, std::array<double, 2>& g) {
        const double s = left + right;
        const double shareLeft = s > 0 ? left / s : 0.5;
        g[0] = total * std::sqrt(shareLeft);
        g[1] = total * std::sqrt(1.0 - shareLeft);
    };
    if (algorithm_ == WadingAlgorithm::V1) {
        const double c = sumClamped(lt, rt);
        out_.v1 = c;
        const double g = c > 0 ? c * dbToGain(mapping_.v1GainDb) : 0.0;
        split(g, lt, rt, out_.gain[0]);
        split(g, lt, rt, out_.gain[1]);
        out_.gain[2] = {0.0, 0.0};
        out_.eqDb = 0.0;
        out_.bubbleRateScale = c;
        return out_;
    }
    const double w1 = mapping_.thighWeight, w2 = mapping_.shankWeight;
    // C1: weighted thigh sum -> follower -> x^k1.
    out_.c1 = powerShape(sumEnv_[0].processSample(sumClamped(lt, rt, w1, w1)), mapping_.c1Exponent);
    // C2: shank sum -> follower -> x^k2.
    out_.c2 = powerShape(sumEnv_[1].processSample(sumClamped(ls, rs, w2, w2)), mapping_.c2Exponent);
    // C3: shank sum delayed -> follower -> x^k3.
    out_.c3 =
        powerShape(sumEnv_[2].processSample(splashDelay_.processSample(sumClamped(ls, rs, w2, w2))),
                   mapping_.c3Exponent);
    // Side shares: the same followers on each limb's own signal.
    const double e1l = sideEnv_[0][0].processSample(lt), e1r = sideEnv_[0][1].processSample(rt);
    const double e2l = sideEnv_[1][0].processSample(ls), e2r = sideEnv_[1][1].processSample(rs);
    const double e3l = sideEnv_[2][0].processSample(splashSideDelay_[0].processSample(ls));
    const double e3r = sideEnv_[2][1].processSample(splashSideDelay_[1].processSample(rs));
    const auto& m = mapping_;
    split(restGain(faderDb(out_.c1, m.flowingMinDb, m.flowingMaxDb), out_.c1), e1l, e1r,
          out_.gain[0]);
    split(restGain(faderDb(out_.c2, m.bubblingMinDb, m.bubblingMaxDb), out_.c2), e2l, e2r,
          out_.gain[1]);
    split(restGain(faderDb(out_.c3, m.splashMinDb, m.splashMaxDb), out_.c3), e3l, e3r,
          out_.gain[2]);
    out_.eqDb = m.eqMaxDb * out_.c1;
    out_.bubbleRateScale = 1.0;
    return out_;
}

} // namespace underfoot::engine
