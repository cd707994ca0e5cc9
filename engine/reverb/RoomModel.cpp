// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/RoomModel.h"

#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"
#include "engine/dsp/RealFft.h"

#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <stdexcept>

namespace underfoot::engine {

namespace {

/// Vector front end of RealFft (offline only: planning allocates).
class VectorFft {
  public:
    explicit VectorFft(std::size_t n) : n_(n), fft_(static_cast<int>(n)) {}

    std::size_t bins() const { return n_ / 2 + 1; }
    std::vector<std::complex<double>> forward(const std::vector<double>& x) {
        double* time = fft_.time();
        std::fill(time, time + n_, 0.0);
        std::copy(x.begin(), x.begin() + static_cast<long>(std::min(x.size(), n_)), time);
        fft_.forward();
        const fftw_complex* freq = fft_.spectrum();
        std::vector<std::complex<double>> out(bins());
        for (std::size_t k = 0; k < bins(); ++k) out[k] = {freq[k][0], freq[k][1]};
        return out;
    }
    /// Inverse, normalised (forward then inverse is the identity).
    std::vector<double> inverse(const std::vector<std::complex<double>>& spectrum) {
        fftw_complex* freq = fft_.spectrum();
        for (std::size_t k = 0; k < bins(); ++k) {
            freq[k][0] = spectrum[k].real();
            freq[k][1] = spectrum[k].imag();
        }
        fft_.inverse();
        std::vector<double> out(fft_.time(), fft_.time() + n_);
        const double scale = 1.0 / static_cast<double>(n_);
        for (double& v : out) v *= scale;
        return out;
    }

  private:
    std::size_t n_;
    RealFft fft_;
};

// The late tail is split finer than the octave bands: one extra band below 125 Hz and one above
// 8 kHz (same T60 as their neighbour), so that the noise of each octave is normalised on its own
// (see flattenEnvelope). Split band j is centred on 62.5 x 2^j Hz and decays with the T60 of
// octave band clamp(j - 1, 0, 6).
constexpr int kSplitBandCount = kOctaveBandCount + 2;
int octaveOfSplit(int j) {
    return std::clamp(j - 1, 0, kOctaveBandCount - 1);
}

// Complementary crossovers on log2(f / 62.5 Hz): the weights sum to 1 at every frequency. Each
// band is flat over its middle half octave, with cos^2 transitions half an octave wide centred on
// the band edges (fc x sqrt 2).
std::array<double, kSplitBandCount> splitWeights(double frequencyHz) {
    std::array<double, kSplitBandCount> w{};
    const double x = frequencyHz > 0 ? std::log2(frequencyHz / 62.5) : -1e9;
    if (x <= 0) {
        w[0] = 1;
    } else if (x >= kSplitBandCount - 1) {
        w[kSplitBandCount - 1] = 1;
    } else {
        const int i = static_cast<int>(std::floor(x));
        const double u = std::clamp((x - i - 0.25) / 0.5, 0.0, 1.0);
        const double c = std::cos(0.5 * kPi * u);
        w[static_cast<std::size_t>(i)] = c * c;
        w[static_cast<std::size_t>(i + 1)] = 1.0 - c * c;
    }
    return w;
}

double sinc(double x) {
    return std::fabs(x) < 1e-12 ? 1.0 : std::sin(kPi * x) / (kPi * x);
}

// Adds amplitude a at fractional sample position p (16-tap Hann-windowed sinc).
void addFractional(std::vector<double>& y, double p, double a) {
    constexpr int kHalf = 8;
    const auto base = static_cast<long>(std::floor(p));
    const double frac = p - static_cast<double>(base);
    if (frac < 1e-9) {
        if (base >= 0 && base < static_cast<long>(y.size())) y[static_cast<std::size_t>(base)] += a;
        return;
    }
    for (long n = base - kHalf + 1; n <= base + kHalf; ++n) {
        if (n < 0 || n >= static_cast<long>(y.size())) continue;
        const double d = static_cast<double>(n) - p;
        const double window = 0.5 * (1.0 + std::cos(kPi * d / kHalf));
        y[static_cast<std::size_t>(n)] += a * sinc(d) * window;
    }
}

// Divides band-limited noise by its running RMS (centred moving window of `windowS` seconds) and
// restores its mean power: the short-term energy no longer fluctuates, so the decay imposed on it
// is the one measured (Gaussian band noise alone scatters a T30 by +-10 % in the low octaves).
void flattenEnvelope(std::vector<double>& x, std::size_t len, double windowS, double fs) {
    const auto half = static_cast<std::size_t>(std::max(1.0, 0.5 * windowS * fs));
    std::vector<double> prefix(len + 1, 0.0);
    for (std::size_t i = 0; i < len; ++i) prefix[i + 1] = prefix[i] + x[i] * x[i];
    const double meanPower = prefix[len] / static_cast<double>(std::max<std::size_t>(1, len));
    if (!(meanPower > 0)) return;
    std::vector<double> y(len);
    for (std::size_t i = 0; i < len; ++i) {
        const std::size_t a = i > half ? i - half : 0, b = std::min(len, i + half + 1);
        const double power = (prefix[b] - prefix[a]) / static_cast<double>(b - a);
        y[i] = power > 0 ? x[i] * std::sqrt(meanPower / power) : 0.0;
    }
    std::copy(y.begin(), y.end(), x.begin());
}

std::size_t nextPow2(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
}

} // namespace

double RoomSpec::absorption(int band) const {
    const double t60 = t60Seconds[static_cast<std::size_t>(band)];
    return 1.0 - std::exp(-0.161 * volumeM3() / (surfaceM2() * t60));
}

void RoomSpec::validate() const {
    auto fail = [&](const std::string& what) {
        throw std::invalid_argument(fmt::format("room \"{}\": {}", name, what));
    };
    for (double d : {lengthM, widthM, heightM})
        if (!std::isfinite(d) || d < 1.0 || d > 200.0)
            fail(fmt::format("dimension {} m outside [1, 200] m", d));
    for (std::size_t b = 0; b < t60Seconds.size(); ++b) {
        const double t = t60Seconds[b];
        if (!std::isfinite(t) || t < 0.05 || t > 20.0)
            fail(fmt::format("T60 {} s at {} Hz outside [0.05, 20] s", t, kOctaveBandCentersHz[b]));
        // Eyring needs alpha < 1 and the statistical tail needs a diffuse field: T60 above the
        // Eyring minimum with alpha = 0.99.
        if (absorption(static_cast<int>(b)) > 0.95)
            fail(fmt::format("T60 {} s at {} Hz is too short for a {:.0f} m^3 room (absorption "
                             "above 0.95)",
                             t, kOctaveBandCentersHz[b], volumeM3()));
    }
    auto inside = [&](const Point3& p, const char* what, double margin) {
        if (!(p.x > margin && p.x < lengthM - margin && p.y > margin && p.y < widthM - margin &&
              p.z > 0 && p.z < heightM - margin))
            fail(fmt::format("{} position ({}, {}, {}) m is not inside the room", what, p.x, p.y,
                             p.z));
    };
    inside(sourceM, "source", 0.0);
    inside(listenerM, "listener", earSpacingM);
    if (!(speedOfSoundMps > 300 && speedOfSoundMps < 400))
        fail(fmt::format("speed of sound {} m/s outside [300, 400]", speedOfSoundMps));
}

namespace {
// The built-in rooms, in the order roomPresetNames() lists them.
const std::vector<RoomSpec>& builtInRooms() {
    static const std::vector<RoomSpec> rooms = {
        {.name = "hall",
         .description = "large hall (30 x 20 x 12 m), T_mid 1.8 s",
         .lengthM = 30.0,
         .widthM = 20.0,
         .heightM = 12.0,
         .t60Seconds = {2.00, 1.90, 1.84, 1.76, 1.62, 1.42, 1.15},
         .sourceM = {11.0, 8.5, 0.01},
         .listenerM = {11.2, 8.5, 1.6}},
        {.name = "small_room",
         .description = "small furnished room (4 x 3.5 x 2.5 m), T_mid 0.4 s",
         .lengthM = 4.0,
         .widthM = 3.5,
         .heightM = 2.5,
         .t60Seconds = {0.50, 0.45, 0.40, 0.40, 0.38, 0.35, 0.30},
         .sourceM = {1.5, 1.6, 0.01},
         .listenerM = {1.7, 1.6, 1.6}},
        // A medium room with a wooden floor and wooden panelling: panels absorb the low
        // frequencies a little (membrane absorption), furniture and air the highs.
        {.name = "wooden_room",
         .description = "medium room (7 x 5 x 3 m) with a wooden floor, T_mid 0.8 s",
         .lengthM = 7.0,
         .widthM = 5.0,
         .heightM = 3.0,
         .t60Seconds = {0.70, 0.76, 0.80, 0.80, 0.76, 0.70, 0.60},
         .sourceM = {2.6, 2.2, 0.01},
         .listenerM = {2.8, 2.2, 1.6}},
    };
    return rooms;
}
} // namespace

std::vector<std::string> roomPresetNames() {
    std::vector<std::string> names;
    for (const RoomSpec& r : builtInRooms()) names.push_back(r.name);
    return names;
}

RoomSpec roomPreset(const std::string& name) {
    for (const RoomSpec& r : builtInRooms())
        if (r.name == name) return r;
    std::string names;
    for (const auto& n : roomPresetNames()) names += (names.empty() ? "" : ", ") + n;
    throw std::invalid_argument(
        fmt::format("unknown room \"{}\"; expected one of: {}", name, names));
}

AudioBuffer generateRoomImpulseResponse(const RoomSpec& room, const RoomIrOptions& o) {
    room.validate();
    if (!(o.sampleRateHz >= 8000 && o.sampleRateHz <= 384000))
        throw std::invalid_argument(
            fmt::format("room IR: sample rate {} Hz outside [8000, 384000]", o.sampleRateHz));
    if (o.channels != 1 && o.channels != 2)
        throw std::invalid_argument(
            fmt::format("room IR: {} channels; expected 1 or 2", o.channels));
    if (!std::isfinite(o.lengthSeconds) || o.lengthSeconds < 0 || o.lengthSeconds > 60)
        throw std::invalid_argument(
            fmt::format("room IR: length {} s outside [0 (auto), 60]", o.lengthSeconds));
    const double fs = o.sampleRateHz, c = room.speedOfSoundMps;
    const double maxT60 = *std::max_element(room.t60Seconds.begin(), room.t60Seconds.end());
    const double seconds = o.lengthSeconds > 0 ? o.lengthSeconds : 1.1 * maxT60;
    const auto len = static_cast<std::size_t>(std::llround(seconds * fs));
    const std::size_t nfft = nextPow2(len + 32);
    VectorFft fft(nfft);

    std::array<double, kOctaveBandCount> beta{};
    for (int b = 0; b < kOctaveBandCount; ++b)
        beta[static_cast<std::size_t>(b)] = std::sqrt(1.0 - room.absorption(b));
    std::vector<std::array<double, kSplitBandCount>> split(fft.bins());
    std::vector<std::array<double, kOctaveBandCount>> weights(fft.bins()); // octave bands
    for (std::size_t k = 0; k < fft.bins(); ++k) {
        split[k] = splitWeights(static_cast<double>(k) * fs / static_cast<double>(nfft));
        weights[k] = {};
        for (int j = 0; j < kSplitBandCount; ++j)
            weights[k][static_cast<std::size_t>(octaveOfSplit(j))] +=
                split[k][static_cast<std::size_t>(j)];
    }

    const Point3 s = room.sourceM, l = room.listenerM;
    auto receiver = [&](int ch) {
        const double earOffset = o.channels == 1 ? 0.0 : (ch == 0 ? -0.5 : 0.5) * room.earSpacingM;
        return Point3{l.x, l.y + earOffset, l.z};
    };
    // Time 0 = the first arrival of the direct sound at either ear.
    double d0 = 1e300;
    for (int ch = 0; ch < o.channels; ++ch) {
        const Point3 r = receiver(ch);
        d0 = std::min(d0, std::sqrt((s.x - r.x) * (s.x - r.x) + (s.y - r.y) * (s.y - r.y) +
                                    (s.z - r.z) * (s.z - r.z)));
    }
    const double tMix = room.mixingTimeSeconds(), tCut = 1.5 * tMix;
    auto earlyWeight = [&](double t) {
        if (t <= tMix) return 1.0;
        if (t >= tCut) return 0.0;
        const double cs = std::cos(0.5 * kPi * (t - tMix) / (tCut - tMix));
        return cs * cs;
    };
    const double sigma0 = std::sqrt(4.0 * kPi * c / (room.volumeM3() * fs));

    AudioBuffer out;
    out.sampleRateHz = fs;
    out.channels = o.channels;
    out.samples.assign(len * static_cast<std::size_t>(o.channels), 0.0f);
    std::vector<std::vector<double>> channelData;
    for (int ch = 0; ch < o.channels; ++ch) {
        const Point3 r = receiver(ch);
        // Early reflections: one sparse train per band.
        std::vector<std::vector<double>> early(kOctaveBandCount, std::vector<double>(nfft, 0.0));
        const double reach = c * (tCut + d0 / c);
        const int nx = static_cast<int>(std::ceil(reach / (2 * room.lengthM))) + 1;
        const int ny = static_cast<int>(std::ceil(reach / (2 * room.widthM))) + 1;
        const int nz = static_cast<int>(std::ceil(reach / (2 * room.heightM))) + 1;
        for (int ix = -nx; ix <= nx; ++ix)
            for (int iy = -ny; iy <= ny; ++iy)
                for (int iz = -nz; iz <= nz; ++iz)
                    for (int u = 0; u < 2; ++u)
                        for (int v = 0; v < 2; ++v)
                            for (int w = 0; w < 2; ++w) {
                                const double x = (1 - 2 * u) * s.x + 2 * ix * room.lengthM;
                                const double y = (1 - 2 * v) * s.y + 2 * iy * room.widthM;
                                const double z = (1 - 2 * w) * s.z + 2 * iz * room.heightM;
                                const double d =
                                    std::sqrt((x - r.x) * (x - r.x) + (y - r.y) * (y - r.y) +
                                              (z - r.z) * (z - r.z));
                                const double t = (d - d0) / c;
                                if (t >= tCut) continue;
                                const int order = std::abs(ix - u) + std::abs(ix) +
                                                  std::abs(iy - v) + std::abs(iy) +
                                                  std::abs(iz - w) + std::abs(iz);
                                const double g = earlyWeight(std::max(0.0, t)) / d;
                                for (int b = 0; b < kOctaveBandCount; ++b)
                                    addFractional(
                                        early[static_cast<std::size_t>(b)], std::max(0.0, t) * fs,
                                        g * std::pow(beta[static_cast<std::size_t>(b)], order));
                            }
        std::vector<std::complex<double>> earlySpectrum(fft.bins());
        for (int b = 0; b < kOctaveBandCount; ++b) {
            const auto spectrum = fft.forward(early[static_cast<std::size_t>(b)]);
            for (std::size_t k = 0; k < fft.bins(); ++k)
                earlySpectrum[k] += weights[k][static_cast<std::size_t>(b)] * spectrum[k];
        }
        std::vector<double> y = fft.inverse(earlySpectrum);
        y.resize(len);
        // Late tail: band-split seeded noise with a decay per band.
        Random random(Random::deriveSeed(o.seed, static_cast<std::uint64_t>(ch)));
        std::vector<double> noise(nfft, 0.0);
        for (std::size_t i = 0; i < len; ++i) noise[i] = random.gaussian();
        const auto noiseSpectrum = fft.forward(noise);
        for (int j = 0; j < kSplitBandCount; ++j) {
            std::vector<std::complex<double>> band(fft.bins());
            for (std::size_t k = 0; k < fft.bins(); ++k)
                band[k] = split[k][static_cast<std::size_t>(j)] * noiseSpectrum[k];
            auto bandTime = fft.inverse(band);
            flattenEnvelope(bandTime, len, std::max(0.02, 32.0 / (62.5 * std::exp2(j))), fs);
            const double rate =
                6.907755 / room.t60Seconds[static_cast<std::size_t>(octaveOfSplit(j))];
            for (std::size_t i = 0; i < len; ++i) {
                const double t = static_cast<double>(i) / fs;
                if (t <= tMix) continue;
                const double late = 1.0 - earlyWeight(t);
                y[i] += late * sigma0 * std::exp(-rate * (t + d0 / c)) * bandTime[i];
            }
        }
        channelData.push_back(std::move(y));
    }
    // Direct sound at 0.5; a 20 ms cos^2 fade-out at the very end.
    const double scale = 0.5 * d0;
    const std::size_t fade = std::min(len, static_cast<std::size_t>(0.02 * fs));
    double peak = 0;
    for (auto& y : channelData)
        for (std::size_t i = 0; i < len; ++i) {
            double v = y[i] * scale;
            if (i >= len - fade) {
                const double cs = std::cos(0.5 * kPi * static_cast<double>(i - (len - fade)) /
                                           static_cast<double>(fade));
                v *= cs * cs;
            }
            y[i] = v;
            peak = std::max(peak, std::fabs(v));
        }
    const double limit = peak > 0.99 ? 0.99 / peak : 1.0; // never clip a PCM file
    for (int ch = 0; ch < o.channels; ++ch)
        for (std::size_t i = 0; i < len; ++i)
            out.samples[i * static_cast<std::size_t>(o.channels) + static_cast<std::size_t>(ch)] =
                static_cast<float>(channelData[static_cast<std::size_t>(ch)][i] * limit);
    return out;
}

std::vector<double> energyDecayCurveDb(const std::vector<float>& ir) {
    std::vector<double> edc(ir.size());
    double sum = 0;
    for (std::size_t i = ir.size(); i-- > 0;) {
        sum += static_cast<double>(ir[i]) * ir[i];
        edc[i] = sum;
    }
    const double total = ir.empty() ? 0.0 : edc[0];
    for (double& e : edc) e = total > 0 && e > 0 ? 10.0 * std::log10(e / total) : -400.0;
    return edc;
}

double schroederT60Seconds(const std::vector<float>& ir, double sampleRateHz, double fromDb,
                           double toDb) {
    const auto edc = energyDecayCurveDb(ir);
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    std::size_t n = 0;
    bool reached = false;
    for (std::size_t i = 0; i < edc.size(); ++i) {
        if (edc[i] > fromDb) continue;
        if (edc[i] < toDb) {
            reached = true;
            break;
        }
        const double t = static_cast<double>(i) / sampleRateHz;
        sx += t, sy += edc[i], sxx += t * t, sxy += t * edc[i];
        ++n;
    }
    if (!reached || n < 2)
        throw std::invalid_argument(fmt::format(
            "Schroeder T60: the decay curve does not reach {} dB (IR too short or too noisy)",
            toDb));
    const double nn = static_cast<double>(n);
    const double slope = (nn * sxy - sx * sy) / (nn * sxx - sx * sx); // dB per second
    return -60.0 / slope;
}

} // namespace underfoot::engine
