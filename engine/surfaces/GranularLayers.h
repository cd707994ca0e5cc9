// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The "grains" layer: one stochastic aggregate process (engine/models/Aggregate.h) driven by the
/// ground reaction force. Aggregate surfaces (gravel, sand, snow, leaves, grass, underbrush,
/// dirt, carpet) are sums of such layers.
///
/// GRF -> process (per sample, F in kN, dF/dt in kN/s smoothed by a one-pole of derivative_ms):
///   rate    = events_per_s_per_kn x F + events_per_kn_rise x max(dF/dt, 0)
///                                     + events_per_kn_fall x max(-dF/dt, 0)        [events/s]
///   (grains settle under a standing load; they crunch while the load builds up and shifts, and
///   some spring back on release: the two derivative terms are "events per kN of load change")
///   scale   = F^load_exponent x (1 + rise_energy x max(dF/dt, 0) / 10)   (energy multiplier)
///           with energy_saturation S > 0 the scale saturates softly: scale -> S tanh(scale / S)
///           (unchanged for light loads, never above S: a grain can only break so hard)
///   onset   = one event of energy onset_energy x clamp(dF/dt / 10, 0.1, 3) when the load first
///             crosses onset_force_n in a step (the heel lands: a thump or a crunch).
/// A load that appears from no contact by more than 100 N within one sample (a GRF file or the
/// walker starting mid-stance) is taken as already there: no landing event, no rise.
/// Everything is zero while F <= contact_threshold_n; when the voices have rung out and the load
/// stays below the threshold the layer sleeps (a block then costs one scan of the GRF).
/// Energy bound: amplitude_cap (in amplitudes of the largest event under a 1 kN load) bounds the
/// summed amplitude of the grains ringing at once (engine/models/Aggregate.h): a heavy or fast
/// walker makes more and stronger breaks, but the bed under the sole releases only so much
/// energy at a time, so the layer's output stays below sqrt(resonances) x cap x gain for any
/// load. 0 (the default): no bound.
/// Heel burst (heel_rate_hz > 0; docs/decisions/realism-revoicing.md "Heel-driven grains and
/// several starts"): the heel's first impact crushes the most grains. The sole lands at its highest
/// speed and stops within tens of ms, before the load has built up, so a bed of sand or dirt
/// crushes and shifts most in the first 20-30 ms of the contact (recorded sand and dirt steps peak
/// there) whatever the slower load curve does later. When the load first exceeds the contact
/// threshold in a step, an envelope starts: e(t) = (t / T) exp(1 - t / T) up to its peak 1 at
/// T = heel_ms, then exp(-(t - T) / D), D = heel_decay_ms (the crushed bed settling; it ends at
/// T + 10 D). It adds heel_rate_hz x e(t) events/s whose energy
/// scale is heel_energy x e(t) (saturated like the others by energy_saturation); the two
/// streams are one Poisson process (rates add) whose energy scale is their rate-weighted mean.
/// No random draw of its own, computed per sample: deterministic and block-size independent;
/// bounded by amplitude_cap like every event. A load that appears mid-stance (a cut, above)
/// starts no burst. heel_rate_hz = 0 (the default): exactly the process above.
/// Load memory (felicity_ratio R > 0): the two rise terms (events_per_kn_rise, rise_energy) count
/// only while F >= R x the highest load of this contact so far. A brittle crust or bond breaks
/// under a load it has not carried yet and is silent when reloaded below it (the Kaiser effect of
/// acoustic emission; R is its Felicity ratio: 1 = strict, < 1 = it re-breaks a little before the
/// old maximum). The memory is cleared when the foot leaves (F <= contact_threshold_n). 0 (the
/// default): every load rise counts.
/// Excitation: "resonant" (the default: each event rings at random resonances) or "noise" (each
/// event is a burst of white noise decaying with noise_decay_ms and rising over
/// noise_attack_ratio of it, Aggregate.h: grains too small to ring, heard as the hiss of sand or
/// the crunch of snow rather than as pitched ticks).
/// The sum of the voices goes through an optional 2nd-order Butterworth high-pass and low-pass
/// (tone) and the layer gain.
#include "engine/dsp/Biquad.h"
#include "engine/models/Aggregate.h"
#include "engine/surfaces/LoadDrivenLayer.h"

namespace underfoot::engine {

/// The GRF mapping of a grains layer (see the file comment).
struct GrainsControl {
    double eventsPerSecondPerKn = 0.0;
    double eventsPerKnRise = 0.0;
    double eventsPerKnFall = 0.0;
    double loadExponent = 1.0;
    double riseEnergy = 0.0;
    double energySaturation = 0.0; ///< S of scale -> S tanh(scale / S); 0: linear
    double onsetEnergy = 0.0;
    double onsetForceN = 200.0;
    double derivativeMs = 5.0;
    double contactThresholdN = 5.0;
    double lowpassHz = 0.0;  ///< 0: off
    double highpassHz = 0.0; ///< 0: off
    double gainDb = 0.0;
    double heelRateHz = 0.0;    ///< heel burst: peak extra event rate (0: no burst)
    double heelMs = 15.0;       ///< heel burst: time from contact to its peak
    double heelDecayMs = 30.0;  ///< heel burst: decay time constant after the peak
    double heelEnergy = 1.0;    ///< heel burst: energy scale of its events at the peak
    double felicityRatio = 0.0; ///< rise terms only while F >= ratio x the contact's peak; 0: off
    LoadSettling::Params settling; ///< a load held still: the bed settles (LoadInput.h)
};

class GrainsLayer final : public LoadDrivenLayer {
  public:
    GrainsLayer(const AggregateParameters& model, const GrainsControl& control,
                const AccuracyOptions& options);
    void prepare(const ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    const char* kind() const noexcept override { return "grains"; }

    const AggregateModel& model() const noexcept { return model_; }
    AggregateModel& model() noexcept { return model_; }
    const GrainsControl& control() const noexcept { return control_; }

  private:
    bool processAwake(const float* grf, float* out, int n) noexcept override;
    bool settleTail() noexcept override;
    void fallAsleep() noexcept override;
    /// Heel burst: the envelope at this sample (advances it); 0 when no burst runs.
    double heelEnvelope() noexcept;
    AggregateModel model_;
    GrainsControl control_;
    int maxEventsPerSecond_;
    double gain_ = 1.0;
    Biquad lowpass_, highpass_;
    bool useLowpass_ = false, useHighpass_ = false;
    std::vector<float> rate_, buffer_;
    // What a sample's energy scale is computed from. The scale (a pow and up to two tanh) matters
    // only where a grain starts, so the model asks for it there (scaleAt); the same values.
    struct SampleLoad {
        double kn, rise, heelE; // load (kN), rise term, heel burst envelope
        float baseRate;         // the event rate before the heel burst's
        bool contact, heel;     // in contact; the heel burst's branch taken
    };
    std::vector<SampleLoad> loads_;
    std::size_t scaleBase_ = 0; // the sample of this chunk where the model's call starts
    float scaleOf(std::size_t u) const noexcept;
    static float scaleAt(void* self, int i) noexcept;
    void runModel(int from, int to, float* buffer) noexcept;
    double contactPeakN_ = 0.0; ///< highest load of this contact so far (felicity_ratio)
    bool onsetArmed_ = true;
    LoadSettling settling_;
    std::int64_t heelAge_ = -1; ///< samples since the heel burst started; -1: none running
    std::int64_t heelEnd_ = 0;  ///< its length (heel_ms + 10 heel_decay_ms) in samples
};

/// Factory for the layer table: reads every parameter of a grains layer (with unit and range).
std::unique_ptr<SurfaceLayer> makeGrainsLayer(PresetReader& reader, const AccuracyOptions& options);

} // namespace underfoot::engine
