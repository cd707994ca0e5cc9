// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/surfaces/GranularLayers.h"

#include "engine/dsp/Envelope.h"
#include "engine/surfaces/LoadInput.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace underfoot::engine {

namespace {
constexpr double kTailSeconds = 0.25; // filters ring out this long before the layer sleeps
constexpr double kDerivativeRefKnPerS = 10.0;

} // namespace

GrainsLayer::GrainsLayer(const AggregateParameters& model, const GrainsControl& control,
                         const AccuracyOptions& options)
    : control_(control), maxEventsPerSecond_(options.maxEventsPerSecond) {
    model_.configure(model);
    gain_ = dbToGain(control.gainDb);
}

void GrainsLayer::prepare(const ProcessSpec& spec) {
    prepareLoad(spec, control_.derivativeMs, control_.contactThresholdN, kTailSeconds);
    model_.prepare(spec.sampleRateHz, maxEventsPerSecond_);
    const double nyquistGuard = 0.45 * sampleRateHz_;
    useLowpass_ = control_.lowpassHz > 0 && control_.lowpassHz < nyquistGuard;
    useHighpass_ = control_.highpassHz > 0;
    if (useLowpass_)
        lowpass_.setCoefficients(
            BiquadCoefficients::lowpass(sampleRateHz_, control_.lowpassHz, 0.7071067811865476));
    if (useHighpass_)
        highpass_.setCoefficients(BiquadCoefficients::highpass(
            sampleRateHz_, std::min(control_.highpassHz, nyquistGuard), 0.7071067811865476));
    const auto block = static_cast<std::size_t>(std::max(1, spec.maxBlockSize));
    rate_.assign(block, 0.0f);
    loads_.assign(block, SampleLoad{});
    buffer_.assign(block, 0.0f);
    settling_.prepare(control_.settling, sampleRateHz_);
    heelEnd_ = static_cast<std::int64_t>(
        std::ceil((control_.heelMs + 10.0 * control_.heelDecayMs) * 1e-3 * sampleRateHz_));
    reset(0);
}

void GrainsLayer::reset(std::uint64_t seed) noexcept {
    model_.reset(seed);
    lowpass_.reset();
    highpass_.reset();
    resetLoad();
    contactPeakN_ = 0.0;
    onsetArmed_ = true;
    heelAge_ = -1;
    settling_.reset();
}

double GrainsLayer::heelEnvelope() noexcept {
    if (heelAge_ < 0) return 0.0;
    if (heelAge_ >= heelEnd_) {
        heelAge_ = -1;
        return 0.0;
    }
    const double t = static_cast<double>(heelAge_++) / sampleRateHz_;
    const double peak = control_.heelMs * 1e-3;
    if (t < peak) return t / peak * std::exp(1.0 - t / peak);     // rise: (t / T) exp(1 - t / T)
    return std::exp(-(t - peak) / (control_.heelDecayMs * 1e-3)); // then the settling decay
}

bool GrainsLayer::processAwake(const float* grf, float* out, int n) noexcept {
    const double threshold = control_.contactThresholdN;
    bool contactSeen = false;
    float* buffer = buffer_.data();
    std::fill(buffer, buffer + n, 0.0f);
    int modelDone = 0; // samples the model has run
    for (int i = 0; i < n; ++i) {
        const double f = sanitizeForce(grf[i]);
        if (control_.heelRateHz > 0) // heel burst: starts at a landing, not at a cut (below)
            heelAge_ = previousF_ <= threshold && f > threshold ? (f - previousF_ > kJumpN ? -1 : 0)
                                                                : (f > threshold ? heelAge_ : -1);
        // A cut (a file or walker starting in the middle of a step): the load is already
        // there, no landing.
        if (trackLoad(f)) onsetArmed_ = false;
        const auto u = static_cast<std::size_t>(i);
        if (f > threshold) {
            contactSeen = true;
            const double kn = f * 1e-3;
            const double loadRise = std::max(derivative_, 0.0);
            // Load memory: a load the layer has carried in this contact breaks nothing new.
            const double rise = f >= control_.felicityRatio * contactPeakN_ ? loadRise : 0.0;
            contactPeakN_ = std::max(contactPeakN_, f);
            const double fall = std::max(-derivative_, 0.0);
            // A load held still: the bed settles (LoadSettling; exactly 1 while walking).
            const double settle = settling_.inContact(derivative_);
            rate_[u] = static_cast<float>((control_.eventsPerSecondPerKn * kn +
                                           control_.eventsPerKnRise * rise +
                                           control_.eventsPerKnFall * fall) *
                                          settle);
            SampleLoad& sl = loads_[u];
            sl.contact = true;
            sl.kn = kn;
            sl.rise = rise;
            sl.heel = heelAge_ >= 0;
            if (sl.heel) { // heel burst: one Poisson stream, rate-weighted energy scale
                const double e = heelEnvelope();
                const double heelRate = control_.heelRateHz * e;
                sl.heelE = e;
                sl.baseRate = rate_[u];
                rate_[u] = static_cast<float>(static_cast<double>(rate_[u]) + heelRate);
            }
            if (onsetArmed_ && f >= control_.onsetForceN) {
                onsetArmed_ = false;
                if (control_.onsetEnergy > 0) {
                    // The onset event starts at this sample: run the model up to it first.
                    runModel(modelDone, i, buffer);
                    modelDone = i;
                    model_.trigger(control_.onsetEnergy *
                                   std::clamp(loadRise / kDerivativeRefKnPerS, 0.1, 3.0));
                }
            }
        } else {
            rate_[u] = 0.0f;
            loads_[u].contact = false;
            onsetArmed_ = true;
            contactPeakN_ = 0.0;
            settling_.reset();
        }
    }
    runModel(modelDone, n, buffer);
    // (sample by sample: the filters' tiny state is snapped on the sleep grid, not per call)
    if (useHighpass_)
        for (int i = 0; i < n; ++i)
            buffer[i] = static_cast<float>(highpass_.processSample(buffer[i]));
    if (useLowpass_)
        for (int i = 0; i < n; ++i)
            buffer[i] = static_cast<float>(lowpass_.processSample(buffer[i]));
    const float gain = static_cast<float>(gain_);
    for (int i = 0; i < n; ++i) out[i] += gain * buffer[i];
    return contactSeen;
}

void GrainsLayer::runModel(int from, int to, float* buffer) noexcept {
    scaleBase_ = static_cast<std::size_t>(from);
    model_.process(rate_.data() + from, &GrainsLayer::scaleAt, this, buffer + from, to - from);
}

float GrainsLayer::scaleAt(void* self, int i) noexcept {
    const auto* layer = static_cast<const GrainsLayer*>(self);
    return layer->scaleOf(layer->scaleBase_ + static_cast<std::size_t>(i));
}

// The energy scale of sample u: the load (to load_exponent) raised by the load's rise, softly
// saturated, and during a heel burst averaged with the burst's scale, weighted by the two rates.
float GrainsLayer::scaleOf(std::size_t u) const noexcept {
    const SampleLoad& sl = loads_[u];
    if (!sl.contact) return 0.0f;
    const double kn = sl.kn;
    const double load = control_.loadExponent == 1.0   ? kn
                        : control_.loadExponent == 0.0 ? 1.0
                                                       : std::pow(kn, control_.loadExponent);
    double scale = load * (1.0 + control_.riseEnergy * sl.rise / kDerivativeRefKnPerS);
    if (control_.energySaturation > 0) // soft saturation: linear below, bounded above
        scale = control_.energySaturation * std::tanh(scale / control_.energySaturation);
    if (sl.heel) {
        const double e = sl.heelE;
        const double heelRate = control_.heelRateHz * e;
        double heelScale = control_.heelEnergy * e;
        if (control_.energySaturation > 0)
            heelScale =
                control_.energySaturation * std::tanh(heelScale / control_.energySaturation);
        const double base = static_cast<double>(sl.baseRate);
        if (base + heelRate > 0) scale = (base * scale + heelRate * heelScale) / (base + heelRate);
    }
    return static_cast<float>(scale);
}

bool GrainsLayer::settleTail() noexcept {
    highpass_.snapTinyState();
    lowpass_.snapTinyState();
    return model_.idle();
}

void GrainsLayer::fallAsleep() noexcept {
    lowpass_.reset();
    highpass_.reset();
}

std::unique_ptr<SurfaceLayer> makeGrainsLayer(PresetReader& r, const AccuracyOptions& options) {
    AggregateParameters m;
    GrainsControl c;
    c.gainDb = r.number("gain_db", 0.0, -60.0, 40.0, "dB", "level of this layer");
    c.eventsPerSecondPerKn =
        r.number("events_per_s_per_kn", 0.0, 0.0, 10000.0, "events/s/kN",
                 "event rate per kN of standing load (grains settling under the weight)");
    c.eventsPerKnRise = r.number("events_per_kn_rise", 0.0, 0.0, 5000.0, "events/kN",
                                 "events per kN of load increase (crunch while loading)");
    c.eventsPerKnFall = r.number("events_per_kn_fall", 0.0, 0.0, 5000.0, "events/kN",
                                 "events per kN of load decrease (spring-back on release)");
    m.maxRateHz = r.number("max_rate_hz", 4000.0, 1.0, 20000.0, "events/s",
                           "this layer's cap on the event rate (bursts included)", true);
    m.gamma = r.number("gamma", -1.5, -4.0, 1.0, "", "exponent of the energy law p(E) ~ E^gamma");
    m.energyMin = r.number("energy_min", 1e-3, 1e-6, 1.0, "relative",
                           "smallest event energy (the largest is 1)", true);
    m.energyMax = 1.0;
    c.loadExponent = r.number("load_exponent", 1.0, 0.0, 3.0, "",
                              "event energies scale as (GRF / 1 kN)^load_exponent");
    c.riseEnergy =
        r.number("rise_energy", 0.0, 0.0, 20.0, "per 10 kN/s",
                 "extra energy while the load rises: x (1 + rise_energy dF/dt / 10 kN/s)");
    c.energySaturation = r.number(
        "energy_saturation", 0.0, 0.0, 1000.0, "x energy scale at 1 kN",
        "event energies saturate with load and load change: scale -> S tanh(scale / S), so no "
        "single break exceeds S times the largest one under a 1 kN load (0: linear)");
    c.onsetEnergy = r.number("onset_energy", 0.0, 0.0, 10.0, "relative",
                             "energy of one event when the heel loads (0: none)");
    c.onsetForceN = r.number("onset_force_n", 200.0, 1.0, 2000.0, "N",
                             "load at which the onset event fires", true);
    const bool noise =
        r.string("excitation", "resonant", {"resonant", "noise"},
                 "each event rings at random resonances or is a noise burst") == "noise";
    if (noise) { // noise bursts: no resonances to read (a stray freq_* or q_* is refused)
        m.excitation = AggregateParameters::Excitation::Noise;
        m.resonances = 1;
        m.noiseDecayMs = r.number(
            "noise_decay_ms", 5.0, 0.1, 200.0, "ms",
            "excitation = \"noise\": each event is a burst of white noise (the layer's tone "
            "filters colour it) whose amplitude decays as exp(-t / noise_decay_ms): the friction "
            "and fracture of grains too small to ring",
            true);
        m.noiseCornerHz = r.number("noise_corner_hz", 0.0, 0.0, 20000.0, "Hz",
                                   "excitation = \"noise\": the bursts' spectrum falls 6 dB per "
                                   "octave above this frequency (0: white)");
        m.noiseAttackMs =
            m.noiseDecayMs *
            r.number("noise_attack_ratio", 0.0, 0.0, 0.9, "x noise_decay_ms",
                     "excitation = \"noise\": each burst's power rises as exp(-2t / D) - "
                     "exp(-2t / (ratio x D)), D = noise_decay_ms, instead of starting at once: "
                     "grains rubbing and giving way build up their noise, where an instantaneous "
                     "start clicks like a hard tap (0: instantaneous)");
    } else {
        m.resonances = r.integer("resonances", 2, 1, 4, "damped resonances per event");
        std::tie(m.freqMinHz, m.freqMaxHz) =
            orderedPair(r.number("freq_min_hz", 1000.0, 20.0, 20000.0, "Hz",
                                 "lowest resonance frequency of a grain", true),
                        r.number("freq_max_hz", 4000.0, 20.0, 20000.0, "Hz",
                                 "highest resonance frequency of a grain", true));
        std::tie(m.qMin, m.qMax) =
            orderedPair(r.number("q_min", 5.0, 0.5, 200.0, "",
                                 "lowest quality factor (decay Q / (pi f))", true),
                        r.number("q_max", 20.0, 0.5, 200.0, "", "highest quality factor", true));
    }
    m.burstEvents = r.number("burst_events", 0.0, 0.0, 32.0, "events",
                             "mean number of micro-events following each event (a crunch)");
    m.burstMs = r.number("burst_ms", 2.0, 0.1, 100.0, "ms",
                         "mean delay of a burst's micro-events after their event", true);
    m.voices = r.integer("voices", 32, 1, 256, "simultaneous events");
    m.amplitudeCap = r.number(
        "amplitude_cap", 0.0, 0.0, 100.0, "x largest grain at 1 kN",
        "bound on the summed amplitude of the grains ringing at once, in amplitudes of the largest "
        "event under a 1 kN load: the bed releases only so much energy at a time (0: none)");
    c.derivativeMs =
        r.number("derivative_ms", 5.0, 0.5, 50.0, "ms", "smoothing time constant of dF/dt", true);
    c.contactThresholdN = r.number("contact_threshold_n", 5.0, 0.5, 100.0, "N",
                                   "load below which the foot is off the ground (silence)", true);
    c.felicityRatio = r.number(
        "felicity_ratio", 0.0, 0.0, 1.0, "x contact's peak load",
        "load memory: the rise terms (events_per_kn_rise, rise_energy) count only while the load "
        "is at least this fraction of the highest load of the contact so far (a brittle crust "
        "breaks only under a load it has not carried yet: the Kaiser effect; 0: every rise "
        "counts)");
    c.lowpassHz =
        r.number("lowpass_hz", 0.0, 0.0, 20000.0, "Hz", "tone: 2nd-order low-pass cutoff (0: off)");
    c.highpassHz =
        r.number("highpass_hz", 20.0, 0.0, 5000.0, "Hz", "2nd-order high-pass cutoff (0: off)");
    c.heelRateHz = r.number(
        "heel_rate_hz", 0.0, 0.0, 20000.0, "events/s",
        "heel burst: extra events at the heel's impact, at most this rate at heel_ms after the "
        "contact, rising as (t / heel_ms) exp(1 - t / heel_ms), then decaying with "
        "heel_decay_ms: the sole's first impact crushes the most grains (0: none)");
    c.heelMs = r.number("heel_ms", 15.0, 1.0, 200.0, "ms",
                        "heel burst: time from the heel's contact to the burst's peak", true);
    c.heelDecayMs = r.number("heel_decay_ms", 30.0, 1.0, 1000.0, "ms",
                             "heel burst: decay time constant after its peak, exp(-(t - "
                             "heel_ms) / heel_decay_ms) (the crushed bed settling)",
                             true);
    c.heelEnergy =
        r.number("heel_energy", 1.0, 0.0, 100.0, "x energy scale at 1 kN",
                 "heel burst: energy scale of its events at the peak (follows the same envelope)");
    c.settling = LoadSettling::read(r);
    if (c.lowpassHz > 0 && c.lowpassHz < 20) c.lowpassHz = 20; // a 0+ cutoff would mute everything
    return std::make_unique<GrainsLayer>(m, c, options);
}

} // namespace underfoot::engine
