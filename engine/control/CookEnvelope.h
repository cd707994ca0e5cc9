// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Cook's envelope extraction: a GRF-like control signal from microphone or recorded footstep
/// audio.
///
///     e[n] = (1 - b) |x[n]| + b e[n-1],   b = b_up if |x[n]| > e[n-1], else b_down
///
/// (Cook, PhISM 1997 and "Modeling Bill's gait", AES 22nd Int. Conf. 2002; used as the GRF
/// estimator in Nordahl, Turchet & Serafin, IEEE TVCG 17(9) 2011 §3 and in Turchet et al. 2010.)
/// With several microphones, each channel has its own envelope and the loudest one is the output
/// (TVCG 2011: "among the four footstep sounds detected by the four microphones, we choose the
/// one which is higher in amplitude"), re-chosen at every sample.
///
/// The coefficients are given as 99 % times (engine/dsp/Envelope.h convention,
/// b = exp(ln 0.01 / (t_ms fs / 1000))), so they mean the same thing at every sample rate.
/// Defaults: attack 1 ms, release 100 ms. The papers do not print b_up/b_down, so these are our
/// engineering choice: 1 ms follows a heel strike without smearing its onset (a delay below what
/// listeners notice in a footstep's attack), and a 100 ms release (time constant 21.7 ms) bridges
/// the oscillations of the recorded sound down to ~50 Hz while letting a step (~100-300 ms of
/// sound) decay before the next one. At 48 kHz: b_up = 0.90852, b_down = 0.99904.
#include "engine/control/GrfFile.h"
#include "engine/dsp/Envelope.h"
#include "engine/dsp/ProcessSpec.h"

#include <array>

namespace underfoot::engine {

/// Settings of Cook's envelope extractor.
struct CookEnvelopeSettings {
    double attackMs = 1.0;    ///< 99 % rise time (b_up); 0 = instantaneous
    double releaseMs = 100.0; ///< 99 % fall time (b_down)
    double gain = 1.0;        ///< output units per unit of |x| (e.g. newtons per full scale)
};

/// Real-time extractor over up to kMaxChannels inputs: no allocation at all (fixed arrays).
class CookEnvelope {
  public:
    static constexpr int kMaxChannels = 16;

    /// Sets the rate and the number of input channels (1..kMaxChannels; throws otherwise).
    void prepare(const ProcessSpec& spec, int numChannels);
    /// Validates (throws std::invalid_argument) and applies settings; call off the audio thread.
    void setSettings(const CookEnvelopeSettings& settings);
    const CookEnvelopeSettings& settings() const noexcept { return settings_; }
    void reset() noexcept;

    /// One frame of `numChannels` interleaved samples -> the loudest channel's envelope x gain.
    float processFrame(const float* frame) noexcept;
    /// Planar blocks: inputs[c][i] for c < numChannels; out may alias none of the inputs.
    void process(const float* const* inputs, float* out, int n) noexcept;
    /// The channel whose envelope was the output at the last sample.
    int loudestChannel() const noexcept { return loudest_; }
    int numChannels() const noexcept { return numChannels_; }
    double upCoefficient() const noexcept { return followers_[0].attackCoefficient(); }
    double downCoefficient() const noexcept { return followers_[0].releaseCoefficient(); }

  private:
    void applyCoefficients() noexcept;
    CookEnvelopeSettings settings_{};
    double sampleRateHz_ = 48000.0;
    int numChannels_ = 1;
    int loudest_ = 0;
    std::array<EnvelopeFollower, kMaxChannels> followers_{};
};

/// Offline: the envelope of a recorded footstep (loudest channel), scaled so that its peak is
/// `peakNewtons`; one channel named "grf" at the buffer's rate. Throws FileError when silent.
GrfSignal grfFromFootstep(const AudioBuffer& recording, double peakNewtons,
                          const CookEnvelopeSettings& settings = {});

/// Offline: reads a recorded footstep (WAV/FLAC/OGG), resamples it to targetRateHz and returns
/// its scaled envelope (see grfFromFootstep). Throws FileError.
GrfSignal grfFromFootstepFile(const std::string& path, double peakNewtons, double targetRateHz,
                              const CookEnvelopeSettings& settings = {});

} // namespace underfoot::engine
