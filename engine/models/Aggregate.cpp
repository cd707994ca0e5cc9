// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Aggregate.h"

#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Simd.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace underfoot::engine {

namespace {
constexpr int kLanes = 8;                 // resonator slots summed in parallel lanes
constexpr int kRunMax = 128;              // samples the resonators run at a time (laneSums_)
constexpr int kMaxEventsPerSample = 8;    // bound on the work of one sample
constexpr int kMaxBurstEvents = 256;      // bound on pending burst micro-events
constexpr double kMaxVoiceSeconds = 30.0; // no voice rings longer than this
constexpr double kSilenceBelowMaxDb = -80.0;

void require(bool ok, const char* name, const std::string& expected, double value) {
    if (!ok)
        throw std::invalid_argument(
            fmt::format("aggregate parameter {}: expected {}, got {:g}", name, expected, value));
}

int roundUpLanes(int slots) {
    return (slots + kLanes - 1) / kLanes * kLanes;
}

// Eight resonator slots (one lane group) as one AVX vector, or as two SSE2 quads. Both do, lane
// by lane, the IEEE float operations of the scalar recurrence (no FMA: neither target enables
// it), so the samples do not depend on the kernel.
typedef float F4 __attribute__((vector_size(16)));
typedef float F8 __attribute__((vector_size(32)));

// (Loaded through a reference, not returned: a 32-byte vector returned by value from code built
// without AVX would change the calling convention.)
template <typename V>
[[gnu::always_inline]] inline void load(V& v, const float* p) noexcept {
    std::memcpy(&v, p, sizeof v);
}
template <typename V>
[[gnu::always_inline]] inline void store(float* p, const V& v) noexcept {
    std::memcpy(p, &v, sizeof v);
}

// Runs the resonators of slots [s, s + lanes of V) over n samples from their state in c1..y2,
// adding each sample's output to the lane sums at sums + t * kLanes + lane (lane = s % kLanes).
// The first group of a run starts the sums at 0.0f + y, as the sample-by-sample loop did.
template <typename V, bool First>
[[gnu::always_inline]] inline void ringSlots(const float* c1, const float* c2, float* y1, float* y2,
                                             int s, float* sums, int n) noexcept {
    V a, b, x, y;
    load(a, c1 + s);
    load(b, c2 + s);
    load(x, y1 + s);
    load(y, y2 + s);
    float* lane = sums + s % kLanes;
    for (int t = 0; t < n; ++t, lane += kLanes) {
        const V nx = a * x - b * y;
        const V ny = b * x + a * y;
        x = nx;
        y = ny;
        V sum{};
        if constexpr (!First) load(sum, lane);
        store(lane, sum + ny);
    }
    store(y1 + s, x);
    store(y2 + s, y);
}

// Two groups of eight slots at once in one pass over the samples (two independent recurrences
// in flight); group j's output is added to the sums before group j + 1's, as in a single pass.
template <typename V, bool First>
[[gnu::always_inline]] inline void ringTwoGroups(const float* c1, const float* c2, float* y1,
                                                 float* y2, int s, float* sums, int n) noexcept {
    V a0, b0, a1, b1, x0, y0, x1, y1v;
    load(a0, c1 + s);
    load(b0, c2 + s);
    load(a1, c1 + s + kLanes);
    load(b1, c2 + s + kLanes);
    load(x0, y1 + s);
    load(y0, y2 + s);
    load(x1, y1 + s + kLanes);
    load(y1v, y2 + s + kLanes);
    float* lane = sums;
    for (int t = 0; t < n; ++t, lane += kLanes) {
        const V nx0 = a0 * x0 - b0 * y0;
        const V ny0 = b0 * x0 + a0 * y0;
        const V nx1 = a1 * x1 - b1 * y1v;
        const V ny1 = b1 * x1 + a1 * y1v;
        x0 = nx0;
        y0 = ny0;
        x1 = nx1;
        y1v = ny1;
        V sum{};
        if constexpr (!First) load(sum, lane);
        store(lane, (sum + ny0) + ny1);
    }
    store(y1 + s, x0);
    store(y2 + s, y0);
    store(y1 + s + kLanes, x1);
    store(y2 + s + kLanes, y1v);
}
} // namespace

void AggregateParameters::validate() const {
    auto finite = [](double v) { return std::isfinite(v); };
    require(finite(gamma) && gamma >= -10 && gamma <= 10, "gamma", "a number in [-10, 10]", gamma);
    require(finite(energyMin) && energyMin > 0, "energyMin", "a positive number", energyMin);
    require(finite(energyMax) && energyMax >= energyMin, "energyMax", "a number >= energyMin",
            energyMax);
    require(resonances >= 1 && resonances <= 4, "resonances", "1..4", resonances);
    require(finite(freqMinHz) && freqMinHz > 0, "freqMinHz", "a positive frequency", freqMinHz);
    require(finite(freqMaxHz) && freqMaxHz >= freqMinHz, "freqMaxHz", "a frequency >= freqMinHz",
            freqMaxHz);
    require(finite(qMin) && qMin >= 0.1, "qMin", "a quality factor >= 0.1", qMin);
    require(finite(qMax) && qMax >= qMin, "qMax", "a quality factor >= qMin", qMax);
    require(voices >= 1 && voices <= 4096, "voices", "1..4096", voices);
    require(finite(burstEvents) && burstEvents >= 0 && burstEvents <= 64, "burstEvents",
            "a mean count in [0, 64]", burstEvents);
    require(finite(burstMs) && burstMs > 0, "burstMs", "a positive time", burstMs);
    require(finite(maxRateHz) && maxRateHz > 0, "maxRateHz", "a positive rate", maxRateHz);
    require(finite(amplitudeCap) && amplitudeCap >= 0, "amplitudeCap",
            "a non-negative amplitude (0: no bound)", amplitudeCap);
    require(finite(noiseDecayMs) && noiseDecayMs > 0, "noiseDecayMs", "a positive time",
            noiseDecayMs);
    require(finite(noiseCornerHz) && noiseCornerHz >= 0, "noiseCornerHz",
            "a frequency >= 0 (0: white)", noiseCornerHz);
    require(finite(noiseAttackMs) && noiseAttackMs >= 0 && noiseAttackMs < noiseDecayMs,
            "noiseAttackMs", "a time >= 0 and below noiseDecayMs (0: instantaneous)",
            noiseAttackMs);
}

void AggregateModel::configure(const AggregateParameters& parameters) {
    parameters.validate();
    params_ = parameters;
}

void AggregateModel::prepare(double sampleRateHz, int maxEventsPerSecond) {
    if (!(sampleRateHz > 0) || !std::isfinite(sampleRateHz))
        throw std::invalid_argument(fmt::format("aggregate: bad sample rate {:g}", sampleRateHz));
    sampleRateHz_ = sampleRateHz;
    const double cap =
        std::min(params_.maxRateHz, static_cast<double>(std::max(1, maxEventsPerSecond)));
    // The cap bounds the total rate, burst micro-events included.
    rateCapHz_ = cap;
    silenceAmplitude_ = std::sqrt(params_.energyMax) * std::pow(10.0, kSilenceBelowMaxDb / 20.0);
    stride_ = params_.resonances;
    const std::size_t slots = static_cast<std::size_t>(roundUpLanes(params_.voices * stride_));
    c1_.assign(slots, 0.0f);
    c2_.assign(slots, 0.0f);
    y1_.assign(slots, 0.0f);
    y2_.assign(slots, 0.0f);
    const auto v = static_cast<std::size_t>(params_.voices);
    deathSample_.assign(v, 0);
    startAmplitude_.assign(v, 0.0);
    logDecay_.assign(v, 0.0);
    startSample_.assign(v, 0);
    laneSums_.assign(static_cast<std::size_t>(kRunMax * kLanes), 0.0f);
    noise_ = params_.excitation == AggregateParameters::Excitation::Noise;
    noiseLogDecay_ = -1.0 / (params_.noiseDecayMs * 1e-3 * sampleRateHz_);
    noisePowerDecay_ = std::exp(2.0 * noiseLogDecay_);
    noiseRiseDecay_ = params_.noiseAttackMs > 0
                          ? std::exp(-2.0 / (params_.noiseAttackMs * 1e-3 * sampleRateHz_))
                          : 0.0;
    // y += (1 - a) (x - y) with a = exp(-2 pi fc / fs); its output variance is (1 - a) / (1 + a).
    noiseColour_ = params_.noiseCornerHz > 0
                       ? std::exp(-kTwoPi * std::min(params_.noiseCornerHz, 0.45 * sampleRateHz_) /
                                  sampleRateHz_)
                       : 0.0;
    noiseColourGain_ = std::sqrt((1.0 + noiseColour_) / (1.0 - noiseColour_));
    allowAvx(avxAllowed_);
    reset(0);
}

void AggregateModel::allowAvx(bool on) noexcept {
    avxAllowed_ = on;
    ring_ = on && simdAllowsAvx() ? &ringAvx : &ringGeneric;
}

bool AggregateModel::usesAvx() const noexcept {
    return ring_ == &ringAvx;
}

template <bool Avx>
[[gnu::always_inline]] inline void AggregateModel::ringBody(float* out, int n) noexcept {
    const int slots = roundUpLanes(activeVoices_ * stride_);
    if (slots == 0) {
        for (int t = 0; t < n; ++t) out[t] += 0.0f; // as the sum of no lanes
        return;
    }
    float* c1 = c1_.data();
    float* c2 = c2_.data();
    float* y1 = y1_.data();
    float* y2 = y2_.data();
    float* sums = laneSums_.data();
    if constexpr (Avx) {
        int s = 0;
        if (slots >= 2 * kLanes) {
            ringTwoGroups<F8, true>(c1, c2, y1, y2, 0, sums, n);
            for (s = 2 * kLanes; s + 2 * kLanes <= slots; s += 2 * kLanes)
                ringTwoGroups<F8, false>(c1, c2, y1, y2, s, sums, n);
        } else {
            ringSlots<F8, true>(c1, c2, y1, y2, 0, sums, n);
            s = kLanes;
        }
        if (s < slots) ringSlots<F8, false>(c1, c2, y1, y2, s, sums, n);
    } else {
        ringSlots<F4, true>(c1, c2, y1, y2, 0, sums, n);
        ringSlots<F4, true>(c1, c2, y1, y2, 4, sums, n);
        for (int s = kLanes; s < slots; s += kLanes) {
            ringSlots<F4, false>(c1, c2, y1, y2, s, sums, n);
            ringSlots<F4, false>(c1, c2, y1, y2, s + 4, sums, n);
        }
    }
    for (int t = 0; t < n; ++t) {
        const float* lane = sums + t * kLanes;
        float sum = 0.0f;
        for (int l = 0; l < kLanes; ++l) sum += lane[l];
        out[t] += sum;
    }
}

void AggregateModel::ringGeneric(AggregateModel& m, float* out, int n) noexcept {
    m.ringBody<false>(out, n);
}

UNDERFOOT_TARGET_AVX
void AggregateModel::ringAvx(AggregateModel& m, float* out, int n) noexcept {
    m.ringBody<true>(out, n);
}

void AggregateModel::ringNoise(float* out, int n) noexcept {
    if (noisePower_ == 0.0) return;
    const double floor = silenceAmplitude_ * silenceAmplitude_;
    const double unitVariance = std::sqrt(3.0) * noiseColourGain_; // uniform: variance 1/3
    const double a = noiseColour_;
    for (int t = 0; t < n; ++t) {
        noiseState_ += (1.0 - a) * (noiseRandom_.bipolar() - noiseState_);
        // (without an attack noiseRise_ stays 0: the same samples as before)
        const double power = std::max(noisePower_ - noiseRise_, 0.0);
        out[t] += static_cast<float>(std::sqrt(power) * unitVariance * noiseState_);
        noisePower_ *= noisePowerDecay_;
        noiseRise_ *= noiseRiseDecay_;
        if (noisePower_ < floor) { // 80 dB below the largest burst: silent
            noisePower_ = 0.0;
            noiseRise_ = 0.0;
            return;
        }
    }
}

void AggregateModel::ring(float* out, int n) noexcept {
    if (noise_) {
        ringNoise(out, n);
        return;
    }
    for (int done = 0; done < n; done += kRunMax)
        ring_(*this, out + done, std::min(kRunMax, n - done));
}

void AggregateModel::reset(std::uint64_t seed) noexcept {
    random_.setSeed(seed);
    clock_.reset(random_);
    burstClock_.reset(random_);
    burstRemaining_ = 0;
    burstScale_ = 0.0;
    pendingTrigger_ = 0.0;
    std::fill(c1_.begin(), c1_.end(), 0.0f);
    std::fill(c2_.begin(), c2_.end(), 0.0f);
    std::fill(y1_.begin(), y1_.end(), 0.0f);
    std::fill(y2_.begin(), y2_.end(), 0.0f);
    activeVoices_ = 0;
    nextDeath_ = INT64_MAX;
    sample_ = 0;
    eventCount_ = 0;
    stolen_ = 0;
    capped_ = 0;
    peakSummed_ = 0.0;
    noisePower_ = 0.0;
    noiseRise_ = 0.0;
    noiseState_ = 0.0;
    noiseAmplitude_ = 0.0;
    noiseAmplitudeAt_ = 0;
    noiseRandom_.setSeed(Random::deriveSeed(seed, 0x6e6f697365)); // "noise"
}

void AggregateModel::trigger(double energy) noexcept {
    if (std::isfinite(energy) && energy > 0) pendingTrigger_ += energy;
}

bool AggregateModel::fitUnderCap(double summed, double& amplitude) noexcept {
    const double room = params_.amplitudeCap - summed;
    if (amplitude > room) {
        ++capped_;
        amplitude = room;
        if (!(amplitude > silenceAmplitude_)) {
            peakSummed_ = std::max(peakSummed_, summed);
            return false; // the bed is at its bound: this break releases nothing audible
        }
    }
    peakSummed_ = std::max(peakSummed_, summed + amplitude);
    return true;
}

void AggregateModel::spawn(double energy, bool burst) noexcept {
    ++eventCount_;
    if (observer_) observer_(observerUser_, {sample_, energy, burst});
    double amplitude = std::sqrt(energy);
    if (!(amplitude > silenceAmplitude_) || c1_.empty()) return; // inaudible: no voice
    if (noise_) {
        spawnNoise(amplitude);
        return;
    }
    // Current envelope of every ringing voice: their sum (for the energy bound) and the quietest
    // (replaced when the pool is full). The loop runs only when one of them is needed.
    const bool full = activeVoices_ >= params_.voices;
    const double cap = params_.amplitudeCap;
    int quietestVoice = 0;
    double quietest = HUGE_VAL, summed = 0.0;
    if (full || cap > 0) {
        for (int i = 0; i < activeVoices_; ++i) {
            const auto u = static_cast<std::size_t>(i);
            const double a =
                startAmplitude_[u] *
                std::exp(logDecay_[u] * static_cast<double>(sample_ - startSample_[u]));
            summed += a;
            if (a < quietest) {
                quietest = a;
                quietestVoice = i;
            }
        }
    }
    if (cap > 0) {
        if (full) summed -= quietest; // that voice is replaced
        if (!fitUnderCap(summed, amplitude)) return;
    }
    int v;
    if (!full) {
        v = activeVoices_++;
    } else { // pool full: replace the quietest voice
        v = quietestVoice;
        ++stolen_;
    }
    const double nyquistGuard = 0.45 * sampleRateHz_; // resonances stay below Nyquist
    const double fLo = std::min(params_.freqMinHz, nyquistGuard);
    const double fHi = std::min(params_.freqMaxHz, nyquistGuard);
    double weights[4];
    double sumSquares = 0.0;
    for (int k = 0; k < stride_; ++k) {
        weights[k] = random_.uniform(0.3, 1.0);
        sumSquares += weights[k] * weights[k];
    }
    const double norm = amplitude / std::sqrt(sumSquares);
    double slowest = 0.0; // largest log(r), i.e. the slowest decay
    bool first = true;
    for (int k = 0; k < stride_; ++k) {
        const double f = fLo * std::pow(fHi / fLo, random_.uniform());
        const double q = params_.qMin * std::pow(params_.qMax / params_.qMin, random_.uniform());
        const double theta = kTwoPi * f / sampleRateHz_;
        const double logR = -kPi * f / (q * sampleRateHz_);
        const double r = std::exp(logR);
        const auto s = static_cast<std::size_t>(v * stride_ + k);
        // Rotation (coupled) form: [x, y] <- r [cos, -sin; sin, cos] [x, y]. Its coefficients
        // keep sin(theta) apart from cos(theta), so low frequencies stay accurate in float at any
        // sample rate, and the pole radius is r exactly as long as a^2 + b^2 < 1.
        float a = static_cast<float>(r * std::cos(theta));
        float b = static_cast<float>(r * std::sin(theta));
        const double radius2 = static_cast<double>(a) * a + static_cast<double>(b) * b;
        if (radius2 >= 1.0) { // rounding reached the unit circle: pull the pole back inside
            const double shrink = (1.0 - 1e-6) / std::sqrt(radius2);
            a = static_cast<float>(a * shrink);
            b = static_cast<float>(b * shrink);
        }
        c1_[s] = a;
        c2_[s] = b;
        // Starts at [A, 0]: y[n] = A r^n sin(n theta) (from the first processed sample on).
        y1_[s] = static_cast<float>(norm * weights[k]);
        y2_[s] = 0.0f;
        if (first || logR > slowest) slowest = logR;
        first = false;
    }
    const auto u = static_cast<std::size_t>(v);
    const double life = std::min(std::log(silenceAmplitude_ / amplitude) / slowest,
                                 kMaxVoiceSeconds * sampleRateHz_);
    deathSample_[u] = sample_ + static_cast<std::int64_t>(std::ceil(life)) + 1;
    startAmplitude_[u] = amplitude;
    logDecay_[u] = slowest;
    startSample_[u] = sample_;
    nextDeath_ = std::min(nextDeath_, deathSample_[u]);
}

void AggregateModel::spawnNoise(double amplitude) noexcept {
    const double cap = params_.amplitudeCap;
    if (cap > 0) {
        // The bursts' summed amplitude now: exact, from its value at the last burst.
        const double summed =
            noiseAmplitude_ *
            std::exp(noiseLogDecay_ * static_cast<double>(sample_ - noiseAmplitudeAt_));
        noiseAmplitude_ = summed;
        noiseAmplitudeAt_ = sample_;
        if (!fitUnderCap(summed, amplitude)) return;
        noiseAmplitude_ += amplitude;
    }
    noisePower_ += amplitude * amplitude;
    if (noiseRiseDecay_ > 0) noiseRise_ += amplitude * amplitude; // the burst starts at 0
}

void AggregateModel::freeVoice(int v) noexcept {
    const int last = activeVoices_ - 1;
    if (v != last) {
        for (int k = 0; k < stride_; ++k) {
            const auto d = static_cast<std::size_t>(v * stride_ + k);
            const auto s = static_cast<std::size_t>(last * stride_ + k);
            c1_[d] = c1_[s];
            c2_[d] = c2_[s];
            y1_[d] = y1_[s];
            y2_[d] = y2_[s];
        }
        const auto d = static_cast<std::size_t>(v), s = static_cast<std::size_t>(last);
        deathSample_[d] = deathSample_[s];
        startAmplitude_[d] = startAmplitude_[s];
        logDecay_[d] = logDecay_[s];
        startSample_[d] = startSample_[s];
    }
    for (int k = 0; k < stride_; ++k) {
        const auto s = static_cast<std::size_t>(last * stride_ + k);
        c1_[s] = c2_[s] = y1_[s] = y2_[s] = 0.0f;
    }
    --activeVoices_;
}

void AggregateModel::retireDeadVoices() noexcept {
    for (int v = activeVoices_ - 1; v >= 0; --v)
        if (deathSample_[static_cast<std::size_t>(v)] <= sample_) freeVoice(v);
    nextDeath_ = INT64_MAX;
    for (int v = 0; v < activeVoices_; ++v)
        nextDeath_ = std::min(nextDeath_, deathSample_[static_cast<std::size_t>(v)]);
}

void AggregateModel::process(const float* rateHz, const float* energyScale, float* out,
                             int n) noexcept {
    processWith(
        rateHz, [energyScale](int i) { return energyScale[i]; }, out, n);
}

void AggregateModel::process(const float* rateHz, ScaleFn scaleAt, void* user, float* out,
                             int n) noexcept {
    processWith(
        rateHz, [scaleAt, user](int i) { return scaleAt(user, i); }, out, n);
}

template <typename ScaleAt>
void AggregateModel::processWith(const float* rateHz, ScaleAt&& scaleAt, float* out,
                                 int n) noexcept {
    if (c1_.empty()) return;
    const double dt = 1.0 / sampleRateHz_;
    const double meanBurst = params_.burstEvents;
    // Total rate = primary x (1 + mean burst): cap the primary so the total stays under the cap.
    const double primaryCap = rateCapHz_ / (1.0 + meanBurst);
    // Each pending micro-event fires after its own exponential delay (mean burstMs): the pending
    // pool drains at rate pending / burstMs, so bursts never queue up behind each other.
    const double burstExpected = dt * 1000.0 / params_.burstMs;
    const double burstP = meanBurst / (1.0 + meanBurst); // geometric: P(N = k) = (1-p) p^k
    const double logBurstP = burstP > 0 ? std::log(burstP) : 0.0;
    // The resonators run in runs of samples between the samples where a voice starts or ends
    // (ring()); the events, their random draws and their order are decided sample by sample.
    int runStart = 0;
    for (int i = 0; i < n; ++i) {
        double rate = static_cast<double>(rateHz[i]);
        if (!(rate > 0)) rate = 0; // also NaN
        rate = std::min(rate, primaryCap);
        // Flushes the run before the first change of the voices at this sample.
        auto flush = [&] {
            if (runStart < i) ring(out + runStart, i - runStart);
            runStart = i;
        };
        if (pendingTrigger_ > 0) {
            flush();
            spawn(pendingTrigger_, false);
            pendingTrigger_ = 0;
        }
        const int count = clock_.advance(rate * dt, random_, kMaxEventsPerSample);
        // The energy scale matters only where an event starts: read (or computed) there only.
        double scale = 0.0;
        if (count > 0) {
            scale = static_cast<double>(scaleAt(i));
            if (!(scale > 0) || !std::isfinite(scale)) scale = 0;
        }
        for (int e = 0; e < count; ++e) {
            flush();
            spawn(scale * random_.powerLaw(params_.gamma, params_.energyMin, params_.energyMax),
                  false);
            if (burstP > 0) {
                const double extra = std::floor(std::log(random_.uniformOpen0()) / logBurstP);
                burstRemaining_ = std::min(
                    kMaxBurstEvents, burstRemaining_ + static_cast<int>(std::min(extra, 1e4)));
                burstScale_ = scale;
            }
        }
        if (burstRemaining_ > 0) {
            const int b =
                std::min(burstRemaining_, burstClock_.advance(burstExpected * burstRemaining_,
                                                              random_, kMaxEventsPerSample));
            for (int e = 0; e < b; ++e) {
                flush();
                spawn(burstScale_ *
                          random_.powerLaw(params_.gamma, params_.energyMin, params_.energyMax),
                      true);
            }
            burstRemaining_ -= b;
        }
        if (sample_ >= nextDeath_) {
            flush();
            retireDeadVoices();
        }
        ++sample_;
    }
    if (runStart < n) ring(out + runStart, n - runStart);
}

} // namespace underfoot::engine
