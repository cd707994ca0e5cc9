// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/AudioFeatures.h"

#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/RealFft.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace underfoot::engine {
namespace {
std::vector<float> monoMix(const AudioBuffer& a) {
    std::vector<float> m(a.frames());
    for (std::size_t f = 0; f < m.size(); ++f) {
        double s = 0;
        for (int c = 0; c < a.channels; ++c) s += a.at(f, c);
        m[f] = static_cast<float>(s / std::max(1, a.channels));
    }
    return m;
}

// Power spectra of Hann-windowed frames (FFTW r2c; plans made once per call).
std::vector<std::vector<double>> powerFrames(const std::vector<float>& x, int n, int hop) {
    std::vector<std::vector<double>> frames;
    if (x.size() < static_cast<std::size_t>(n)) return frames;
    RealFft fft(n);
    double* in = fft.time();
    const fftw_complex* out = fft.spectrum();
    std::vector<double> window(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        window[static_cast<std::size_t>(i)] = 0.5 - 0.5 * std::cos(kTwoPi * i / n);
    for (std::size_t start = 0; start + static_cast<std::size_t>(n) <= x.size();
         start += static_cast<std::size_t>(hop)) {
        for (int i = 0; i < n; ++i)
            in[i] = x[start + static_cast<std::size_t>(i)] * window[static_cast<std::size_t>(i)];
        fft.forward();
        std::vector<double> p(static_cast<std::size_t>(n / 2 + 1));
        for (int k = 0; k <= n / 2; ++k)
            p[static_cast<std::size_t>(k)] = out[k][0] * out[k][0] + out[k][1] * out[k][1];
        frames.push_back(std::move(p));
    }
    return frames;
}
} // namespace

AudioFeatures computeFeatures(const AudioBuffer& audio) {
    AudioFeatures f;
    const auto x = monoMix(audio);
    if (x.empty()) return f;
    const double fs = audio.sampleRateHz;
    double peak = 0;
    for (float v : audio.samples) peak = std::max(peak, double(std::fabs(v)));
    f.peakDb = peak > 0 ? 20 * std::log10(peak) : -999;
    double squares = 0;
    for (float v : x) squares += double(v) * double(v);
    if (squares > 0) f.leqDb = 10 * std::log10(squares / double(x.size()));
    // 10 ms frame energies.
    const auto frameLen = static_cast<std::size_t>(std::max(1.0, 0.01 * fs));
    std::vector<double> energy;
    for (std::size_t s = 0; s + frameLen <= x.size(); s += frameLen) {
        double e = 0;
        for (std::size_t i = s; i < s + frameLen; ++i) e += double(x[i]) * x[i];
        energy.push_back(e / double(frameLen));
    }
    if (energy.empty()) return f;
    const double maxE = *std::max_element(energy.begin(), energy.end());
    if (!(maxE > 0)) return f;
    double activeE = 0;
    int active = 0;
    for (double e : energy)
        if (e > maxE * 1e-4) {
            activeE += e;
            ++active;
        }
    f.activeShare = double(active) / double(energy.size());
    f.rmsDb = 10 * std::log10(activeE / active);
    f.crestDb = f.peakDb - f.rmsDb;
    // Decay: from each local energy maximum, frames until -20 dB.
    std::vector<double> decays;
    for (std::size_t i = 1; i + 1 < energy.size(); ++i) {
        if (energy[i] > maxE * 1e-3 && energy[i] >= energy[i - 1] && energy[i] > energy[i + 1]) {
            std::size_t j = i;
            while (j < energy.size() && energy[j] > energy[i] * 0.01) ++j;
            decays.push_back(double(j - i) * 10.0);
        }
    }
    if (!decays.empty()) {
        std::nth_element(decays.begin(), decays.begin() + decays.size() / 2, decays.end());
        f.decayMsMedian = decays[decays.size() / 2];
    }
    // Spectral descriptors and onsets from 1024-point frames.
    const int n = 1024, hop = static_cast<int>(std::max(1.0, 0.01 * fs));
    const auto frames = powerFrames(x, n, hop);
    std::vector<double> total(static_cast<std::size_t>(n / 2 + 1), 0.0);
    std::vector<double> flux;
    std::vector<double> prev;
    for (const auto& p : frames) {
        const double e = std::accumulate(p.begin(), p.end(), 0.0);
        if (e > 0)
            for (std::size_t k = 0; k < p.size(); ++k) total[k] += p[k];
        if (!prev.empty()) {
            double fl = 0;
            for (std::size_t k = 0; k < p.size(); ++k) {
                const double d = std::sqrt(p[k]) - std::sqrt(prev[k]);
                if (d > 0) fl += d;
            }
            flux.push_back(fl);
        }
        prev = p;
    }
    const double sum = std::accumulate(total.begin(), total.end(), 0.0);
    if (sum > 0) {
        double c = 0, acc = 0;
        bool rolled = false;
        for (std::size_t k = 0; k < total.size(); ++k) {
            const double hz = double(k) * fs / n;
            c += hz * total[k];
            acc += total[k];
            if (!rolled && acc >= 0.85 * sum) {
                f.rolloff85Hz = hz;
                rolled = true;
            }
            if (hz < 500) f.lowShare += total[k] / sum;
            if (hz > 4000) f.highShare += total[k] / sum;
        }
        f.centroidHz = c / sum;
    }
    // Onsets: flux peaks above a moving threshold (median of +-50 ms x 1.5 + small floor).
    int onsets = 0;
    if (!flux.empty()) {
        const double fluxMax = *std::max_element(flux.begin(), flux.end());
        for (std::size_t i = 1; i + 1 < flux.size(); ++i) {
            const std::size_t lo = i >= 5 ? i - 5 : 0, hi = std::min(flux.size(), i + 6);
            std::vector<double> w(flux.begin() + static_cast<long>(lo),
                                  flux.begin() + static_cast<long>(hi));
            std::nth_element(w.begin(), w.begin() + static_cast<long>(w.size() / 2), w.end());
            const double thr = 1.5 * w[w.size() / 2] + 0.02 * fluxMax;
            if (flux[i] > thr && flux[i] >= flux[i - 1] && flux[i] > flux[i + 1]) ++onsets;
        }
    }
    f.eventsPerSecond = onsets / (double(x.size()) / fs);
    return f;
}

std::vector<std::vector<float>> spectrogramDb(const AudioBuffer& audio, int fftSize, int hop) {
    std::vector<std::vector<float>> out;
    for (const auto& p : powerFrames(monoMix(audio), fftSize, hop)) {
        std::vector<float> row(p.size());
        for (std::size_t k = 0; k < p.size(); ++k)
            row[k] = static_cast<float>(10 * std::log10(p[k] + 1e-20));
        out.push_back(std::move(row));
    }
    return out;
}

} // namespace underfoot::engine
