// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The "bubbles" layer: a van den Doel bubble stream (engine/models/Bubbles.h) plus band-limited
/// noise, driven by the ground reaction force, for puddles and water.
///
/// GRF -> sound (F in kN, dF/dt in kN/s smoothed by derivative_ms):
///  - splash: during the first splash_ms of each contact, bubbles start at
///    splash_bubbles_per_kn x max(dF/dt, 0) per second (i.e. so many bubbles per kN of load taken
///    on while the foot lands) and a splash noise (band-pass at splash_hz) follows the same drive
///    with a decay of splash_decay_ms (with splash_rise_ms > 0 the noise envelope rises towards
///    the drive with that time constant instead of at once: a splash develops, the sheet of water
///    thrown up and its drops falling back peak some tens of ms after the foot lands);
///  - stirring: while in contact, bubbles_per_kn x |dF/dt| bubbles per second (the foot moves and
///    pushes water around);
///  - wake: when the foot leaves (the load falls below contact_threshold_n) a motion envelope
///    starts at the speed of the release (|dF/dt| / 10 kN/s, clamped to [0.25, 2]) and decays with
///    time constant wake_ms: bubbles at wake_bubbles_hz x envelope (drips from the shoe in a
///    puddle; the leg swinging through the water when wading, the wading study);
///  - slosh: low band-pass noise (slosh_hz) following the motion (|dF/dt| / 10 kN/s, smoothed, plus
///    the wake envelope): the mass of water being displaced.
/// A load appearing from no contact by more than 100 N within one sample (a GRF starting
/// mid-stance) is no landing: no splash.
/// With the GRF at zero from reset the layer is silent and sleeps; after a step it sleeps again
/// once the bubbles, the wake and the noise have decayed.
#include "engine/dsp/Biquad.h"
#include "engine/models/Bubbles.h"
#include "engine/surfaces/LoadDrivenLayer.h"

namespace underfoot::engine {

struct BubblesControl {
    double bubblesPerKn = 0.0;
    double splashBubblesPerKn = 0.0;
    double splashMs = 60.0;
    double splashNoiseDb = -120.0; ///< <= -120: off
    double splashHz = 3000.0;
    double splashDecayMs = 40.0;
    double splashRiseMs = 0.0; ///< 0: the splash noise follows the landing at once
    double wakeMs = 0.0;
    double wakeBubblesHz = 0.0;
    double sloshDb = -120.0; ///< <= -120: off
    double sloshHz = 400.0;
    double derivativeMs = 5.0;
    double contactThresholdN = 5.0;
    double gainDb = 0.0;
    LoadSettling::Params settling; ///< a leg held still: the water calms (LoadInput.h)
};

class BubblesLayer final : public LoadDrivenLayer {
  public:
    BubblesLayer(const BubbleStreamParameters& stream, const BubblesControl& control,
                 const AccuracyOptions& options);
    void prepare(const ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    const char* kind() const noexcept override { return "bubbles"; }

    const BubbleStream& stream() const noexcept { return stream_; }

  private:
    bool processAwake(const float* grf, float* out, int n) noexcept override;
    bool settleTail() noexcept override;
    void fallAsleep() noexcept override;
    BubbleStream stream_;
    BubblesControl control_;
    int maxEventsPerSecond_;
    double splashDecayG_ = 0, splashRiseG_ = 0, wakeG_ = 0, motionG_ = 0;
    double gain_ = 1.0, splashGain_ = 0.0, sloshGain_ = 0.0;
    Biquad splashFilter_, sloshFilter_;
    Random noise_;
    std::vector<float> rate_, scale_, buffer_;
    bool inContact_ = false;
    LoadSettling settling_;
    int contactSamples_ = 0, splashSamples_ = 0;
    double releasePeak_ = 0;
    double splashEnv_ = 0, wakeEnv_ = 0, motionEnv_ = 0;
};

std::unique_ptr<SurfaceLayer> makeBubblesLayer(PresetReader& reader,
                                               const AccuracyOptions& options);

} // namespace underfoot::engine
