// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/OnsetFeatures.h"

#include "engine/dsp/RealFft.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <stdexcept>

namespace underfoot::realism {
namespace {

constexpr double kWindowsS[3] = {0.030, 0.080, 0.150};

double db(double p) {
    return 10.0 * std::log10(std::max(p, 1e-30));
}

// Power spectrum of x[b, e) (at most n samples), with a 1 ms raised-cosine fade-in and a 5 ms
// fade-out (a Hann window over 30 ms would hide the transient at its start), zero-padded to n.
std::vector<double> windowSpectrum(engine::RealFft& fft, const std::vector<float>& x, std::size_t b,
                                   std::size_t e, double fs) {
    const auto n = static_cast<std::size_t>(fft.size());
    e = std::min({e, x.size(), b + n});
    const std::size_t len = e > b ? e - b : 0;
    const auto fadeIn = std::min(len / 2, static_cast<std::size_t>(0.001 * fs));
    const auto fadeOut = std::min(len / 2, static_cast<std::size_t>(0.005 * fs));
    double* in = fft.time();
    for (std::size_t i = 0; i < n; ++i) {
        double w = i < len ? 1.0 : 0.0;
        if (i < fadeIn)
            w = 0.5 - 0.5 * std::cos(std::numbers::pi * (double(i) + 0.5) / double(fadeIn));
        else if (i < len && i >= len - fadeOut)
            w = 0.5 - 0.5 * std::cos(std::numbers::pi * (double(len - i) - 0.5) / double(fadeOut));
        in[i] = i < len ? double(x[b + i]) * w : 0.0;
    }
    fft.forward();
    const fftw_complex* out = fft.spectrum();
    std::vector<double> p(n / 2 + 1);
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = out[k][0] * out[k][0] + out[k][1] * out[k][1];
    return p;
}

struct SpectralShape {
    double centroidOct = 0, slopeDbPerOct = 0, hiLoDb = 0, flatnessDb = 0;
    double band[4] = {0, 0, 0, 0}; ///< 20-250, 250-1k, 1k-4k, 4k-maxHz re the whole band, dB
};

SpectralShape shape(const std::vector<double>& p, double fs, int n, const AnalysisOptions& o) {
    const double binHz = fs / n;
    const double maxHz = std::min(o.maxHz, 0.5 * fs);
    const double edges[5] = {20, 250, 1000, 4000, 1e9};
    double total = 0, weighted = 0, logSum = 0, hi = 0, lo = 0, band[4] = {0, 0, 0, 0};
    int bins = 0;
    for (std::size_t k = 1; k < p.size(); ++k) {
        const double f = double(k) * binHz;
        if (f < o.minHz || f > maxHz) continue;
        total += p[k];
        weighted += p[k] * f;
        logSum += std::log(std::max(p[k], 1e-30));
        ++bins;
        if (f >= 2000) hi += p[k];
        if (f >= 200 && f < 2000) lo += p[k];
        for (int j = 0; j < 4; ++j)
            if (f >= edges[j] && f < edges[j + 1]) band[j] += p[k];
    }
    if (!(total > 0) || bins == 0)
        throw std::invalid_argument("the step's onset is silent in the analysed band");
    SpectralShape s;
    s.centroidOct = std::log2(weighted / total);
    s.flatnessDb = db(std::exp(logSum / bins) / (total / bins));
    s.hiLoDb = db((hi + 1e-12 * total) / (lo + 1e-12 * total));
    for (int j = 0; j < 4; ++j) s.band[j] = std::max(db(band[j] / total), -60.0);
    // Least-squares slope of the third-octave levels (100 Hz up) against octaves.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (double fc : thirdOctaveCentres(maxHz)) {
        if (fc < 100) continue;
        const double lo3 = fc * std::pow(2.0, -1.0 / 6.0), hi3 = fc * std::pow(2.0, 1.0 / 6.0);
        double e = 0;
        for (std::size_t k = 1; k < p.size(); ++k) {
            const double f = double(k) * binHz;
            if (f >= lo3 && f < hi3) e += p[k];
        }
        const double xo = std::log2(fc / 1000.0);
        const double y = std::max(db(e / total), -100.0);
        sx += xo;
        sy += y;
        sxx += xo * xo;
        sxy += xo * y;
        ++m;
    }
    if (m >= 2) s.slopeDbPerOct = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    return s;
}

} // namespace

const std::vector<OnsetFeatureInfo>& onsetFeatureInfo() {
    static const std::vector<OnsetFeatureInfo> info = {
        {"centroid_30ms", "spectral centroid of the first 30 ms, octaves re 1 Hz", 0.25},
        {"slope_30ms", "third-octave envelope slope of the first 30 ms, dB/octave", 1.0},
        {"hilo_30ms", "energy above 2 kHz over 200 Hz-2 kHz, first 30 ms, dB", 1.5},
        {"flatness_30ms", "spectral flatness of the first 30 ms, dB", 1.5},
        {"centroid_80ms", "spectral centroid of the first 80 ms, octaves re 1 Hz", 0.25},
        {"slope_80ms", "third-octave envelope slope of the first 80 ms, dB/octave", 1.0},
        {"hilo_80ms", "energy above 2 kHz over 200 Hz-2 kHz, first 80 ms, dB", 1.5},
        {"flatness_80ms", "spectral flatness of the first 80 ms, dB", 1.5},
        {"centroid_150ms", "spectral centroid of the first 150 ms, octaves re 1 Hz", 0.25},
        {"slope_150ms", "third-octave envelope slope of the first 150 ms, dB/octave", 1.0},
        {"hilo_150ms", "energy above 2 kHz over 200 Hz-2 kHz, first 150 ms, dB", 1.5},
        {"flatness_150ms", "spectral flatness of the first 150 ms, dB", 1.5},
        {"band_20_250_80ms", "energy 20-250 Hz re the whole band, first 80 ms, dB", 1.5},
        {"band_250_1k_80ms", "energy 250 Hz-1 kHz re the whole band, first 80 ms, dB", 1.5},
        {"band_1k_4k_80ms", "energy 1-4 kHz re the whole band, first 80 ms, dB", 1.5},
        {"band_4k_80ms", "energy 4 kHz-band limit re the whole band, first 80 ms, dB", 1.5},
        {"grains_150ms", "micro-onsets in the first 150 ms, log2(1 + count)", 0.25},
        {"early_30_150", "energy of the first 30 ms re the first 150 ms, dB", 1.0},
        {"fall_20_40ms", "fall of the 1 ms envelope from its peak to 20-40 ms after it, dB", 1.5},
        {"crest_80ms", "crest factor (peak over RMS) of the first 80 ms, dB", 1.0},
    };
    return info;
}

std::vector<double> onsetFeatures(const std::vector<float>& x, double fs, StepSpan span,
                                  const AnalysisOptions& o) {
    if (span.end > x.size() || span.end <= span.begin)
        throw std::invalid_argument(fmt::format("step [{}, {}) is empty or outside the {} samples",
                                                span.begin, span.end, x.size()));
    // 1 ms energy envelope of the step; the attack point is its first frame within 20 dB of
    // the loudest.
    const auto hop = static_cast<std::size_t>(std::max(1.0, std::round(0.001 * fs)));
    std::vector<double> env;
    for (std::size_t s = span.begin; s < span.end; s += hop) {
        double acc = 0;
        for (std::size_t i = s; i < std::min(span.end, s + hop); ++i)
            acc += double(x[i]) * double(x[i]);
        env.push_back(acc / double(hop));
    }
    const auto peakIt = std::max_element(env.begin(), env.end());
    if (!(*peakIt > 0)) throw std::invalid_argument("the step is silent");
    std::size_t attack = 0;
    while (env[attack] < *peakIt * 1e-2) ++attack;
    const std::size_t pre = 2 * hop; // start 2 ms before the attack point
    const std::size_t t0 = span.begin + (attack * hop > pre ? attack * hop - pre : 0);
    const auto at = [&](double seconds) {
        return std::min(span.end, t0 + static_cast<std::size_t>(std::llround(seconds * fs)));
    };

    std::vector<double> f;
    const int n = 1 << static_cast<int>(std::ceil(std::log2(0.150 * fs + 1)));
    engine::RealFft fft(n); // plans under FFTW's planner lock
    SpectralShape s80;      // the 80 ms window's band balance follows the window features
    for (std::size_t w = 0; w < std::size(kWindowsS); ++w) {
        const auto s = shape(windowSpectrum(fft, x, t0, at(kWindowsS[w]), fs), fs, n, o);
        f.insert(f.end(), {s.centroidOct, s.slopeDbPerOct, s.hiLoDb, s.flatnessDb});
        if (w == 1) s80 = s;
    }
    f.insert(f.end(), {s80.band[0], s80.band[1], s80.band[2], s80.band[3]});

    // Temporal fine structure of the first 150 ms.
    const std::size_t e150 = at(0.150), e80 = at(0.080), e30 = at(0.030);
    // micro-onsets: peaks of the differentiated signal's 1 ms energy that rise 6 dB above the
    // previous trough, within 30 dB of the window's loudest (as the grain rate descriptor)
    const int events = countGrainEvents(x, t0, e150, hop);
    f.push_back(std::log2(1.0 + events));
    double eAll = 0, eEarly = 0, pk = 0, sq80 = 0;
    for (std::size_t i = t0; i < e150; ++i) {
        const double v = double(x[i]) * double(x[i]);
        eAll += v;
        if (i < e30) eEarly += v;
        if (i < e80) {
            sq80 += v;
            pk = std::max(pk, std::fabs(double(x[i])));
        }
    }
    f.push_back(db(eEarly / eAll));
    // fall: peak of the 1 ms envelope (within the first 150 ms) to the median 20-40 ms after it
    const std::size_t i0 = (t0 - span.begin) / hop;
    const std::size_t i1 = std::min(env.size(), (e150 - span.begin) / hop + 1);
    std::size_t ip = i0;
    for (std::size_t i = i0; i < i1; ++i)
        if (env[i] > env[ip]) ip = i;
    std::vector<double> later;
    for (std::size_t i = ip + 20; i < std::min(env.size(), ip + 40); ++i) later.push_back(env[i]);
    double fall = 60.0; // the step ends within 20 ms of its peak: as far as the floor
    if (!later.empty()) {
        std::nth_element(later.begin(), later.begin() + long(later.size() / 2), later.end());
        fall = std::min(60.0, db(env[ip]) - db(later[later.size() / 2]));
    }
    f.push_back(fall);
    const double n80 = double(std::max<std::size_t>(e80 - t0, 1));
    f.push_back(20.0 * std::log10(std::max(pk, 1e-15) / std::sqrt(std::max(sq80 / n80, 1e-30))));
    for (double v : f)
        if (!std::isfinite(v)) throw std::invalid_argument("non-finite onset feature");
    return f;
}

std::vector<std::vector<double>> onsetFeaturesOfSteps(const engine::AudioBuffer& audio,
                                                      const AnalysisOptions& o) {
    return forEachStep(audio, o, [&](const std::vector<float>& x, double fs, StepSpan s) {
        return onsetFeatures(x, fs, s, o);
    });
}

} // namespace underfoot::realism
