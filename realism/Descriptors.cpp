// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Descriptors.h"

#include "engine/dsp/Random.h"
#include "engine/dsp/RealFft.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace underfoot::realism {
namespace {

constexpr int kFft = 1024;
constexpr int kHop = 256;

double db(double p) {
    return 10.0 * std::log10(std::max(p, 1e-30));
}

// Mean power spectrum (Hann, kFft points, kHop hop) of the frames of [b, e) whose energy is
// within 40 dB of the loudest frame; a step shorter than one frame is zero-padded.
std::vector<double> stepSpectrum(const std::vector<float>& x, std::size_t b, std::size_t e) {
    const auto n = static_cast<std::size_t>(kFft);
    engine::RealFft fft(kFft); // plans under FFTW's planner lock: callers run on worker threads
    double* in = fft.time();
    const fftw_complex* out = fft.spectrum();
    std::vector<double> window(n);
    for (std::size_t i = 0; i < n; ++i)
        window[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * double(i) / double(n));
    std::vector<std::vector<double>> frames;
    std::vector<double> energy;
    for (std::size_t s = b; s < e; s += static_cast<std::size_t>(kHop)) {
        for (std::size_t i = 0; i < n; ++i)
            in[i] = (s + i < e ? double(x[s + i]) : 0.0) * window[i];
        fft.forward();
        std::vector<double> p(n / 2 + 1);
        double sum = 0;
        for (std::size_t k = 0; k <= n / 2; ++k) {
            p[k] = out[k][0] * out[k][0] + out[k][1] * out[k][1];
            sum += p[k];
        }
        frames.push_back(std::move(p));
        energy.push_back(sum);
        if (s + n >= e) break;
    }
    std::vector<double> mean(n / 2 + 1, 0.0);
    if (frames.empty()) return mean;
    const double maxE = *std::max_element(energy.begin(), energy.end());
    int used = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
        if (energy[f] < maxE * 1e-4) continue;
        for (std::size_t k = 0; k < mean.size(); ++k) mean[k] += frames[f][k];
        ++used;
    }
    for (double& v : mean) v /= std::max(used, 1);
    return mean;
}

// Energy envelope: mean square over `win` samples every `hop` samples.
std::vector<double> envelope(const std::vector<float>& x, std::size_t b, std::size_t e,
                             std::size_t win, std::size_t hop) {
    std::vector<double> env;
    for (std::size_t s = b; s < e; s += hop) {
        double acc = 0;
        const std::size_t end = std::min(e, s + win);
        for (std::size_t i = s; i < end; ++i) acc += double(x[i]) * double(x[i]);
        env.push_back(acc / double(win));
    }
    return env;
}

const DescriptorInfo kInfo[kDescriptorCount] = {
    {"centroid", "spectral centroid", "Hz", true, 0.5},
    {"rolloff85", "85 % spectral roll-off", "Hz", true, 0.5},
    {"flatness", "spectral flatness", "dB", false, 3.0},
    {"band_20_250", "energy 20-250 Hz re total", "dB", false, 3.0},
    {"band_250_1k", "energy 250 Hz-1 kHz re total", "dB", false, 3.0},
    {"band_1k_4k", "energy 1-4 kHz re total", "dB", false, 3.0},
    {"band_4k_16k", "energy 4-16 kHz (to the shared band limit) re total", "dB", false, 3.0},
    {"peakiness", "spectral crest (tonality): top bin over mean", "dB", false, 3.0},
    {"grain_rate", "micro-events per second of active step", "1/s", true, 0.5},
    {"crest", "crest factor (peak over RMS)", "dB", false, 3.0},
    {"decay20", "decay from the peak to -20 dB", "s", true, 0.5},
    {"attack", "rise from -30 dB to the peak", "s", true, 0.5},
    {"active", "time within 30 dB of the peak", "s", true, 0.5},
    {"temporal_centroid", "energy centroid after the onset", "s", true, 0.5},
};

} // namespace

const DescriptorInfo& descriptorInfo(int d) {
    if (d < 0 || d >= kDescriptorCount)
        throw std::out_of_range(fmt::format("descriptor index {} out of range", d));
    return kInfo[d];
}

std::vector<double> thirdOctaveCentres(double maxHz) {
    std::vector<double> c;
    for (int k = -13;; ++k) { // 1000 * 2^(-13/3) = 49.6 Hz
        const double fc = 1000.0 * std::pow(2.0, k / 3.0);
        if (fc * std::pow(2.0, 1.0 / 6.0) > maxHz) break;
        c.push_back(fc);
    }
    return c;
}

std::vector<float> analysisSignal(const engine::AudioBuffer& audio, const AnalysisOptions& o) {
    engine::AudioBuffer mono;
    mono.sampleRateHz = audio.sampleRateHz;
    mono.channels = 1;
    mono.samples.resize(audio.frames());
    for (std::size_t f = 0; f < audio.frames(); ++f) {
        double s = 0;
        for (int c = 0; c < audio.channels; ++c) s += audio.at(f, c);
        mono.samples[f] = static_cast<float>(s / std::max(1, audio.channels));
    }
    if (std::fabs(audio.sampleRateHz - o.analysisRateHz) > 1e-6)
        mono = engine::resample(mono, o.analysisRateHz);
    addNoiseFloor(mono.samples, o.analysisRateHz, o);
    return mono.samples;
}

double addNoiseFloor(std::vector<float>& x, double fs, const AnalysisOptions& o) {
    if (!(o.noiseFloorDb > 0) || x.empty()) return 0.0;
    const auto hop = static_cast<std::size_t>(std::max(1.0, std::round(0.001 * fs)));
    const auto env = envelope(x, 0, x.size(), 2 * hop, hop); // mean square of 2 ms, 1 ms apart
    const double loudest = *std::max_element(env.begin(), env.end());
    if (!(loudest > 0)) return 0.0;
    const double rms = std::sqrt(loudest) * std::pow(10.0, -o.noiseFloorDb / 20.0);
    engine::Random noise(o.noiseSeed);
    for (float& v : x) v = static_cast<float>(double(v) + rms * noise.gaussian());
    return rms;
}

std::vector<StepSpan> segmentSteps(const std::vector<float>& x, double fs,
                                   const AnalysisOptions& o) {
    std::vector<StepSpan> steps;
    const auto hop = static_cast<std::size_t>(std::max(1.0, std::round(0.005 * fs)));
    const auto env = envelope(x, 0, x.size(), hop, hop);
    if (env.empty()) return steps;
    const double peak = *std::max_element(env.begin(), env.end());
    if (!(peak > 0)) return steps;
    const double threshold = peak * std::pow(10.0, -o.stepThresholdDb / 10.0);
    // An onset: the envelope is within stepThresholdDb of the file's peak and has risen 10 dB
    // above its lowest value of the previous 50 ms (so a step is found even while the previous
    // one still rings), at least minStepGapS after the previous onset.
    const auto gap = static_cast<std::size_t>(o.minStepGapS * fs / double(hop));
    const std::size_t look = 10;
    std::vector<std::size_t> onsets;
    for (std::size_t i = 0; i < env.size(); ++i) {
        if (env[i] < threshold || (!onsets.empty() && i - onsets.back() < gap)) continue;
        double low = i == 0 ? 0.0 : env[i - 1];
        for (std::size_t k = i > look ? i - look : 0; k < i; ++k) low = std::min(low, env[k]);
        if (i == 0 || env[i] >= 10.0 * low) onsets.push_back(i);
    }
    const auto maxLen = static_cast<std::size_t>(o.maxStepS * fs);
    for (std::size_t k = 0; k < onsets.size(); ++k) {
        StepSpan s;
        const std::size_t pre = static_cast<std::size_t>(0.005 * fs);
        s.begin = onsets[k] * hop > pre ? onsets[k] * hop - pre : 0;
        std::size_t end = std::min(x.size(), s.begin + maxLen);
        if (k + 1 < onsets.size()) end = std::min(end, onsets[k + 1] * hop);
        s.end = end;
        if (s.end > s.begin + static_cast<std::size_t>(0.01 * fs)) steps.push_back(s);
    }
    return steps;
}

int countGrainEvents(const std::vector<float>& x, std::size_t from, std::size_t to,
                     std::size_t hop) {
    std::vector<double> g; // energy of the first difference per frame of `hop` samples
    for (std::size_t s = from; s < to; s += hop) {
        double acc = 0;
        for (std::size_t i = std::max(s, std::size_t{1}); i < std::min(to, s + hop); ++i) {
            const double dx = double(x[i]) - double(x[i - 1]);
            acc += dx * dx;
        }
        g.push_back(acc);
    }
    int events = 0;
    if (g.empty()) return events;
    const double gPeak = *std::max_element(g.begin(), g.end());
    double trough = g[0]; // lowest envelope value since the last counted event
    for (std::size_t i = 1; i + 1 < g.size(); ++i) {
        trough = std::min(trough, g[i]);
        const bool isPeak = g[i] >= g[i - 1] && g[i] > g[i + 1];
        if (isPeak && g[i] >= gPeak * 1e-3 && g[i] >= 4.0 * trough) {
            ++events;
            trough = g[i];
        }
    }
    return events;
}

StepDescriptors describeStep(const std::vector<float>& x, double fs, StepSpan span,
                             const AnalysisOptions& o) {
    if (span.end > x.size() || span.end <= span.begin)
        throw std::invalid_argument(fmt::format("step [{}, {}) is empty or outside the {} samples",
                                                span.begin, span.end, x.size()));
    StepDescriptors d;
    // ---- spectrum ----
    const auto p = stepSpectrum(x, span.begin, span.end);
    const double binHz = fs / kFft;
    const double maxHz = std::min(o.maxHz, 0.5 * fs);
    double total = 0, weighted = 0, logSum = 0;
    int bins = 0;
    double band[4] = {0, 0, 0, 0};
    const double edges[5] = {20, 250, 1000, 4000, 16000};
    double top = 0;
    for (std::size_t k = 1; k < p.size(); ++k) {
        const double f = double(k) * binHz;
        if (f < o.minHz || f > maxHz) continue;
        total += p[k];
        weighted += p[k] * f;
        logSum += std::log(std::max(p[k], 1e-30));
        ++bins;
        top = std::max(top, p[k]);
        for (int b = 0; b < 4; ++b)
            if (f >= edges[b] && f < edges[b + 1]) band[b] += p[k];
    }
    if (!(total > 0) || bins == 0)
        throw std::invalid_argument("the step is silent in the analysed band");
    auto& v = d.value;
    v[kCentroid] = weighted / total;
    double acc = 0;
    v[kRolloff] = maxHz;
    for (std::size_t k = 1; k < p.size(); ++k) {
        const double f = double(k) * binHz;
        if (f < o.minHz || f > maxHz) continue;
        acc += p[k];
        if (acc >= 0.85 * total) {
            v[kRolloff] = f;
            break;
        }
    }
    const double mean = total / bins;
    v[kFlatness] = db(std::exp(logSum / bins) / mean);
    v[kBandLow] = db(band[0] / total);
    v[kBandLowMid] = db(band[1] / total);
    v[kBandMid] = db(band[2] / total);
    v[kBandHigh] = db(band[3] / total);
    v[kPeakiness] = db(top / mean);
    for (double fc : thirdOctaveCentres(maxHz)) {
        const double lo = fc * std::pow(2.0, -1.0 / 6.0), hi = fc * std::pow(2.0, 1.0 / 6.0);
        double e = 0;
        for (std::size_t k = 1; k < p.size(); ++k) {
            const double f = double(k) * binHz;
            if (f >= lo && f < hi) e += p[k];
        }
        d.thirdOctaveDb.push_back(std::max(db(e / total), -100.0));
    }
    d.spectrumDb.resize(p.size());
    for (std::size_t k = 0; k < p.size(); ++k) d.spectrumDb[k] = db(p[k] / mean);

    // ---- temporal envelope (1 ms hop, 2 ms window) ----
    const auto hop = static_cast<std::size_t>(std::max(1.0, std::round(0.001 * fs)));
    const auto env = envelope(x, span.begin, span.end, 2 * hop, hop);
    const auto peakIt = std::max_element(env.begin(), env.end());
    const double peakE = *peakIt;
    if (!(peakE > 0)) throw std::invalid_argument("the step is silent");
    const auto ip = static_cast<std::size_t>(peakIt - env.begin());
    const double dt = double(hop) / fs;
    const double e30 = peakE * 1e-3, e20 = peakE * 1e-2;
    std::size_t first = ip, last = ip;
    for (std::size_t i = 0; i < env.size(); ++i)
        if (env[i] >= e30) {
            first = std::min(first, i);
            last = std::max(last, i);
        }
    std::size_t i20 = ip;
    while (i20 < env.size() && env[i20] > e20) ++i20;
    v[kDecay20] = std::max(double(i20 - ip), 0.5) * dt;
    v[kAttack] = std::max(double(ip - first), 0.5) * dt;
    v[kActive] = double(last - first + 1) * dt;
    double eSum = 0, tSum = 0;
    for (std::size_t i = first; i <= last; ++i) {
        eSum += env[i];
        tSum += env[i] * double(i - first) * dt;
    }
    v[kTemporalCentroid] = std::max(tSum / eSum, 0.5 * dt);

    // crest factor over the active part
    const std::size_t a0 = span.begin + first * hop;
    const std::size_t a1 = std::min(span.end, span.begin + (last + 1) * hop + hop);
    double sq = 0, pk = 0;
    for (std::size_t i = a0; i < a1; ++i) {
        sq += double(x[i]) * double(x[i]);
        pk = std::max(pk, std::fabs(double(x[i])));
    }
    v[kCrest] = 20.0 * std::log10(pk / std::sqrt(sq / double(a1 - a0)));

    // ---- grain events: peaks of the differentiated signal's 1 ms envelope that rise 6 dB
    // above the previous trough, within 30 dB of the step's peak (clicks, grains, bubbles) ----
    const int events = countGrainEvents(x, a0, a1, hop);
    v[kGrainRate] = std::max(double(events), 0.5) / (double(a1 - a0) / fs);
    for (double val : v)
        if (!std::isfinite(val)) throw std::invalid_argument("non-finite descriptor");
    return d;
}

std::vector<StepDescriptors> describeSteps(const engine::AudioBuffer& audio,
                                           const AnalysisOptions& o) {
    return forEachStep(audio, o, [&](const std::vector<float>& x, double fs, StepSpan s) {
        return describeStep(x, fs, s, o);
    });
}

} // namespace underfoot::realism
