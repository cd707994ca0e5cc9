// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Bubbles.h"

#include "engine/dsp/ProcessSpec.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace underfoot::engine {

namespace {
constexpr int kLanes = 4;
constexpr int kMaxBubblesPerSample = 8;
constexpr double kSilenceBelowMaxDb = -80.0;
constexpr double kNyquistGuard = 0.45;

void require(bool ok, const char* name, const char* expected, double value) {
    if (!ok)
        throw std::invalid_argument(
            fmt::format("bubble parameter {}: expected {}, got {:g}", name, expected, value));
}
typedef double D2 __attribute__((vector_size(16)));
inline D2 load2(const double* p) noexcept {
    D2 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
inline void store2(double* p, D2 v) noexcept {
    std::memcpy(p, &v, sizeof v);
}
int roundUpLanes(int v) {
    return (v + kLanes - 1) / kLanes * kLanes;
}
} // namespace

void BubbleStreamParameters::validate() const {
    require(std::isfinite(radiusMinM) && radiusMinM > 0, "radiusMinM", "a positive radius",
            radiusMinM);
    require(std::isfinite(radiusMaxM) && radiusMaxM >= radiusMinM, "radiusMaxM",
            "a radius >= radiusMinM", radiusMaxM);
    require(std::isfinite(radiusExponent) && std::fabs(radiusExponent) <= 10, "radiusExponent",
            "a number in [-10, 10]", radiusExponent);
    require(std::isfinite(xi) && xi >= 0 && xi <= 1, "xi", "a number in [0, 1]", xi);
    require(std::isfinite(depthMin) && depthMin > 0 && depthMin <= 1, "depthMin",
            "a number in (0, 1]", depthMin);
    require(voices >= 1 && voices <= 4096, "voices", "1..4096", voices);
    require(std::isfinite(maxRateHz) && maxRateHz > 0, "maxRateHz", "a positive rate", maxRateHz);
}

void BubbleStream::configure(const BubbleStreamParameters& parameters) {
    parameters.validate();
    params_ = parameters;
}

void BubbleStream::prepare(double sampleRateHz, int maxEventsPerSecond) {
    if (!(sampleRateHz > 0) || !std::isfinite(sampleRateHz))
        throw std::invalid_argument(fmt::format("bubbles: bad sample rate {:g}", sampleRateHz));
    sampleRateHz_ = sampleRateHz;
    rateCapHz_ = std::min(params_.maxRateHz, static_cast<double>(std::max(1, maxEventsPerSecond)));
    minRadiusM_ = 3.0 / (kNyquistGuard * sampleRateHz_);
    const double rMax = std::max(params_.radiusMaxM, minRadiusM_);
    silenceAmplitude_ =
        BubblePhysics::amplitude(rMax, 1.0) * std::pow(10.0, kSilenceBelowMaxDb / 20.0);
    const auto slots = static_cast<std::size_t>(roundUpLanes(params_.voices));
    for (auto* v : {&zr_, &zi_, &wr_, &wi_, &ur_, &ui_, &g_, &startAmplitude_, &logDecay_})
        v->assign(slots, 0.0);
    death_.assign(slots, 0);
    start_.assign(slots, 0);
    reset(0);
}

void BubbleStream::reset(std::uint64_t seed) noexcept {
    random_.setSeed(seed);
    clock_.reset(random_);
    for (auto* v : {&zr_, &zi_, &wr_, &wi_, &ur_, &ui_, &g_}) std::fill(v->begin(), v->end(), 0.0);
    activeVoices_ = 0;
    nextDeath_ = INT64_MAX;
    sample_ = 0;
    bubbleCount_ = 0;
    scale_ = 1.0;
    pendingRadius_ = pendingDepth_ = 0.0;
}

void BubbleStream::triggerBubble(double radiusM, double depth) noexcept {
    if (!(radiusM > 0) || !std::isfinite(radiusM) || !(depth > 0) || !std::isfinite(depth)) return;
    pendingRadius_ = radiusM;
    pendingDepth_ = depth;
}

void BubbleStream::spawn(double radiusM, double depth) noexcept {
    ++bubbleCount_;
    if (zr_.empty()) return;
    const double r = std::max(radiusM, minRadiusM_);
    const double amplitude = BubblePhysics::amplitude(r, depth) * scale_;
    if (!(amplitude > silenceAmplitude_)) return;
    int v;
    if (activeVoices_ < params_.voices) {
        v = activeVoices_++;
    } else {
        v = 0;
        double quietest = HUGE_VAL;
        for (int i = 0; i < activeVoices_; ++i) {
            const auto u = static_cast<std::size_t>(i);
            const double a = startAmplitude_[u] *
                             std::exp(logDecay_[u] * static_cast<double>(sample_ - start_[u]));
            if (a < quietest) {
                quietest = a;
                v = i;
            }
        }
    }
    const double f0 = BubblePhysics::frequencyHz(r);
    const double d = BubblePhysics::dampingPerSecond(r);
    const double sigma = params_.xi * d; // f(t) = f0 (1 + sigma t)
    const double T = 1.0 / sampleRateHz_;
    // Phase increment over sample n: 2 pi f0 T (1 + sigma (n + 1/2) T); it grows by
    // 2 pi f0 sigma T^2 per sample.
    const double delta0 = kTwoPi * f0 * T * (1.0 + 0.5 * sigma * T);
    const double chirp = kTwoPi * f0 * sigma * T * T;
    const auto u = static_cast<std::size_t>(v);
    zr_[u] = amplitude; // z = a e^{i 0}: output Im(z) = a sin(phase)
    zi_[u] = 0.0;
    wr_[u] = std::cos(delta0);
    wi_[u] = std::sin(delta0);
    ur_[u] = std::cos(chirp);
    ui_[u] = std::sin(chirp);
    g_[u] = std::exp(-d * T);
    // Ends 80 dB below the loudest bubble, or when the rising pitch reaches 0.45 fs.
    double life = std::log(amplitude / silenceAmplitude_) / (d * T);
    if (sigma > 0)
        life = std::min(life, (kNyquistGuard * sampleRateHz_ / f0 - 1.0) / sigma * sampleRateHz_);
    life = std::min(life, 60.0 * sampleRateHz_);
    death_[u] = sample_ + static_cast<std::int64_t>(std::ceil(std::max(life, 1.0)));
    start_[u] = sample_;
    startAmplitude_[u] = amplitude;
    logDecay_[u] = -d * T;
    nextDeath_ = std::min(nextDeath_, death_[u]);
}

void BubbleStream::freeVoice(int v) noexcept {
    const auto d = static_cast<std::size_t>(v);
    const auto s = static_cast<std::size_t>(activeVoices_ - 1);
    if (d != s) {
        for (auto* a : {&zr_, &zi_, &wr_, &wi_, &ur_, &ui_, &g_, &startAmplitude_, &logDecay_})
            (*a)[d] = (*a)[s];
        death_[d] = death_[s];
        start_[d] = start_[s];
    }
    zr_[s] = zi_[s] = wr_[s] = wi_[s] = ur_[s] = ui_[s] = g_[s] = 0.0;
    --activeVoices_;
}

void BubbleStream::retireDeadVoices() noexcept {
    for (int v = activeVoices_ - 1; v >= 0; --v)
        if (death_[static_cast<std::size_t>(v)] <= sample_) freeVoice(v);
    nextDeath_ = INT64_MAX;
    for (int v = 0; v < activeVoices_; ++v)
        nextDeath_ = std::min(nextDeath_, death_[static_cast<std::size_t>(v)]);
}

void BubbleStream::process(const float* rateHz, const float* amplitudeScale, float* out,
                           int n) noexcept {
    if (zr_.empty()) return;
    const double T = 1.0 / sampleRateHz_;
    double* zr = zr_.data();
    double* zi = zi_.data();
    double* wr = wr_.data();
    double* wi = wi_.data();
    const double* ur = ur_.data();
    const double* ui = ui_.data();
    const double* g = g_.data();
    for (int i = 0; i < n; ++i) {
        double rate = static_cast<double>(rateHz[i]);
        if (!(rate > 0)) rate = 0;
        rate = std::min(rate, rateCapHz_);
        const double s = static_cast<double>(amplitudeScale[i]);
        scale_ = (s > 0 && std::isfinite(s)) ? s : 0.0;
        if (pendingRadius_ > 0) {
            const double keep = scale_;
            scale_ = 1.0;
            spawn(pendingRadius_, pendingDepth_);
            scale_ = keep;
            pendingRadius_ = 0;
        }
        const int count = clock_.advance(rate * T, random_, kMaxBubblesPerSample);
        for (int e = 0; e < count; ++e) {
            const double r =
                random_.powerLaw(params_.radiusExponent, params_.radiusMinM, params_.radiusMaxM);
            spawn(r, random_.uniform(params_.depthMin, 1.0));
        }
        if (sample_ >= nextDeath_) retireDeadVoices();
        const int slots = roundUpLanes(activeVoices_);
        // Four lanes as two pairs of doubles (SSE2 on x86-64: each lane computes exactly what
        // the scalar expression computes; the lane sums are added in the same order as before).
        D2 accLo = {0.0, 0.0}, accHi = {0.0, 0.0};
        for (int j = 0; j < slots; j += kLanes) {
            for (int h = 0; h < kLanes; h += 2) {
                const int k = j + h;
                const D2 zrk = load2(zr + k), zik = load2(zi + k), wrk = load2(wr + k),
                         wik = load2(wi + k), urk = load2(ur + k), uik = load2(ui + k),
                         gk = load2(g + k);
                (h == 0 ? accLo : accHi) += zik;
                // z <- z w g, then w <- w u (the rotation of the next sample)
                store2(zr + k, (zrk * wrk - zik * wik) * gk);
                store2(zi + k, (zrk * wik + zik * wrk) * gk);
                store2(wr + k, wrk * urk - wik * uik);
                store2(wi + k, wrk * uik + wik * urk);
            }
        }
        const double acc[kLanes] = {accLo[0], accLo[1], accHi[0], accHi[1]};
        out[i] += static_cast<float>(acc[0] + acc[1] + acc[2] + acc[3]);
        ++sample_;
    }
}

} // namespace underfoot::engine
