// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Hunt–Crossley impact between an inertial exciter (the sole, a point mass) and a modal
/// resonator (the floor).
///
/// Physics (Hunt & Crossley 1975; Avanzini & Rocchesso, DAFx 2001; docs/explanation/models.md):
/// with compression c = x_exciter - x_floor (positive when the bodies interpenetrate) and its
/// rate c',
///     F = k c^alpha (1 + mu c')   for c > 0,   else 0,
/// clamped at F >= 0 (the contact never pulls, Marhefka & Orin 1999). mu = lambda / k is the
/// dissipation in s/m: restitution for a rigid floor is e ~ 1 - (2/3)... falls with mu v_in.
///
/// Discretisation: the floor is integrated exactly for a force linear between samples (see
/// ModalResonator), the exciter with the average-acceleration (trapezoidal) rule, unconditionally
/// stable however stiff the contact; both bodies respond instantaneously to the contact force
/// at n+1 through known compliances; the contact force is then the root of a
/// scalar monotone equation g(F) = F - HC(c_h - K_c F, c'_h - K_d F), solved by Newton's method
/// safeguarded by bisection on the bracket [0, HC(c_h, c'_h)] (the "K-method" of Borin, De Poli
/// & Rocchesso 2000), followed by an energy check that bisects the force history when the
/// discrete contact would create energy. The explicit variant computes the force from the state at
/// n, as the Sound Design Toolkit does. Work per sample is bounded by the iteration cap.
#include "engine/dsp/Biquad.h"
#include "engine/dsp/SleepGrid.h"
#include "engine/models/ModalResonator.h"

#include <vector>

namespace underfoot::engine {

enum class ImpactSolver {
    Explicit, ///< force from the previous state (cheap, inaccurate and unstable when stiff)
    Newton,   ///< implicit, safeguarded Newton with at most `newtonIterations` steps
};

struct ImpactParams {
    double stiffness = 1e7;     ///< k, N/m^alpha
    double alpha = 1.5;         ///< hardening exponent (1 = linear spring, 1.5 = Hertz)
    double dissipation = 0.5;   ///< mu = lambda / k, s/m
    double exciterMassKg = 0.3; ///< effective mass of the striking sole
    ImpactSolver solver = ImpactSolver::Newton;
    int newtonIterations = 6; ///< iteration cap (bounded work per sample)
    int oversampling = 1;     ///< 1, 2, 4 or 8: the contact runs at this multiple of the rate
    /// 1, 2, 4, 8 or 16: a sample in which the bodies touch is computed as this many sub-steps
    /// (the exact modal discretisation at the finer step, the force linear in each sub-step);
    /// samples of free flight stay single steps. A contact lasts ~10-20 samples per strike, so
    /// this costs ~1 % while matching the 8x oversampled reference: with 4, the
    /// bench strike's restitution is 0.5585 against the reference's 0.5583 and its spectrum is
    /// 0.02 dB from it (8 sub-steps: 0.5583, 0.01 dB, at twice the cost of a strike's samples).
    int contactSubsteps = 4;
    /// A sample in contact is sub-stepped only while the contact is a transient: it opens or
    /// closes in the sample, or the single step's force differs from the previous one by more
    /// than this fraction of the larger. A sole resting on the floor stays single-stepped. After
    /// a sample whose force changed by more than 4x this fraction (a strike), the next sample is
    /// sub-stepped without trying the single step first.
    double substepForceChange = 0.02;
};

/// Statistics of the last strikes, for tests and the accuracy benchmark.
struct ContactStats {
    double contactTimeSeconds = 0;  ///< duration of the last continuous contact
    double peakForceN = 0;          ///< largest contact force of the last contact
    double incomingVelocity = 0;    ///< relative velocity when the last contact began
    double outgoingVelocity = 0;    ///< relative velocity when it ended
    long long solverIterations = 0; ///< Newton iterations since reset
    long long solvedSamples = 0;    ///< samples in contact since reset
    int maxIterationsInOneSample = 0;
    long long passivityCorrections = 0; ///< samples where the energy guard removed a gain
    long long freeRunSamples = 0;       ///< samples of free flight run at once (runFree)
    /// of those, samples run with the floor's contact point tested sample by sample (right after
    /// a contact, where the bound on the floor's ringing is too loose: ringFreeUntilContact)
    long long testedRunSamples = 0;
};

template <typename Real>
class HuntCrossleyImpactT {
  public:
    /// Sets the floor's modes and pickup gains: pickup 0 is the contact point, `listenPickup`
    /// the point whose velocity is the output.
    void configure(const ImpactParams& params, std::vector<Mode> modes,
                   std::vector<std::vector<double>> gains, int listenPickup = 0);
    /// Allocates and computes coefficients. Throws std::invalid_argument on bad parameters.
    void prepare(const ProcessSpec& spec);
    void reset() noexcept;

    /// Launches the exciter at the contact point with `velocity` m/s towards the floor (adds to
    /// the current velocity when already in contact).
    void strike(double velocity) noexcept;
    /// Adds `velocity` to the exciter's downward velocity (an impulse from the leg).
    void kick(double deltaVelocity) noexcept {
        exciterV_ += deltaVelocity;
        awake_ = true;
    }

    /// Processes n samples: `externalForceN` (may be null = 0) pushes the exciter towards the
    /// floor; writes the listen pickup's velocity (m/s) into `out` (overwrites). Falling asleep
    /// is decided on the sleep grid (engine/dsp/SleepGrid.h), so the output does not depend on
    /// how the samples are cut into calls.
    void process(const float* externalForceN, float* out, int n) noexcept;
    /// n samples of silence while asleep with no push (what process() would do, without the
    /// output): keeps the sleep grid counting. Call only when isSleeping().
    void advanceAsleep(int n) noexcept;

    /// Output velocity (m/s) below which a free, untouched floor is considered silent.
    void setSleepVelocity(double v) noexcept { sleepVelocity_ = v; }
    /// True when nothing moves and nothing pushes: process() then costs almost nothing.
    bool isSleeping() const noexcept { return !awake_; }
    const ContactStats& stats() const noexcept { return stats_; }
    /// allowFreeRuns(false) steps free flight sample by sample, as before the runs (tests compare
    /// the two: the samples, the state and the statistics are the same).
    void allowFreeRuns(bool on) noexcept { freeRuns_ = on; }
    /// allowSubstepLoop(false) runs a sample's contact sub-steps through the general step one by
    /// one instead of the loop that keeps the state in registers (the Hertz law with Newton);
    /// tests compare the two: the samples, the state and the statistics are the same.
    void allowSubstepLoop(bool on) noexcept { substepLoop_ = on; }
    /// allowAvx(false): the SSE2 kernels (the resonator's and the sub-step loop's) even where the
    /// CPU has AVX; the samples are the same (tests).
    void allowAvx(bool on) noexcept { resonator_.allowAvx(on); }
    /// Kinetic energy of the exciter + modal energy of the floor + energy stored in the contact
    /// (the work it absorbed and has not yet returned), J.
    double totalEnergy() const noexcept;
    double exciterVelocity() const noexcept { return exciterV_; }
    /// Contact force of the last sample, N (never negative).
    double lastContactForce() const noexcept { return lastForce_; }
    double compression() const noexcept { return exciterX_ - resonator_.position(0); }
    const ModalResonatorT<Real>& resonator() const noexcept { return resonator_; }
    const ImpactParams& params() const noexcept { return params_; }

  private:
    double contactForce(double c, double cdot) const noexcept;
    // One internal step. With `abortOnContact`, returns false and commits nothing when the step
    // would touch (the caller then sub-steps it); otherwise commits and writes the output to y.
    bool step(double fextNow, double fextNext, bool abortOnContact, double& y) noexcept;
    // One trial of a step: the contact force held from n scaled by `held` (1 = as solved at n),
    // the new force at n+1 by `scale`; the sole's state at n+1, and (evaluateTrial) the bodies'
    // energy after it and the external force's work over the step.
    struct Trial {
        double force, x, v, energy, work;
    };
    Trial trialAt(double fextNow, double fextNext, double held, double scale) noexcept;
    void evaluateTrial(Trial& t, double fextNow, double fextNext) const noexcept;
    // Commits a step's trial t (`absorbed`: the energy the contact took in it) to the sole's
    // state (x, v), the last force, the contact's stored energy, the time and the contact flag,
    // and counts it in stats(): step() passes its members, the sub-step loop its registers.
    void commitStep(const Trial& t, double absorbed, double& x, double& v, double& last,
                    double& stored, double& time, bool& inContact) noexcept;
    // The passivity guard's correction of a step whose trial (1, 1) would return more energy than
    // the contact stored (rare: see step()); returns the passive trial, the resonator predicted
    // for it.
    [[gnu::noinline, gnu::cold]] Trial correctPassivity(double fextNow, double fextNext,
                                                        double bodiesBefore,
                                                        double tolerance) noexcept;
    void setFineRate(bool fine) noexcept;
    double solveForce(double ch, double dh) noexcept; // contact force at n+1
    void processSpan(const float* externalForceN, float* out, int n) noexcept;
    template <bool Single>
    double spanSamples(const float* externalForceN, float* out, int n) noexcept; // its peak
    // Samples [from, from + k) of a span as free flight over a ringing floor, run at once, when
    // the sole cannot touch the floor in them (see the .cpp); returns k (0: step sample by
    // sample) and the largest |output| of the run.
    struct FreeRun {
        int samples = 0;
        double peak = 0.0;
    };
    FreeRun runFree(const float* externalForceN, int from, int n, float* out) noexcept;
    [[gnu::noinline]] FreeRun runFreeTested(const float* externalForceN, int from, int most,
                                            float* out) noexcept;
    // (Out of line: inlined, its stores of the sole's neighbouring position and velocity made
    // GCC keep the two packed in one vector through runFree()'s loop, unpacking and repacking
    // them every sample.)
    [[gnu::noinline]] FreeRun commitFreeRun(int count, double x, double v, double last, double time,
                                            float* out) noexcept;
    /// One sample from external force f0 to f1 as contactSubsteps exact sub-steps (the rare
    /// path of spanSamples, kept out of its loop); y is the output after the last.
    [[gnu::noinline]] void substepSample(double f0, double f1, double& y) noexcept;
    // The sub-steps of substepSample for the Hertz law with Newton (the shipped contact): what
    // step() does for each, with the sole's state in registers and the resonator's pass and the
    // Newton solve inline (a strike's hot path); Wide: the AVX kernel.
    template <bool Wide>
    void substepLoop(double f0, double f1, double& y) noexcept;
    [[gnu::flatten]] void substepsGeneric(double f0, double f1, double& y) noexcept;
    [[gnu::flatten]] UNDERFOOT_TARGET_AVX void substepsAvx(double f0, double f1,
                                                           double& y) noexcept;
    void sleepDecision() noexcept; // at a grid point

    ImpactParams params_;
    ModalResonatorT<Real> resonator_;
    int listen_ = 0;
    double fs_ = 48000.0, internalFs_ = 48000.0, T_ = 1.0 / 48000.0;
    double exciterX_ = 0, exciterV_ = 0, lastForce_ = 0, lastExternal_ = 0;
    double contactEnergy_ = 0; // work absorbed by the open contact and not yet returned, J
    bool inContact_ = false, awake_ = false;
    int quietSamples_ = 0;
    SleepGrid sleepGrid_;               // sleep decided on a fixed grid from reset
    bool pushedSinceGridPoint_ = false; // an external force since the last grid point
    double peakSinceGridPoint_ = 0.0;   // largest |output| since the last grid point
    double sleepVelocity_ = 1e-10;
    double kc_ = 0, kd_ = 0; // instantaneous compliance and mobility of the compression
    // The Hertz law's Newton terms (see solveShaped): k mu; 1.5 kc and k mu kd at the current rate.
    double stiffMu_ = 0, hertzKc_ = 0, hertzKd_ = 0;
    // Per-step constants of the current rate (setFineRate) and the contact law's (prepare).
    struct StepConstants {
        // T^2 / 3, T^2 / 6, T^2 / 6M, T / 2M, T / 2, 1 / M: multiplications only, as the step's
        // chain from one contact force to the next runs through them (a division's latency is
        // several multiplications').
        double ttThird, ttSixth, xPerForce, vPerForce, halfT, perMass;
    };
    StepConstants stepConstants_{}, coarseConstants_{}, fineConstants_{};
    // The sole's position and velocity at n+1 from (x, v) under the accelerations aNow at n and
    // aNext at n+1 (linear in between), with no new contact force: step()'s trials and
    // runFree's flight, the same operations. In the position aNow (which holds the last contact
    // force) is added last, so that the rest is computed while that force is solved. (Written
    // through references: returned as a pair, GCC packed the two into one vector and shuffled them
    // every sample.)
    static void soleWithoutContact(const StepConstants& c, double T, double x, double v,
                                   double aNow, double aNext, double& xNext,
                                   double& vNext) noexcept {
        xNext = (x + T * v + c.ttSixth * aNext) + c.ttThird * aNow;
        vNext = v + c.halfT * (aNow + aNext);
    }
    // One sample of a free run's flight (runFree, runFreeTested): what spanSamples' advance()
    // and step()'s trial(1, 1) compute for it, the external force going from `last` to fNext
    // and the held force `held` (0 in a free run).
    static void soleInFreeRun(const StepConstants& c, double T, double held, double last,
                              double fNext, double x, double v, double& xNext,
                              double& vNext) noexcept {
        const double f1 = last + (fNext - last);
        const double aNow = (last - 1.0 * held) * c.perMass;
        soleWithoutContact(c, T, x, v, aNow, f1 * c.perMass, xNext, vNext);
    }
    double stiffness_ = 0, dissipation_ = 0;
    enum class Shape { Linear, Hertz, Square, General };
    Shape shape_ = Shape::Hertz;
    template <Shape S>
    double contactForceOf(double c, double cdot) const noexcept;
    // For c > 0: also c^alpha (ca) and alpha c^(alpha - 1) (slope), for Newton's derivative
    // (not Hertz: hertzLaw).
    template <Shape S>
    double contactForceOf(double c, double cdot, double& ca, double& slope) const noexcept;
    template <Shape S>
    double solveShaped(double ch, double dh, double start) noexcept; // solveForce(), one law
    // The Hertz law at c > 0; also sqrt(c) and k (1 + mu cdot), for Newton's slope.
    double hertzLaw(double c, double cdot, double& root, double& stiff) const noexcept;
    template <typename F>
    decltype(auto) withShape(F&& f) const; // f(std::integral_constant<Shape, shape_>)
    double coarseT_ = 0, coarseKc_ = 0, coarseKd_ = 0, fineT_ = 0, fineKc_ = 0, fineKd_ = 0;
    Butterworth decimator_;
    ContactStats stats_;
    double contactStart_ = 0, time_ = 0;
    bool freeRuns_ = true;
    bool substepLoop_ = true;
    static constexpr int kFreeRetrySamples = 8; // samples stepped after a failed runFree()
    int freeRetryIn_ = 0;
    // A sample whose contact force changed by more than kSubstepNextFactor x the sub-step
    // threshold is followed by a sub-stepped sample without its single-step trial (spanSamples).
    static constexpr double kSubstepNextFactor = 4.0;
    bool substepNext_ = false;
    // Sub-steps: Newton's start (negative: the last force) and the forces of the two sub-steps
    // before the last one (0: none), for the extrapolation in substepSample.
    double newtonStart_ = -1.0, subForce1_ = 0.0, subForce2_ = 0.0;
    // runFree's scratch: the floor's output velocity, the sole's position and velocity
    double freeVelocity_[ModalResonatorT<Real>::kFreeRunMax];
    double soleX_[ModalResonatorT<Real>::kFreeRunMax], soleV_[ModalResonatorT<Real>::kFreeRunMax];
};

using HuntCrossleyImpact = HuntCrossleyImpactT<double>;

} // namespace underfoot::engine
