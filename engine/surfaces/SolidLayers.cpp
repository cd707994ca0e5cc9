// SPDX-License-Identifier: GPL-3.0-or-later
// Solid-floor layers. The GRF (N) drives them through two physical gestures:
//  - a foot contact begins when the GRF rises through `onset_n` after the foot was off the floor
//    (below `release_n` for at least 30 ms): the sole strikes the floor with a velocity that
//    grows with the loading rate (a harder, faster landing is a faster sole);
//  - further sharp rises of the load (the forefoot slapping down, or the micro-impacts that a
//    microphone envelope carries) re-strike the floor while the foot is down;
//  - a fraction of the GRF itself presses the sole onto the floor (the low "thud" of the
//    floor's bending under the load, and the contact damping while standing);
//  - optionally (`heel_graze` > 0) the heel's rear edge touches first, lightly, and the heel lands
//    flat `heel_graze_lead_s` later: recorded steps on wood rise to their peak over several
//    milliseconds (docs/decisions/realism-revoicing.md, "The heel's edge before the heel").
#include "engine/surfaces/SolidLayers.h"

#include "engine/dsp/Envelope.h"
#include "engine/dsp/Random.h"
#include "engine/dsp/SleepGrid.h"
#include "engine/models/Friction.h"
#include "engine/models/Impact.h"
#include "engine/surfaces/FrictionDrive.h"

#include <algorithm>
#include <cmath>

namespace underfoot::engine {
namespace {

/// Reads `modes = [{ freq_hz, t60_s, mass_kg, gain }, ...]` (the floor's resonances).
void readModes(PresetReader& reader, const AccuracyOptions& options, std::vector<Mode>& modes,
               std::vector<double>& gains) {
    auto tables = reader.tables("modes", "the floor's modes, one table each (required)");
    if (tables.empty())
        reader.fail(
            "",
            "expected `modes = [{ freq_hz = ..., t60_s = ..., mass_kg = ..., gain = ... }, ...]`");
    for (auto& m : tables) {
        Mode mode;
        mode.frequencyHz =
            m.requiredNumber("freq_hz", 10.0, 40000.0, "Hz", "frequency of the mode", true);
        mode.t60Seconds =
            m.requiredNumber("t60_s", 0.001, 30.0, "s", "time to decay by 60 dB", true);
        mode.massKg = m.number("mass_kg", 1.0, 1e-4, 1e4, "kg",
                               "modal mass (heavier = quieter, stiffer floor)", true);
        gains.push_back(m.number("gain", 1.0, -10.0, 10.0, "", "mode shape at the contact point"));
        m.finish();
        modes.push_back(mode);
    }
    // Keep the lowest `maxModes` modes (an accuracy knob).
    if (static_cast<int>(modes.size()) > options.maxModes) {
        std::vector<std::size_t> order(modes.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(),
                  [&](auto a, auto b) { return modes[a].frequencyHz < modes[b].frequencyHz; });
        order.resize(static_cast<std::size_t>(options.maxModes));
        std::vector<Mode> m2;
        std::vector<double> g2;
        for (auto i : order) {
            m2.push_back(modes[i]);
            g2.push_back(gains[i]);
        }
        modes = m2;
        gains = g2;
    }
}

/// A strike scheduled some samples ahead (the heel after its edge's touch, the forefoot after
/// the heel).
struct PendingStrike {
    double countdown = -1.0, level = 0.0;
    /// Counts one sample down: the strike's strength if it falls due at this sample, else 0.
    double next() noexcept {
        if (countdown < 0.0) return 0.0;
        countdown -= 1.0;
        return countdown < 0.0 ? level : 0.0;
    }
};

/// Detects foot contacts and sharp load rises in a GRF, sample by sample (no allocation).
class StepGestures {
  public:
    double onsetN = 30.0, releaseN = 10.0, retriggerRate = 15000.0, retriggerGapS = 0.05;
    double referenceRate = 20000.0; ///< N/s giving the nominal strike velocity
    double toeDelayS = 0.07;        ///< forefoot lands this long after the heel (0 = never)
    double toeStrength = 0.6;       ///< forefoot strike velocity relative to the heel's
    double grazeStrength = 0.0;     ///< heel edge's touch velocity relative to the heel's (0: none)
    double grazeLeadS = 0.008;      ///< the heel lands flat this long after its edge touches

    void prepare(double fs) {
        fs_ = fs;
        smooth_ = onePoleCoefficientTau(0.0005, fs); // 0.5 ms derivative smoothing
        reset();
    }
    void reset(std::uint64_t seed = 1) {
        rng_.setSeed(seed);
        toe_ = heel_ = PendingStrike{};
        last_ = rate_ = 0.0;
        offSeconds_ = sinceStrike_ = 1e9;
        down_ = false;
        started_ = false;
        rearmed_ = true;
    }
    /// Returns a strike strength factor (> 0) when a strike happens at this sample, else 0.
    double next(double grf) noexcept {
        const double d = (grf - last_) * fs_;
        last_ = grf;
        rate_ = d + smooth_ * (rate_ - d);
        sinceStrike_ += 1.0;
        double strike = 0.0;
        if (!started_) {
            // A signal that starts with the foot already loaded (a walk joined mid-stance) holds
            // no landing: the foot is down, nothing strikes.
            started_ = true;
            down_ = grf >= releaseN;
            rate_ = 0.0;
            return 0.0;
        }
        if (!down_) {
            if (grf < releaseN) offSeconds_ += 1.0 / fs_;
            if (grf >= onsetN) {
                down_ = true;
                rearmed_ = false;
                if (offSeconds_ >= 0.03) {
                    strike = strength(std::max(rate_, 0.0));
                    // Heel then forefoot ("heel-toe" roll-over, Perry & Burnfield 2010): the
                    // forefoot lands about 70 ms later; +-15 % jitter so no two steps are alike.
                    if (toeStrength > 0.0 && toeDelayS > 0.0) {
                        toe_ = {toeDelayS * fs_ * (1.0 + 0.15 * rng_.bipolar()),
                                toeStrength * strike};
                    }
                    // The heel's edge first (the heel lands inclined, then rolls flat): a light
                    // touch now, the heel's strike after the lead (+-25 % jitter).
                    if (grazeStrength > 0.0) {
                        heel_ = {grazeLeadS * fs_ * (1.0 + 0.25 * rng_.bipolar()), strike};
                        strike *= grazeStrength;
                    }
                }
            }
        } else if (grf < releaseN) {
            down_ = false;
            offSeconds_ = 1.0 / fs_;
        } else if (retriggerRate > 0.0) {
            if (rate_ < 0.5 * retriggerRate) rearmed_ = true;
            if (rearmed_ && rate_ > retriggerRate && sinceStrike_ > retriggerGapS * fs_) {
                rearmed_ = false;
                strike = 0.5 * strength(rate_);
            }
        }
        const double heel = heel_.next(), toe = toe_.next(); // (due only while the foot is down)
        if (down_) strike = std::max({strike, heel, toe});
        if (strike > 0.0) sinceStrike_ = 0.0;
        return strike;
    }
    double rate() const noexcept { return rate_; }

  private:
    double strength(double rate) const noexcept {
        return std::clamp(std::sqrt(rate / referenceRate), 0.25, 3.0);
    }
    double fs_ = 48000, smooth_ = 0, last_ = 0, rate_ = 0;
    double offSeconds_ = 1e9, sinceStrike_ = 1e9; // time off the floor, samples since a strike
    PendingStrike toe_, heel_; // the forefoot after the heel; the heel after its edge's touch
    Random rng_;
    bool down_ = false, rearmed_ = true, started_ = false;
};

void readGestures(PresetReader& r, StepGestures& g) {
    g.onsetN = r.number("onset_n", 30.0, 1.0, 500.0, "N", "GRF at which a foot contact begins");
    g.releaseN =
        r.number("release_n", 10.0, 0.0, 400.0, "N", "GRF below which the foot is off the floor");
    if (g.releaseN >= g.onsetN) r.fail("release_n", "expected release_n below onset_n");
    g.referenceRate = r.number("reference_rate_n_per_s", 20000.0, 100.0, 1e6, "N/s",
                               "loading rate that gives the nominal strike velocity", true);
    g.retriggerRate = r.number("retrigger_rate_n_per_s", 15000.0, 0.0, 1e6, "N/s",
                               "load rise rate that re-strikes while the foot is down (0 = never)");
    g.retriggerGapS =
        r.number("retrigger_gap_s", 0.05, 0.005, 1.0, "s", "shortest time between strikes");
    g.grazeStrength = r.number("heel_graze", 0.0, 0.0, 1.0, "",
                               "the heel edge's first touch, as a share of the heel strike's "
                               "velocity (0 = the heel lands flat at once)");
    g.grazeLeadS = r.number("heel_graze_lead_s", 0.008, 0.001, 0.05, "s",
                            "time from the heel edge's touch to the heel's strike");
}

class ImpactLayer final : public SurfaceLayer {
  public:
    ImpactLayer(PresetReader& r, const AccuracyOptions& options) {
        std::vector<Mode> modes;
        std::vector<double> gains;
        readModes(r, options, modes, gains);
        ImpactParams p;
        p.stiffness = r.number("stiffness", 1e7, 1e4, 1e11, "N/m^alpha",
                               "sole-floor contact stiffness", true);
        p.alpha = r.number("alpha", 1.5, 1.0, 3.0, "", "contact hardening exponent");
        p.dissipation =
            r.number("dissipation", 0.5, 0.0, 5.0, "s/m", "contact damping (Hunt-Crossley mu)");
        p.exciterMassKg = r.number("sole_mass_kg", 0.3, 0.001, 5.0, "kg",
                                   "effective mass of the striking sole", true);
        p.oversampling = options.oversampling;
        p.newtonIterations = options.newtonIterations;
        p.solver = options.explicitImpact ? ImpactSolver::Explicit : ImpactSolver::Newton;
        strikeVelocity_ =
            r.number("strike_velocity", 0.5, 0.01, 3.0, "m/s", "sole speed at a nominal landing");
        pressFraction_ = r.number("press_fraction", 0.05, 0.0, 1.0, "",
                                  "share of the GRF pressing the sole on the floor");
        gain_ = dbToGain(r.number("gain_db", 20.0, -40.0, 80.0, "dB",
                                  "output gain (0 dB: 1 m/s floor velocity = full scale)"));
        readGestures(r, gestures_);
        impact_.configure(p, std::move(modes), {gains});
        impact_.setSleepVelocity(1e-6 / gain_); // asleep below -120 dBFS at the output
    }
    void prepare(const ProcessSpec& spec) override {
        impact_.prepare(spec);
        gestures_.prepare(spec.sampleRateHz);
        press_.assign(static_cast<std::size_t>(spec.maxBlockSize), 0.0f);
        buffer_.assign(static_cast<std::size_t>(spec.maxBlockSize), 0.0f);
    }
    void reset(std::uint64_t seed) noexcept override {
        impact_.reset();
        gestures_.reset(seed);
    }
    void process(const float* grf, float* out, int n) noexcept override {
        int start = 0;
        bool anyLoad = false;
        for (int i = 0; i < n; ++i) {
            const double g = std::max(0.0f, grf[i]);
            anyLoad |= g > 0.0;
            press_[static_cast<std::size_t>(i)] = static_cast<float>(pressFraction_ * g);
            const double strike = gestures_.next(g);
            if (strike > 0.0) {
                run(start, i, out);
                impact_.strike(strikeVelocity_ * strike);
                start = i;
            }
        }
        if (!anyLoad && impact_.isSleeping()) { // nothing to do (the sleep grid still counts)
            impact_.advanceAsleep(n - start);
            return;
        }
        run(start, n, out);
    }
    bool isSleeping() const noexcept override { return impact_.isSleeping(); }
    const char* kind() const noexcept override { return "impact"; }

  private:
    void run(int from, int to, float* out) noexcept {
        if (to <= from) return;
        impact_.process(press_.data() + from, buffer_.data() + from, to - from);
        const float g = static_cast<float>(gain_);
        for (int i = from; i < to; ++i) out[i] += g * buffer_[static_cast<std::size_t>(i)];
    }
    HuntCrossleyImpact impact_;
    StepGestures gestures_;
    double strikeVelocity_, pressFraction_, gain_;
    std::vector<float> press_, buffer_;
};

/// Creaking boards (engine/surfaces/FrictionDrive.h): while the load changes, the boards shear
/// against each other (and their nails): an anchor moves with a speed proportional to the GRF's
/// rate of change and drags a rubbing mass through a stiff spring; stick-slip against the
/// boards' modes makes the creak.
class FrictionLayer final : public SurfaceLayer {
  public:
    FrictionLayer(PresetReader& r, const AccuracyOptions& options) {
        FrictionLayerSettings s = readFrictionLayer(r, options);
        gain_ = s.gain;
        drive_.configure(s.drive);
        friction_.configure(s.model, std::move(s.modes), {std::move(s.gains)});
    }
    void prepare(const ProcessSpec& spec) override {
        friction_.prepare(spec.sampleRateHz);
        drive_.prepare(spec.sampleRateHz);
    }
    void reset(std::uint64_t seed) noexcept override {
        friction_.reset(seed);
        drive_.reset();
        sleepGrid_.reset();
    }
    void process(const float* grf, float* out, int n) noexcept override {
        // The resonator's tiny state is flushed on the sleep grid (engine/dsp/SleepGrid.h), not
        // at the end of each host block: the flush changes the next samples' last bits.
        sleepGrid_.split(n, [&](int offset, int length, bool atGridPoint) {
            processSpan(grf + offset, out + offset, length);
            if (atGridPoint) friction_.resonator().flushTinyState();
        });
    }
    bool isSleeping() const noexcept override { return drive_.isSleeping(); }
    const char* kind() const noexcept override { return "friction"; }

  private:
    void processSpan(const float* grf, float* out, int n) noexcept {
        const float g = static_cast<float>(gain_);
        FrictionDrive::Input in;
        for (int i = 0; i < n; ++i) {
            if (!drive_.next(grf[i], friction_, in)) continue; // asleep: nothing computed
            const double y =
                friction_.processSample(in.normal, 0.0, in.anchor, in.anchorVelocity, in.roughness);
            out[i] += g * static_cast<float>(y);
            drive_.settle(y, in, friction_);
        }
    }
    ElastoPlasticFriction friction_;
    FrictionDrive drive_;
    SleepGrid sleepGrid_;
    double gain_ = 1.0;
};

} // namespace

FrictionLayerSettings readFrictionLayer(PresetReader& r, const AccuracyOptions& options) {
    FrictionLayerSettings s;
    readModes(r, options, s.modes, s.gains);
    FrictionParams& p = s.model;
    p.sigma0 = r.number("sigma0", 1e5, 1e2, 1e8, "N/m", "bristle stiffness", true);
    p.sigma1 = r.number("sigma1", 300.0, 0.0, 1e5, "N s/m", "bristle damping");
    p.sigma2 = r.number("sigma2", 0.5, 0.0, 100.0, "N s/m", "viscous friction");
    p.sigma3 = r.number("sigma3", 0.0, 0.0, 100.0, "N", "roughness noise");
    p.staticCoefficient =
        r.number("static_coefficient", 0.6, 0.0, 2.0, "", "static friction per newton of load");
    p.dynamicCoefficient =
        r.number("dynamic_coefficient", 0.3, 0.0, 2.0, "", "Coulomb friction per newton of load");
    if (p.dynamicCoefficient > p.staticCoefficient)
        r.fail("dynamic_coefficient", "expected dynamic_coefficient <= static_coefficient");
    p.stribeckVelocity =
        r.number("stribeck_velocity", 0.05, 1e-4, 1.0, "m/s", "Stribeck velocity", true);
    p.breakAway =
        r.number("break_away", 0.7, 0.05, 0.95, "", "break-away deflection / static deflection");
    p.exciterMassKg =
        r.number("rubbing_mass_kg", 0.05, 1e-3, 5.0, "kg", "mass of the rubbing board edge", true);
    FrictionDriveParams& d = s.drive;
    d.normalFraction = r.number("normal_fraction", 0.2, 0.0, 1.0, "",
                                "share of the GRF pressing the rubbing surfaces");
    p.driveStiffness = r.number("drive_stiffness", 1e6, 1e2, 1e7, "N/m",
                                "stiffness dragging the rubbing mass", true);
    p.driveDamping = r.number("drive_damping", 5.0, 0.0, 1e3, "N s/m", "damping of the drag");
    d.slipPerRate = r.number("slip_m_per_s_per_kn_per_s", 0.002, 0.0, 0.1, "(m/s)/(kN/s)",
                             "shear speed of the boards per kN/s of load change");
    d.threshold = r.number("slip_threshold_n_per_s", 500.0, 0.0, 1e5, "N/s",
                           "load change below which the boards do not shear");
    s.gain = dbToGain(
        r.number("gain_db", 20.0, -40.0, 80.0, "dB", "output gain (0 dB: 1 m/s = full scale)"));
    d.sleepVelocity = 1e-6 / s.gain; // asleep below -120 dBFS at the output
    d.settling = LoadSettling::read(
        r, "after the boards' last shear, a load held still (the roughness noise of the contact)");
    return s;
}

std::unique_ptr<SurfaceLayer> makeImpactLayer(PresetReader& reader,
                                              const AccuracyOptions& options) {
    return std::make_unique<ImpactLayer>(reader, options);
}
std::unique_ptr<SurfaceLayer> makeFrictionLayer(PresetReader& reader,
                                                const AccuracyOptions& options) {
    return std::make_unique<FrictionLayer>(reader, options);
}

} // namespace underfoot::engine
