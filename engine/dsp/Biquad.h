// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Second-order IIR sections and Butterworth designs.
///
/// Coefficients follow R. Bristow-Johnson's "Audio EQ Cookbook" (bilinear transform with
/// frequency pre-warping); Butterworth filters of order N are cascades of N/2 sections whose Q
/// values are 1 / (2 cos(pi (2k+1) / (2N))) (plus one first-order section for odd N).
/// State is double, transposed direct form II (good numerical behaviour at low cutoffs).
#include "engine/dsp/ProcessSpec.h"

#include <array>
#include <vector>

namespace underfoot::engine {

struct BiquadCoefficients {
    double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0; ///< a0 normalised to 1

    static BiquadCoefficients lowpass(double sampleRateHz, double cutoffHz, double q);
    static BiquadCoefficients highpass(double sampleRateHz, double cutoffHz, double q);
    static BiquadCoefficients bandpass(double sampleRateHz, double centreHz,
                                       double q); ///< 0 dB peak
    static BiquadCoefficients peaking(double sampleRateHz, double centreHz, double q,
                                      double gainDb);
    static BiquadCoefficients lowShelf(double sampleRateHz, double cornerHz, double gainDb);
    static BiquadCoefficients highShelf(double sampleRateHz, double cornerHz, double gainDb);
    /// First-order sections (b2 = a2 = 0), bilinear with pre-warping.
    static BiquadCoefficients lowpass1(double sampleRateHz, double cutoffHz);
    static BiquadCoefficients highpass1(double sampleRateHz, double cutoffHz);

    /// Magnitude response at a frequency (for tests and plots).
    double magnitudeAt(double sampleRateHz, double frequencyHz) const;
};

class Biquad {
  public:
    Biquad() = default;
    explicit Biquad(const BiquadCoefficients& c) : c_(c) {}
    void setCoefficients(const BiquadCoefficients& c) noexcept { c_ = c; }
    const BiquadCoefficients& coefficients() const noexcept { return c_; }
    void reset() noexcept { z1_ = z2_ = 0.0; }

    double processSample(double x) noexcept {
        const double y = c_.b0 * x + z1_;
        z1_ = c_.b1 * x - c_.a1 * y + z2_;
        z2_ = c_.b2 * x - c_.a2 * y;
        return y;
    }
    /// Filters n samples in place, then snaps a tiny state to zero (snapTinyState). The snap at
    /// the end of each call makes the output depend on how the signal is cut into calls: code
    /// whose output must not depend on the host's block size calls processSample() and snaps
    /// on a fixed grid (engine/dsp/SleepGrid.h).
    void process(float* data, int n) noexcept {
        for (int i = 0; i < n; ++i) data[i] = static_cast<float>(processSample(data[i]));
        snapTinyState();
    }
    /// Sets a state below 1e-30 to zero (no denormals in the feedback).
    void snapTinyState() noexcept {
        z1_ = snapToZero(z1_);
        z2_ = snapToZero(z2_);
    }

  private:
    BiquadCoefficients c_;
    double z1_ = 0, z2_ = 0;
};

enum class FilterType { Lowpass, Highpass, Bandpass };

/// Butterworth low/high-pass of any order 1..16, or band-pass as a high-pass + low-pass pair.
class Butterworth {
  public:
    Butterworth() = default;
    /// Designs the filter (allocates: call from prepare()). For Bandpass, `cutoffHz` is the low
    /// edge and `upperHz` the high edge; `order` applies to each edge.
    void design(FilterType type, int order, double sampleRateHz, double cutoffHz,
                double upperHz = 0.0);
    void reset() noexcept;
    double processSample(double x) noexcept {
        for (auto& s : sections_) x = s.processSample(x);
        return x;
    }
    void process(float* data, int n) noexcept {
        for (auto& s : sections_) s.process(data, n);
    }
    void snapTinyState() noexcept {
        for (auto& s : sections_) s.snapTinyState();
    }
    double magnitudeAt(double sampleRateHz, double frequencyHz) const;
    int sectionCount() const noexcept { return static_cast<int>(sections_.size()); }

  private:
    void appendSections(FilterType type, int order, double sampleRateHz, double cutoffHz);
    std::vector<Biquad> sections_;
};

} // namespace underfoot::engine
