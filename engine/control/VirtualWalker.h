// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A parametric walker: the vertical ground reaction force (GRF, newtons) under each foot.
///
/// Shape of one stance (one foot on the ground), in stance-normalised time s in [0, 1]:
///  - heel-strike impact transient right after contact: a raised-cosine bump whose height and
///    sharpness grow with shoe hardness (Whittle 1999, "Generation and attenuation of transient
///    impulsive forces beneath the foot: a review", Gait & Posture 10:264-275: transients last
///    roughly 5-25 ms and are attenuated by soft footwear);
///  - heel (weight-acceptance) peak F1 at s = 0.25, mid-stance valley V at s = 0.5, push-off peak
///    F2 at s = 0.75: the classic double hump of walking (Perry & Burnfield, "Gait Analysis:
///    Normal and Pathological Function", 2nd ed. 2010, ch. 2; Winter, "Biomechanics and Motor
///    Control of Human Movement", 4th ed. 2009). F1 and F2 grow and the valley deepens with speed
///    (Keller et al. 1996, "Relationship between vertical ground reaction force and speed during
///    walking, slow jogging, and running", Clin. Biomech. 11:253-259): here
///    F1 = 1.20 + 0.004 (cadence - 110) BW and F2 = 1.12 + 0.002 (cadence - 110) BW (clamped),
///    i.e. 1.16 / 1.10 BW at 100 steps/min;
///  - the curve between the knots is a piecewise cubic Hermite with zero slope at the peaks and
///    the valley, so the extrema sit exactly at the knots.
/// Timing: stride (gait cycle) = 120 / cadence seconds; stance = duty factor x stride with a duty
/// factor of 0.60 at 110 steps/min that shortens with cadence, 0.60 - 0.001 (cadence - 110),
/// clamped to [0.55, 0.66] (Andriacchi, Ogle & Galante 1977, "Walking speed as a basis for normal
/// and abnormal gait measurements", J. Biomech. 10:261-268; stance ~60 % of the cycle, double
/// support ~2 x 10 %). The left foot strikes at t = 0, the right one half a stride later; at t = 0
/// the right foot is already in its stance (steady walking from the first sample).
/// Force balance: over a stride the mean vertical GRF of both feet equals body weight (the centre
/// of mass does not drift vertically), so the valley V is solved per step from that constraint
/// instead of being set by hand; it comes out at 0.68-0.77 BW over 60-150 steps/min.
/// Variability: each step's duration gets Gaussian relative jitter with the given standard
/// deviation, its heel peak, valley and push-off peak independent jitter of half that (all
/// clamped at 2 sigma; seeded, engine/dsp/Random.h); the jittered curve is rescaled so that the
/// force balance still holds.
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"

#include <cstdint>
#include <string>

namespace underfoot::engine {

/// Parameters of the virtual walker with their documented valid ranges.
struct WalkerParameters {
    double massKg = 70.0;              ///< body mass, [20, 200] kg
    double cadenceStepsPerMin = 100.0; ///< steps per minute (2 steps per stride), [60, 150]
    double shoeHardness = 0.5;         ///< 0 soft (trainer) .. 1 hard (leather sole/heel), [0, 1]
    double variability = 0.03;         ///< relative std of step duration and peaks, [0, 0.2]

    static constexpr double kMinMassKg = 20, kMaxMassKg = 200;
    static constexpr double kMinCadence = 60, kMaxCadence = 150;
    static constexpr double kMaxVariability = 0.2;

    /// Parses "cadence=100,mass=70,shoe=0.5,variability=0.03" (any subset, any order; the rest
    /// keep their defaults). Throws std::invalid_argument naming the column and what was expected.
    static WalkerParameters parse(const std::string& spec);
    /// Throws std::invalid_argument when a value is non-finite or outside its range.
    void validate() const;
    /// "cadence=100,mass=70,shoe=0.5,variability=0.03"
    std::string toString() const;
};

/// The shape of one stance derived from the parameters (no variability applied).
struct StanceShape {
    double stanceSeconds = 0;    ///< duration of one foot's contact
    double heelPeakBw = 0;       ///< F1 in body weights at s = 0.25
    double valleyBw = 0;         ///< V at s = 0.5 (solved from force balance)
    double pushOffPeakBw = 0;    ///< F2 at s = 0.75
    double transientBw = 0;      ///< height of the heel-strike transient bump
    double transientSeconds = 0; ///< its duration (peak at half of it)
    /// Vertical force in body weights at stance-normalised time s (0 outside [0, 1)).
    double forceBw(double s) const noexcept;
};

/// Relative deviations of one step's heel peak, valley and push-off peak from the nominal shape
/// (before the force-balance scaling).
struct StanceJitter {
    double heel = 0, valley = 0, pushOff = 0;
};

class VirtualWalker {
  public:
    explicit VirtualWalker(const WalkerParameters& parameters = {});

    /// Validates and sets the parameters (throws std::invalid_argument); takes effect at the next
    /// step. Not for the audio thread.
    void setParameters(const WalkerParameters& parameters);
    const WalkerParameters& parameters() const noexcept { return params_; }

    void prepare(const ProcessSpec& spec);
    /// Restarts the walk at t = 0 (left heel strike) with a new seed.
    void reset(std::uint64_t seed) noexcept;
    /// Writes the vertical GRF in newtons of the left and right foot. No allocation, no locks.
    void process(float* left, float* right, int n) noexcept;

    /// Body weight m g in newtons.
    double bodyWeightNewtons() const noexcept { return params_.massKg * kGravity; }
    /// Stride (gait cycle, two steps) in seconds: 120 / cadence.
    double strideSeconds() const noexcept { return 120.0 / params_.cadenceStepsPerMin; }
    /// Stance duration as a fraction of the stride (duty factor).
    static double dutyFactor(double cadenceStepsPerMin) noexcept;
    /// Stance shape for a step of `stepSeconds` (half a stride). Without jitter the valley is
    /// solved from the force balance; with jitter the heel peak, nominal valley and push-off
    /// peak are perturbed and the whole curve (not the transient) is then scaled so that the
    /// balance still holds exactly.
    static StanceShape shapeFor(const WalkerParameters& p, double stepSeconds,
                                const StanceJitter& jitter = {}) noexcept;

  private:
    struct Stance {
        double startSample = 0;   ///< fractional sample of heel strike
        double lengthSamples = 0; ///< stance duration in samples
        StanceShape shape{};
        bool active = false;
    };
    void scheduleStep(int foot) noexcept;

    WalkerParameters params_;
    double sampleRateHz_ = 48000.0;
    Random random_;
    Stance stance_[2];
    double nextStepSample_ = 0; ///< when the next heel strike happens
    int nextFoot_ = 0;          ///< 0 left, 1 right
    std::int64_t sample_ = 0;
};

} // namespace underfoot::engine
