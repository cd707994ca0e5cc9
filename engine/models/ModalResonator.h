// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Modal resonator: a bank of damped oscillators seen through "pickup" points.
///
/// Physics (docs/explanation/models.md; Adrien 1991; Avanzini & Rocchesso, DAFx 2001): mode i has
/// modal coordinate q_i obeying  m_i (q_i'' + 2 s_i q_i' + w0_i^2 q_i) = sum_p g[p][i] F_p,  where
/// s_i = ln(1000) / T60_i and w0_i^2 = (2 pi f_i)^2 + s_i^2, so that the free response is
/// exp(-s_i t) sin(2 pi f_i t): it rings at exactly f_i and decays by 60 dB in exactly T60_i.
/// The displacement at pickup p is x_p = sum_i g[p][i] q_i.
///
/// Discretisation: the exact state transition of each oscillator (matrix exponential, i.e.
/// impulse invariance of the free response) with the force taken as linear between samples
/// (first-order hold). Then  s[n+1] = A s[n] + B0 u[n] + B1 u[n+1],  which is exact for
/// piecewise-linear forces, unconditionally stable, and keeps an *instantaneous* term B1 that
/// lets an interactor (impact, friction) solve its force implicitly at n+1 (the K-method of
/// Borin, De Poli & Rocchesso 2000).
///
/// Modes at or above Nyquist cannot ring at their frequency without aliasing. Instead of
/// dropping them (as the Sound Design Toolkit does above acos(-0.9995)), they are kept as their
/// quasi-static compliance q = u / w0^2: for excitation far below their frequency this is their
/// exact response, so the contact still "sees" their stiffness. They do not radiate. Their count
/// is reported by quasiStaticModeCount(); oversampling brings them back as ringing modes.
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Simd.h"

#include <cstddef>
#include <span>
#include <vector>

namespace underfoot::engine {

/// One mode of a resonator, in physical units.
struct Mode {
    double frequencyHz = 440.0; ///< damped frequency at which it rings
    double t60Seconds = 0.5;    ///< time to decay by 60 dB
    double massKg = 1.0;        ///< modal mass (larger = less displacement for a force)
};

/// Per-mode coefficients of the exact FOH discretisation (see file comment).
struct ModeCoefficients {
    double a00, a01, a10, a11; ///< homogeneous transition of [q, v]
    double b0x, b0v;           ///< response to u[n]
    double b1x, b1v;           ///< instantaneous response to u[n+1]
    bool quasiStatic;          ///< mode at/above Nyquist, kept as a compliance
};

/// Computes the exact discretisation of one mode at a sample rate (per unit of u = F g / m).
/// The mode is kept quasi-static when its frequency is at or above `quasiStaticFromHz`
/// (default, <= 0: the Nyquist frequency of `sampleRateHz`).
ModeCoefficients computeModeCoefficients(const Mode& mode, double sampleRateHz,
                                         double quasiStaticFromHz = 0.0);

template <typename Real>
class ModalResonatorT {
  public:
    /// Sets modes and pickup gains `gains[p][i]` (allocates). Throws std::invalid_argument for
    /// non-finite or non-positive frequencies, decays or masses.
    void configure(std::vector<Mode> modes, std::vector<std::vector<double>> gains);
    /// Computes coefficients for a sample rate (allocates). With `fineSubsteps` > 1 a second
    /// set is computed for steps of 1/(fineSubsteps * sampleRateHz), selectable per step with
    /// setFineRate(): the impact sub-steps only the samples in contact. Both sets are exact
    /// discretisations of the same oscillators, so the state carries over between them; a mode
    /// is quasi-static in both when it is at or above the coarse rate's Nyquist frequency.
    void prepare(double sampleRateHz, int fineSubsteps = 1);
    /// Selects the fine (true) or coarse (false) coefficient set for the following steps.
    void setFineRate(bool fine) noexcept {
        const bool f = fine && !fineCoefficients_.empty();
        if (f != fine_) {
            settle(); // a deferred commit uses the coefficients of the rate it was made at
            predictedEnergyValid_ = false;
        }
        fine_ = f;
    }
    /// With tracking on, predict() also computes the prediction's energy terms while a force is
    /// held, so that energyIfCommitted(0, F) and the energy() after commit(0, F) cost O(1) (the
    /// impact's passivity guard in sustained contact). Off by default (friction does not need it).
    void setEnergyTracking(bool on) noexcept { trackEnergy_ = on; }
    bool fineRate() const noexcept { return fine_; }
    /// The per-mode loops run four modes per step: as one AVX vector where the CPU has AVX (chosen
    /// in prepare()), else as two SSE2 pairs. Both do the same IEEE operations per mode (no FMA)
    /// and add the four lanes' partial sums in the same order, so the samples are bit-identical;
    /// allowAvx(false) selects the SSE2 kernels (tests compare the two).
    void allowAvx(bool on) noexcept;
    bool usesAvx() const noexcept { return passes_ == kPasses[1]; }
    void reset() noexcept;

    int modeCount() const noexcept { return static_cast<int>(modes_.size()); }
    int pickupCount() const noexcept { return static_cast<int>(gains_.size()); }
    int quasiStaticModeCount() const noexcept { return quasiStaticCount_; }
    const std::vector<Mode>& modes() const noexcept { return modes_; }
    double sampleRateHz() const noexcept { return sampleRateHz_; }

    // ---- one sample, in two halves, for interactors that solve their force implicitly ----
    /// Advances every mode by one sample assuming no *new* force at n+1 (the last committed
    /// force still acts through B0). Afterwards predictedPosition/Velocity(p) are valid.
    /// `heldScale` scales the force held from the previous sample (1 = as committed); the
    /// impact's passivity guard uses smaller values.
    void predict(double heldScale = 1.0) noexcept {
        predictedEnergyValid_ = false;
        if (pending_ && heldScale == 0.0) settle(); // (the passivity guard's trials; rare)
        const int variant = passVariant(heldScale);
        pending_ = false;
        passes_[variant](*this, static_cast<Real>(heldScale));
    }
    /// predict() (held scale 1) with the pass inlined into the caller, for a loop that runs it
    /// many times in a row (the impact's contact sub-steps, friction's per-sample kernel): Wide
    /// = true for a caller compiled with AVX (usesAvx()), false otherwise. The same values as
    /// predict(). Defined in engine/models/ModalKernels.h.
    template <bool Wide>
    void predictInline() noexcept;
    double predictedPosition(int p) const noexcept {
        return p == 0 ? predictedX0_ : predictedSum(qh_, p);
    }
    double predictedVelocity(int p) const noexcept {
        return p == 0 ? predictedV0_ : predictedSum(vh_, p);
    }
    /// Instantaneous displacement / velocity at pickup p per newton applied at pickup p at n+1.
    double compliance(int p) const noexcept {
        return (fine_ ? kxFine_ : kx_)[static_cast<std::size_t>(p)];
    }
    double mobility(int p) const noexcept {
        return (fine_ ? kvFine_ : kv_)[static_cast<std::size_t>(p)];
    }
    /// Energy the modes would hold after commit(p, forceN), without committing (for p = 0 one pass
    /// over the modes per prediction, then O(1) per force).
    double energyIfCommitted(int p, double forceN) const noexcept {
        if (p == 0 && predictedEnergyValid_)
            return predictedEnergy_ + forceN * predictedEnergySlope_ + forceN * forceN * bank().c2;
        return energyIfCommittedSlow(p, forceN);
    }
    /// Completes the sample with force `forceN` acting at pickup p (at n+1). The pickup sums
    /// (position(0), contactVelocity(), the output pickup's velocity) and the tracked energy are
    /// known at once; the per-mode update is deferred into the next predict(), which then makes
    /// one pass over the modes per sample (the same operations in the same order as a separate
    /// pass: the same values). Anything else that reads the modes completes it first.
    void commit(int p, double forceN) noexcept {
        settle();
        if (forceN == 0.0) return commitWithoutForce();
        heldZero_ = false;
        const std::size_t pp = static_cast<std::size_t>(p);
        const Bank& b = bank();
        // The per-mode update q = qh + b1x u, v = vh + b1v u, u = F g / m is deferred into the
        // next predict() (or settle()).
        pending_ = true;
        pendingForce_ = static_cast<Real>(forceN);
        pendingPickup_ = pp;
        // The pickup sums are linear in the force: the prediction's plus the force times the sums
        // of the instantaneous responses (no pass over the modes).
        x0_ = predictedX0_ + forceN * b.dx0[pp];
        v0_ = predictedV0_ + forceN * b.dv0[pp];
        outputVelocity_ = predictedVo_ + forceN * b.dvo[pp];
        energyValid_ = p == 0 && predictedEnergyValid_;
        if (energyValid_)
            committedEnergy_ =
                predictedEnergy_ + forceN * predictedEnergySlope_ + forceN * forceN * b.c2;
        predictedEnergyValid_ = false;
    }

    /// The pickup whose velocity velocity(p) returns fastest (computed during commit()).
    void setOutputPickup(int p);

    // ---- after commit ----
    double position(int p) const noexcept {
        if (p == 0) return x0_;
        settle();
        return pickupSum(q_, p, false);
    }
    /// Velocity of the contact point (pickup 0), all modes included (computed by commit()).
    double contactVelocity() const noexcept { return v0_; }
    double velocity(int p) const noexcept {
        // Quasi-static modes do not radiate (their "velocity" is a finite difference).
        if (p == outputPickup_) return outputVelocity_;
        settle();
        return pickupSum(v_, p, true);
    }
    /// Mechanical energy stored in the modes (kinetic + potential), joules.
    double energy() const noexcept {
        // Known in O(1) after a commit whose prediction tracked the energy (setEnergyTracking).
        return energyValid_ ? committedEnergy_ : energyLoop();
    }

    // ---- free ringing over a run of samples ----
    /// Most samples one ringFree() call runs.
    static constexpr int kFreeRunMax = 64;
    /// True when no force is held or pending and the coarse rate is selected: ringFree() may run.
    bool ringsFree() const noexcept { return heldZero_ && !pending_ && !fine_; }
    int outputPickup() const noexcept { return outputPickup_; }
    /// n samples (1..kFreeRunMax) of free ringing: what n calls of predict() then commit(p, 0)
    /// give, bit for bit (the same operations per mode, the pickup sums added in the same
    /// order), with each quad of modes kept in registers over the run. outputVelocity[t] is
    /// sample t's velocity(outputPickup()) after the commit. Requires ringsFree().
    void ringFree(int n, double* outputVelocity) noexcept { ring_(*this, n, outputVelocity); }
    /// Free ringing while a body at soleX[t] (t = 0 .. n - 1, n <= kFreeRunMax) stays clear of
    /// the contact point: stops before the first sample t whose predicted contact position x0
    /// gives !(soleX[t] - x0 <= 0), the test the impact's step makes (compression soleX - x0 > 0:
    /// contact) on the same x0, bit for bit. Returns the samples run, each what
    /// predict() then commit(p, 0) gives (as ringFree, outputVelocity[t] likewise); 0 when the
    /// first sample would touch. Requires ringsFree(). For the samples right after a contact,
    /// where freeContactBound() is too loose to allow a run. Runs in chunks of kTestedChunk
    /// samples, each as ringFree runs (every quad of modes in registers over the chunk) with the
    /// contact positions summed per sample: a chunk in which the body touches is not committed
    /// and its samples before the touch are run again by ringFree.
    int ringFreeUntilContact(int n, const double* soleX, double* outputVelocity) noexcept {
        int done = 0;
        while (done < n) {
            const int m = n - done < kTestedChunk ? n - done : kTestedChunk;
            const int t = ringChecked_(*this, m, soleX + done, outputVelocity + done);
            if (t < m) {
                if (t > 0) ring_(*this, t, outputVelocity + done);
                return done + t;
            }
            done += m;
        }
        return done;
    }
    /// Samples per chunk of ringFreeUntilContact: a touch wastes at most this many.
    static constexpr int kTestedChunk = 16;
    /// A bound on |predictedPosition(0)| over every later sample of free ringing from the
    /// current state: the sum over the modes of |g0| sqrt(q^2 + v^2 / w0^2) (a freely ringing
    /// mode's energy never grows; the discretisation samples its trajectory exactly).
    double freeContactBound() const noexcept;

    /// Convenience: one full sample with an external force at pickup `p`; returns velocity at
    /// pickup `listen`.
    double processSample(int p, double forceN, int listen) noexcept {
        predict();
        commit(p, forceN);
        return velocity(listen);
    }

    /// Zeroes denormal-sized state (call once per block).
    void flushTinyState() noexcept;
    /// Largest |velocity| over modes: used to decide when the resonator has decayed to silence.
    double peakModalVelocity() const noexcept;

  private:
    // Coefficients of one rate as structure of arrays (contiguous per coefficient, so that the
    // per-mode loops are plain multiply-adds over arrays), stored in Real as the loops use them.
    // The hot loops read four modes at a time from one aligned record per quad (few pointers, so
    // the loop keeps everything in registers, and aligned SIMD operands).
    struct alignas(32) QuadCoefficients {
        Real a00[4], a01[4], a10[4], a11[4], b0x[4], b0v[4], b1x[4], b1v[4];
        double lv[4], lx[4];
    };
    struct alignas(32) QuadGains {
        double g0[4], go[4], kin[4], pot[4]; // pickup 0, output pickup, 0.5 m, 0.5 m w0^2
    };
    // The pass over the modes that predict() runs: 9 variants (see the .cpp) x 2 kernels (SSE2
    // pairs, AVX: passBody<Wide = true>), chosen per call from a table of plain function pointers.
    using PassFn = void (*)(ModalResonatorT&, Real) noexcept;
    // The pass predict(heldScale) runs: 4 energy + 2 fused + held, or 8 for free ringing (the
    // index into kPasses[kernel]; predictInline selects the same pass by it).
    int passVariant(double heldScale) const noexcept {
        if (heldZero_ || heldScale == 0.0) return 8;
        return (trackEnergy_ ? 4 : 0) + (pending_ ? 2 : 0) + (heldScale != 1.0 ? 1 : 0);
    }
    template <bool Energy, bool Fused, bool Held, bool Free>
    static void passGeneric(ModalResonatorT& r, Real h) noexcept;
    template <bool Energy, bool Fused, bool Held, bool Free>
    static void passAvx(ModalResonatorT& r, Real h) noexcept;
    template <bool Wide, bool Energy, bool Fused, bool Held, bool Free>
    void passBody(Real h) noexcept;
    static const PassFn kPasses[2][9];
    const PassFn* passes_ = kPasses[0]; // the kernel in use: kPasses[1] is AVX
    // Free ringing over a run (ringFree), in the same two kernels.
    using RingFn = void (*)(ModalResonatorT&, int, double*) noexcept;
    static void ringGeneric(ModalResonatorT& r, int n, double* vo) noexcept;
    // (the target on the declaration too: see UNDERFOOT_TARGET_AVX)
    UNDERFOOT_TARGET_AVX static void ringAvx(ModalResonatorT& r, int n, double* vo) noexcept;
    // Check: also the contact positions per sample, tested against soleX; a run in which the
    // body would touch returns the samples before the touch and commits nothing.
    template <bool Wide, bool Check>
    int ringBody(int n, const double* soleX, double* vo) noexcept;
    RingFn ring_ = &ringGeneric;
    // One chunk of ringFreeUntilContact (ringBody<Wide, true>), in the same two kernels.
    using RingCheckedFn = int (*)(ModalResonatorT&, int, const double*, double*) noexcept;
    static int ringCheckedGeneric(ModalResonatorT& r, int n, const double* soleX,
                                  double* vo) noexcept;
    UNDERFOOT_TARGET_AVX static int ringCheckedAvx(ModalResonatorT& r, int n, const double* soleX,
                                                   double* vo) noexcept;
    RingCheckedFn ringChecked_ = &ringCheckedGeneric;
    std::vector<double> runSums_;  // a run's per-lane output-pickup sums: [sample][lane]
    std::vector<double> runSums0_; // and contact-pickup sums (ringFreeUntilContact's chunks)
    void commitWithoutForce() noexcept;
    struct Bank {
        std::vector<Real> a00, a01, a10, a11, b0x, b0v, b1x, b1v;
        std::vector<QuadCoefficients> quads; // the same values, four modes per record
        // Energy of the modes after commit(0, F) as a quadratic in F around the prediction:
        // E(F) = E_h + F sum(lv vh + lx qh) + F^2 c2 (double, per mode; see energyIfCommitted).
        std::vector<double> lv, lx;
        double c2 = 0.0;
        // Pickup sums of the instantaneous response to a force at pickup p (per pickup):
        // x0 += F dx0[p], v0 += F dv0[p], output velocity += F dvo[p].
        std::vector<double> dx0, dv0, dvo;
        void assign(std::size_t modes, std::size_t pickups);
    };
    void fillBank(Bank& bank, const std::vector<ModeCoefficients>& c);
    const Bank& bank() const noexcept { return fine_ ? fineBank_ : coarseBank_; }
    double energyLoop() const noexcept;
    /// Applies a commit() deferred into the next predict() (see commit()).
    void settle() const noexcept {
        if (pending_) applyPending();
    }
    void applyPending() const noexcept;
    double energyIfCommittedSlow(int p, double forceN) const noexcept;
    double predictedSum(const std::vector<Real>& x, int p) const noexcept {
        return pickupSum(x, p, false);
    }
    double pickupSum(const std::vector<Real>& x, int p, bool radiatingOnly) const noexcept;

    std::vector<Mode> modes_;
    std::vector<std::vector<double>> gains_; // [pickup][mode]
    std::vector<ModeCoefficients> coefficients_;
    std::vector<ModeCoefficients> fineCoefficients_; // empty unless prepared with sub-steps
    Bank coarseBank_, fineBank_;
    std::vector<QuadGains> quadGains_;
    bool avxAllowed_ = true; // allowAvx(false): the SSE2 kernels even where the CPU has AVX
    bool fine_ = false;
    // Per-mode arrays are padded to a multiple of four (four modes per SIMD step, see the .cpp)
    // with modes whose coefficients and gains are zero.
    std::vector<Real> gainOverMass_; // [pickup * padded modes + mode] = g[p][i] / m_i
    // State, prediction, last generalized force. q_, v_, u_ may lag a commit() by one deferred
    // update (pending_): settle() completes it, also from const readers, hence mutable.
    mutable std::vector<Real> q_, v_, u_;
    std::vector<Real> qh_, vh_;
    mutable bool pending_ = false;
    Real pendingForce_ = Real(0);
    std::size_t pendingPickup_ = 0;
    std::vector<double> kx_, kv_;             // per pickup
    std::vector<double> kxFine_, kvFine_;     // per pickup, fine rate
    std::vector<double> w0sq_;                // undamped angular frequency squared, per mode
    std::vector<double> kinetic_, potential_; // 0.5 m_i (0 when quasi-static), 0.5 m_i w0_i^2
    double sampleRateHz_ = 0.0;
    double predictedX0_ = 0.0, predictedV0_ = 0.0; // pickup 0, computed by predict()
    double predictedVo_ = 0.0;                     // output pickup, computed by predict()
    bool heldZero_ = true; // every u_ is zero (free ringing): predict/commit skip the force terms
    // Energy bookkeeping (setEnergyTracking): predict() computes the prediction's energy E_h and
    // the linear coefficient of E(F) when a force is held; commit(0, F) then knows the committed
    // energy in O(1), so energy() and energyIfCommitted() need no pass over the modes.
    bool trackEnergy_ = false;
    mutable bool predictedEnergyValid_ = false;
    mutable double predictedEnergy_ = 0.0, predictedEnergySlope_ = 0.0;
    bool energyValid_ = true; // committedEnergy_ is the energy of (q_, v_)
    double committedEnergy_ = 0.0;
    double x0_ = 0.0, v0_ = 0.0, outputVelocity_ = 0.0; // computed by commit()
    int outputPickup_ = 0;
    std::vector<double> outGain_;     // output pickup's gains, 0 for non-radiating modes
    std::vector<double> contactGain_; // pickup 0's gains (padded like the state)
    int quasiStaticCount_ = 0;
};

// Defined in ModalResonator.cpp (with the pass table kPasses the inline predict() reads).
extern template class ModalResonatorT<double>;
extern template class ModalResonatorT<float>;

using ModalResonator = ModalResonatorT<double>;

} // namespace underfoot::engine
