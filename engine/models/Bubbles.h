// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Bubbles in water, after K. van den Doel, "Physically Based Models for Liquid Sounds",
/// ACM Trans. Applied Perception 2(4), 2005 (after Minnaert 1933 and Longuet-Higgins 1992).
///
/// One bubble of radius r (metres) radiates  p(t) = a sin(2 pi integral_0^t f(s) ds) exp(-d t)
/// with  f0 = 3 / r Hz  (Minnaert's resonance in water, rounded as van den Doel does),
/// damping  d = 0.13 / r + 0.0072 r^(-3/2)  (1/s; viscous + thermal/radiation terms),
/// a rising pitch  f(t) = f0 (1 + xi d t)  (xi ~ 0.1: the bubble rises towards the surface) and
/// amplitude  a = depth x (r / 1 mm)^(3/2)  (larger bubbles are louder; `depth` in (0, 1] is the
/// excitation/depth factor of van den Doel's model, drawn per bubble in [depthMin, 1]).
///
/// Discretisation: a complex phasor z[n+1] = z[n] w[n] exp(-d/fs) whose per-sample rotation
/// w[n] = exp(i 2 pi f0 T (1 + xi d (n + 1/2) T)) is itself advanced by a constant rotation:
/// the phase is the exact integral of the linear chirp at every sample, with no sin() per sample.
/// A bubble ends when it has decayed 80 dB below the loudest bubble of the stream, or when its
/// rising pitch reaches 0.45 fs (explicit: it would otherwise alias).
///
/// A stream (BubbleStream) is a population: Poisson arrival times with a per-sample rate (the same
/// exact time-rescaling clock as the aggregate model), radii from p(r) ~ r^beta on
/// [radiusMin, radiusMax], a voice pool allocated in prepare().
#include "engine/dsp/Random.h"
#include "engine/models/Aggregate.h"

#include <cstdint>
#include <vector>

namespace underfoot::engine {

/// Formulas of one bubble (van den Doel 2005).
struct BubblePhysics {
    /// Resonance frequency f0 = 3 / r (Hz, r in metres).
    static double frequencyHz(double radiusM) noexcept { return 3.0 / radiusM; }
    /// Damping d = 0.13 / r + 0.0072 r^(-3/2) (1/s).
    static double dampingPerSecond(double radiusM) noexcept {
        return 0.13 / radiusM + 0.0072 * std::pow(radiusM, -1.5);
    }
    /// Amplitude depth x (r / 1 mm)^(3/2).
    static double amplitude(double radiusM, double depth) noexcept {
        return depth * std::pow(radiusM / 1e-3, 1.5);
    }
};

struct BubbleStreamParameters {
    double radiusMinM = 0.5e-3; ///< smallest radius (f0 = 6 kHz)
    double radiusMaxM = 5e-3;   ///< largest radius (f0 = 600 Hz)
    double radiusExponent = -2; ///< beta in p(r) ~ r^beta
    double xi = 0.1;            ///< pitch rise factor
    double depthMin = 0.3;      ///< depth factors drawn uniformly in [depthMin, 1]
    int voices = 48;            ///< simultaneous bubbles
    double maxRateHz = 4000.0;  ///< the stream's own cap on the bubble rate
    /// Throws std::invalid_argument naming the parameter when a value is out of its domain.
    void validate() const;
};

class BubbleStream {
  public:
    void configure(const BubbleStreamParameters& parameters);
    const BubbleStreamParameters& parameters() const noexcept { return params_; }
    /// Allocates the pool; the rate is capped at min(maxRateHz, maxEventsPerSecond). Radii whose
    /// f0 would reach 0.45 fs are raised to that limit (3 / (0.45 fs)).
    void prepare(double sampleRateHz, int maxEventsPerSecond);
    void reset(std::uint64_t seed) noexcept;

    /// Adds n samples into `out`: bubbles start at rate `rateHz[i]` (per second) with amplitudes
    /// multiplied by `amplitudeScale[i]` (NaN/Inf/negative count as 0).
    void process(const float* rateHz, const float* amplitudeScale, float* out, int n) noexcept;
    /// Starts one bubble of a given radius and depth factor at the next processed sample
    /// (the stream's radius range does not apply; the Nyquist limit does).
    void triggerBubble(double radiusM, double depth) noexcept;

    bool idle() const noexcept { return activeVoices_ == 0 && pendingRadius_ <= 0; }
    int activeVoices() const noexcept { return activeVoices_; }
    std::uint64_t bubbleCount() const noexcept { return bubbleCount_; }
    double rateCapHz() const noexcept { return rateCapHz_; }
    /// Smallest radius that can ring at this sample rate.
    double minimumRadiusM() const noexcept { return minRadiusM_; }

  private:
    void spawn(double radiusM, double depth) noexcept;
    void freeVoice(int v) noexcept;
    void retireDeadVoices() noexcept;

    BubbleStreamParameters params_;
    double sampleRateHz_ = 48000.0;
    double rateCapHz_ = 4000.0;
    double minRadiusM_ = 0.0;
    double silenceAmplitude_ = 1e-4;
    double scale_ = 1.0; ///< amplitude scale of bubbles started now
    double pendingRadius_ = 0.0, pendingDepth_ = 0.0;
    Random random_;
    PoissonClock clock_;
    // Per voice (packed at the front): phasor z, rotation w, chirp rotation u, decay g.
    std::vector<double> zr_, zi_, wr_, wi_, ur_, ui_, g_;
    std::vector<std::int64_t> death_, start_;
    std::vector<double> startAmplitude_, logDecay_;
    int activeVoices_ = 0;
    std::int64_t nextDeath_ = INT64_MAX;
    std::int64_t sample_ = 0;
    std::uint64_t bubbleCount_ = 0;
};

} // namespace underfoot::engine
