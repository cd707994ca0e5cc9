// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Elasto-plastic friction between an inertial exciter (the sole, or a board edge) and a modal
/// resonator (the boards), after Dupont, Hayward, Armstrong & Altpeter, "Single state
/// elastoplastic friction models", IEEE Trans. Automatic Control 47(5), 2002, as used for
/// creaking sounds by Avanzini, Serafin & Rocchesso (2005) and the Sound Design Toolkit.
///
///   f = sigma0 z + sigma1 z' + sigma2 v + sigma3 w          (w: uniform noise, roughness)
///   z' = v (1 - alpha(z, v) z / z_ss(v))
///   z_ss(v) = sgn(v) [f_c + (f_s - f_c) exp(-(v/v_s)^2)] / sigma0   (Stribeck)
///   alpha = 0 for |z| <= z_ba (pure stick), 1 for |z| >= |z_ss|, a raised sine in between,
///   and 0 when z and v have opposite signs.
/// f_c = mu_d N and f_s = mu_s N follow the normal force N (here: the GRF).
///
/// Discretisation: the exciter and the resonator respond to the friction force at n+1 through
/// their instantaneous mobilities (exact first-order-hold integration, as in Impact.h); the
/// bristle state is integrated with backward Euler (alpha taken at z_n), which is unconditionally
/// stable — the forward Euler of the Sound Design Toolkit blows up for sigma0 above ~5e7. The
/// relative velocity at n+1 follows in closed form once the plastic rate p = alpha v / z_ss is
/// fixed (a "plain pass"); the solution is the fixed point of p. Shipped :
/// safeguarded Newton on p with the analytic derivatives of the Stribeck curve and the raised
/// sine, warm-started from the last three samples' p and kept in a bracket (bisection or a plain
/// pass when a step leaves it); it stops when a step moved v and z by at most
/// `newtonStepTolerance` (1e-3, relative; Newton's error after that step is of the order of its
/// square), or when the error left, estimated from the step and the steps' contraction, is
/// within `tolerance` (the plain passes' criterion), at most `maxIterations` evaluations (bounded
/// work; cap hits counted in `solveStats()`). Every iterate's output is a plain pass (z1 =
/// (z0 + T v1) / (1 + T p), p >= 0: stable whatever p), so stopping early costs accuracy, never
/// stability. On the creak: 1.08 evaluations a sample, a plain pass from every returned solution
/// moves it by <= 3e-7 relative, and the creak is within 0.001 dB of the 50-pass reference;
/// with newtonStepTolerance = 0 (the tight solve): 1.99 evaluations, < 1e-15 (tests
/// ElastoPlasticFriction.NewtonSolutionMeetsThePlainPassCriterionOnEverySample,
/// ShippedSolveEqualsTheFiftyPassReferenceOnTheCreak).
/// `newton = false` keeps the fixed-point passes (warm start, Aitken extrapolation; friction5:
/// ~6.3 passes a sample to 1e-12) and, with warmStart/extrapolate off, the 50-pass reference.
#include "engine/dsp/Random.h"
#include "engine/models/ModalResonator.h"

#include <cstdint>
#include <cstring>

namespace underfoot::engine {

struct FrictionParams {
    double sigma0 = 1e5;             ///< bristle stiffness, N/m
    double sigma1 = 300.0;           ///< bristle damping, N s/m
    double sigma2 = 0.5;             ///< viscous friction, N s/m
    double sigma3 = 0.0;             ///< noise (roughness) amplitude, N
    double staticCoefficient = 0.6;  ///< mu_s: static friction per newton of normal force
    double dynamicCoefficient = 0.3; ///< mu_d: Coulomb friction per newton of normal force
    double stribeckVelocity = 0.05;  ///< v_s, m/s
    double breakAway = 0.7;          ///< z_ba as a fraction of the static deflection f_c / sigma0
    double exciterMassKg = 0.05;     ///< mass of the rubbing body
    double driveStiffness = 0.0;     ///< N/m: spring dragging the rubbing body from an anchor
    double driveDamping = 0.0;       ///< N s/m: damper in parallel with that spring
    /// Cap on the fixed-point passes per sample (bounded work). The solve stops earlier once a
    /// pass moves the relative velocity by at most tolerance * max(|v|, stribeckVelocity) and the
    /// bristle by at most tolerance * max(|z|, T stribeckVelocity). A sample that reaches the
    /// cap keeps its last pass and is counted in solveStats().capHits.
    int maxIterations = 16;
    double tolerance = 1e-12; ///< relative convergence criterion of the passes (>= 0)
    /// Newton (newton = true) also stops after a step that moved v and z by at most this,
    /// relative to the same scales as `tolerance`. Newton's error after a step is of the order
    /// of the step squared, so the solution returned (the pass at the new p) is far closer than
    /// the step: on the creak, a step of at most 1e-3 leaves a plain-pass residual of at most
    /// 3e-7 (a few float ulps of the output) and the creak within 0.001 dB of the 50-pass
    /// reference, in 1.08 evaluations a sample instead of 1.99. 0: stop only on
    /// `tolerance` (the tight solve; residual < 1e-15 on the creak).
    double newtonStepTolerance = 1e-3;
    /// true: the first trial is the previous sample's relative velocity; false: the prediction
    /// without friction (the solve before friction5, which with a few passes is not converged; kept
    /// for reference renders).
    bool warmStart = true;
    /// true: Aitken extrapolation of the trial after every two plain passes; false: plain
    /// fixed-point passes only (the reference; same fixed point, ~2x the passes).
    bool extrapolate = true;
    /// true (shipped): safeguarded Newton on the scalar plastic rate p = alpha v / z_ss with the
    /// analytic derivatives (Stribeck exp, raised sine), kept in a bracket (bisection or a plain
    /// pass when a step leaves it); every Newton iterate is checked by one plain pass with the
    /// same criterion, and that pass is the output. false: the fixed-point passes above
    /// (warmStart / extrapolate; the reference). warmStart starts Newton from the previous
    /// sample's p.
    bool newton = true;
    /// true: the Stribeck exp and the raised sine from libm (the reference, slower); false: the
    /// bounded-error polynomials frictionExpNeg / frictionSinHalfPi (relative error < 1e-15).
    bool libmFunctions = false;
};

// Bounded-error replacements of the two libm calls of the fixed point (~200
// instructions a sample in libm). Plain double arithmetic without FMA: the same values on every
// x86-64 machine. Errors measured by test FrictionFunctions.ErrorsStayWithinTheirStatedBounds.

/// 2^(j / 256) for j = 0 .. 255, correctly rounded (generated with 60-digit decimal arithmetic).
extern const double kFrictionExp2Table[256];

/// exp(y) for y <= 0, relative error < 1e-15 (0 below -708). Deterministic (no FMA, no libm):
/// y = (256 k + j) ln2 / 256 + r with |r| <= ln2 / 512 (ln2 / 256 split in two so that the
/// product is exact for |k| < 2^18), e^r by its Taylor polynomial of degree 4 (remainder
/// < 4e-17), 2^(j/256) from a table of correctly rounded values and 2^k put into the exponent
/// bits.
[[gnu::always_inline]] inline double frictionExpNeg(double y) noexcept {
    if (!(y > -708.0)) return 0.0;
    constexpr double nOverLn2 = 369.3299304675746, ln2hi = 0.0027076061741126978,
                     ln2lo = -5.0411407304988844e-14;
    constexpr double shifter = 6755399441055744.0; // 1.5 * 2^52: adding it rounds to an integer
    const double kd = (y * nOverLn2 + shifter) - shifter;
    const double r = (y - kd * ln2hi) - kd * ln2lo;
    // 1 + r + r^2 / 2 + r^3 / 6 + r^4 / 24 as (1 + r) + r^2 ((1/2 + r / 6) + r^2 / 24) (Estrin's
    // scheme: 5 dependent operations after r instead of Horner's 8; the friction's per-sample
    // solve waits for this value)
    const double r2 = r * r;
    const double p = (1.0 + r) + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * (1.0 / 24.0));
    const std::int64_t k = static_cast<std::int64_t>(kd);
    const std::int64_t bits = ((k >> 8) + 1023) << 52; // (arithmetic shift: floor(k / 256))
    double scale;
    std::memcpy(&scale, &bits, sizeof scale);
    return p * (kFrictionExp2Table[k & 255] * scale);
}

/// sin(pi t / 2) for |t| <= 1, absolute error < 1e-15. Deterministic (no FMA, no libm).
[[gnu::always_inline]] inline double frictionSinHalfPi(double t) noexcept {
    // sin(pi t / 2) for |t| <= 1: t P(t^2), P the degree-7 Chebyshev fit of
    // sin(pi sqrt(u) / 2) / sqrt(u) on [0, 1] (mpmath chebyfit, fit error 1.8e-16). Absolute
    // error below 1e-15 (6.7e-16 against libm over the test's 2,000,001 points). Estrin's scheme
    // (u, u^2, u^4 and four pairs in parallel): 6 dependent operations after u instead of
    // Horner's 15.
    const double u = t * t, u2 = u * u, u4 = u2 * u2;
    const double q01 = 1.5707963267948964394 - 0.64596409750622322784 * u;
    const double q23 = 0.079692626245683363428 - 0.0046817541314470625397 * u;
    const double q45 = 0.00016044116956310630257 - 3.5988107063136795291e-6 * u;
    const double q67 = 5.6883180640177953288e-8 - 6.4494712378091340345e-10 * u;
    return t * ((q01 + q23 * u2) + (q45 + q67 * u2) * u4);
}

/// cos(pi t / 2) for |t| <= 1, absolute error < 1e-15. Deterministic (no FMA, no libm).
[[gnu::always_inline]] inline double frictionCosHalfPi(double t) noexcept {
    // Q(t^2), Q the degree-8 Chebyshev interpolant of cos(pi sqrt(u) / 2) on [0, 1] (nodes and
    // coefficients in 60-digit decimal arithmetic, rounded to double:
    // tools/perf/friction_cos_fit.py). Evaluated as here, 3.1e-16 at most against libm over the
    // test's 2,000,001 points. Estrin's scheme, as frictionSinHalfPi: both can run side by side
    // from the same u.
    const double u = t * t, u2 = u * u, u4 = u2 * u2;
    const double q01 = 1.0 - 1.233700550136169 * u;
    const double q23 = 0.25366950790103104 - 0.02086348076317886 * u;
    const double q45 = 0.0009192602739434877 - 2.5202039782228713e-05 * u;
    const double q67 = 4.7108307433635577e-07 - 6.382235924529259e-09 * u;
    return (q01 + q23 * u2) + ((q45 + q67 * u2) + 6.3317327178079e-11 * u4) * u4;
}

/// How the per-sample fixed point went since the last reset (samples in contact only). Counting
/// costs a few additions; the audio thread only increments it.
struct FrictionSolveStats {
    std::uint64_t samples = 0; ///< samples solved in contact
    std::uint64_t passes = 0;  ///< fixed-point passes over those samples
    std::uint64_t capHits = 0; ///< samples that used maxIterations passes without converging
    int maxPassesInOneSample = 0;
};

template <typename Real>
class ElastoPlasticFrictionT {
  public:
    void configure(const FrictionParams& params, std::vector<Mode> modes,
                   std::vector<std::vector<double>> gains);
    void prepare(double sampleRateHz);
    void reset(std::uint64_t seed) noexcept;

    /// One sample: `normalForceN` presses the bodies together, `driveForceN` pushes the exciter
    /// tangentially and the drive spring/damper pulls it towards an anchor at `anchorPosition`
    /// moving at `anchorVelocity` (integrated implicitly: an explicit stiff drag would delay its
    /// force by a sample and pump energy in). `roughness` scales the roughness noise sigma3 w at
    /// this sample (1: as configured; 0: the surfaces are not being rubbed, no noise and no draw
    /// from the generator; a caller that knows when the surfaces are rubbed, as the friction
    /// layer does, lets a contact at rest ring out instead of hissing for ever). Returns the
    /// resonator's velocity at pickup 0 (m/s).
    double processSample(double normalForceN, double driveForceN, double anchorPosition = 0.0,
                         double anchorVelocity = 0.0, double roughness = 1.0) noexcept {
        return kernel_(*this, normalForceN, driveForceN, anchorPosition, anchorVelocity, roughness);
    }
    /// allowAvx(false) selects the SSE2 build of the per-sample kernel (and of the resonator's);
    /// with AVX (VEX-encoded scalar code, no FMA) the samples are the same bit for bit.
    void allowAvx(bool on) noexcept;
    bool usesAvx() const noexcept;

    /// Unloaded surfaces: the bristles relax and the rubbing mass stops (keeps the ringing).
    void relax() noexcept {
        z_ = exciterV_ = force_ = lastExternal_ = v_ = p_ = pPrev_ = pPrev2_ = 0.0;
    }
    double frictionForce() const noexcept { return force_; }
    double bristle() const noexcept { return z_; }
    double relativeVelocity() const noexcept { return v_; }
    double exciterVelocity() const noexcept { return exciterV_; }
    double exciterPosition() const noexcept { return exciterX_; }
    const FrictionSolveStats& solveStats() const noexcept { return stats_; }
    /// With tracking on (off by default: it costs a few stores a sample), lastSolveResidual()
    /// tells how far the last sample's Newton solution is from the fixed point: the move of one
    /// plain pass from it, max(|dv| / max(|v|, v_s), |dz| / max(|z|, T v_s)) (the convergence
    /// criterion's measure, to compare with `tolerance`). 0 without contact, without tracking
    /// or with the fixed-point solver (newton = false). For tests.
    void setResidualTracking(bool on) noexcept {
        trackResidual_ = on;
        in_ = SolveInput{};
    }
    double lastSolveResidual() const noexcept;
    const ModalResonatorT<Real>& resonator() const noexcept { return resonator_; }
    ModalResonatorT<Real>& resonator() noexcept { return resonator_; }

  private:
    using Kernel = double (*)(ElastoPlasticFrictionT&, double, double, double, double,
                              double) noexcept;
    // (Wide: the resonator's pass inline with its AVX kernel, for kernelAvx)
    template <bool Libm, bool Wide>
    double processBody(double normal, double drive, double anchorX, double anchorV,
                       double roughness) noexcept;
    template <bool Libm>
    static double kernelGeneric(ElastoPlasticFrictionT& f, double normal, double drive,
                                double anchorX, double anchorV, double roughness) noexcept;
    template <bool Libm>
    static double kernelAvx(ElastoPlasticFrictionT& f, double normal, double drive, double anchorX,
                            double anchorV, double roughness) noexcept;
    void chooseKernel() noexcept;
    /// The fixed-point passes (newton = false): the reference solve.
    struct PassesResult {
        double v, z, force;
        int passes;
        bool converged;
    };
    PassesResult solvePasses(double vRelPred, double z0, double noise, double fc, double fs,
                             double zba) const noexcept;
    double alphaOf(double z, double v, double zss, double zba) const noexcept;
    /// The plastic rate p = alpha(z_c, v) v / z_ss(v) >= 0 at a trial (v, z) (z_c: z0 or z,
    /// see processSample) and its partial derivatives (for Newton).
    struct Plastic {
        double p, dv, dz;
    };
    /// One sample's data for the Newton solve (kept for lastSolveResidual()).
    struct SolveInput {
        double z0 = 0, sC = 0, dC = 0, n0 = 0, n1 = 0; // (see passAt)
        double zssC = 0, zssD = 0; // |z_ss| = zssC + zssD e: f_c / sigma0, (f_s - f_c) / sigma0
        double zba = 0;
        double vOut = 0, zOut = 0; // the solution returned
    };
    struct Pass {
        double v, z, invD, invDen; // v1, z1, 1 / d, 1 / (d0 + d1 p)
    };
    Pass passAt(const SolveInput& in, double p) const noexcept;
    template <bool Libm>
    Plastic plasticRate(const SolveInput& in, double v, double z) const noexcept;
    template <bool Libm>
    Pass solveNewton(const SolveInput& in, double vRelPred, int& passes, bool& converged) noexcept;
    SolveInput in_;
    bool trackResidual_ = false;
    double invStribeck_ = 1.0, minusTwoOverVs_ = -2.0, d0_ = 1.0, d1_ = 0.0;
    double pMax_ = 1e18 * 48000.0; // cap of the plastic rate (T pMax = 1e18)

    FrictionParams params_;
    ModalResonatorT<Real> resonator_;
    Random rng_;
    double T_ = 1.0 / 48000.0;
    double kd_ = 0.0;
    Kernel kernel_ = &kernelGeneric<false>;
    bool avxAllowed_ = true;
    // The exciter's prediction without a new friction force (see prepare()): xePred =
    // xX x + xV v + xH (lastExternal - force) + xE external, vePred likewise.
    double xX_ = 1, xV_ = 0, xH_ = 0, xE_ = 0, vX_ = 0, vV_ = 1, vH_ = 0, vE_ = 0;
    double zssPerN_ = 0, zssDiffPerN_ = 0, zbaPerN_ = 0; // mu_d / sigma0, ..., z_ba / N
    double px_ = 0, pv_ = 0; // exciter compliance / mobility to the friction force
    double stiffPlusDamp_ = 0, dampOverT_ = 0, stiffTPlusDamp_ = 0; // sigma0 + sigma1/T, ...
    double p_ = 0, pPrev_ = 0, pPrev2_ = 0; // plastic rate of the last three samples (warm start)
    double z_ = 0, v_ = 0, force_ = 0, exciterX_ = 0, exciterV_ = 0, lastExternal_ = 0;
    FrictionSolveStats stats_;
};

using ElastoPlasticFriction = ElastoPlasticFrictionT<double>;

} // namespace underfoot::engine
