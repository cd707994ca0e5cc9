// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Friction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace underfoot::engine {

template <typename Real>
void ElastoPlasticFrictionT<Real>::configure(const FrictionParams& p, std::vector<Mode> modes,
                                             std::vector<std::vector<double>> gains) {
    auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
    auto nonNegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
    if (!positive(p.sigma0) || !nonNegative(p.sigma1) || !nonNegative(p.sigma2) ||
        !nonNegative(p.sigma3))
        throw std::invalid_argument("friction: sigma0 must be > 0 and sigma1..3 >= 0");
    if (!nonNegative(p.dynamicCoefficient) || !(p.staticCoefficient >= p.dynamicCoefficient))
        throw std::invalid_argument("friction: need 0 <= mu_d <= mu_s");
    if (!positive(p.stribeckVelocity) || !positive(p.exciterMassKg))
        throw std::invalid_argument("friction: Stribeck velocity and mass must be > 0");
    if (!(p.breakAway > 0.0 && p.breakAway < 1.0))
        throw std::invalid_argument("friction: break-away fraction must lie in (0, 1)");
    if (p.maxIterations < 1 || p.maxIterations > 1000)
        throw std::invalid_argument("friction: maxIterations must lie in [1, 1000]");
    if (!nonNegative(p.tolerance))
        throw std::invalid_argument("friction: tolerance must be finite and >= 0");
    params_ = p;
    resonator_.configure(std::move(modes), std::move(gains));
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::prepare(double fs) {
    T_ = 1.0 / fs;
    resonator_.prepare(fs);
    // Exciter with the drive spring k and damper c taken at n+1 (first-order hold as elsewhere):
    //   [1 + T^2 k/6M, T^2 c/6M; T k/2M, 1 + T c/2M] [x1; v1] = [r1 - s1 F; r2 - s2 F]
    // with s1 = T^2/6M, s2 = T/2M; so x1 = X - px F and v1 = V - pv F.
    const double T = T_, M = params_.exciterMassKg, k = params_.driveStiffness,
                 c = params_.driveDamping;
    m11_ = 1.0 + T * T * k / (6.0 * M);
    m12_ = T * T * c / (6.0 * M);
    m21_ = T * k / (2.0 * M);
    m22_ = 1.0 + T * c / (2.0 * M);
    det_ = m11_ * m22_ - m12_ * m21_;
    const double s1 = T * T / (6.0 * M), s2 = T / (2.0 * M);
    px_ = (m22_ * s1 - m12_ * s2) / det_;
    pv_ = (m11_ * s2 - m21_ * s1) / det_;
    kd_ = pv_ + resonator_.mobility(0);
    stiffPlusDamp_ = params_.sigma0 + params_.sigma1 / T;
    dampOverT_ = params_.sigma1 / T;
    stiffTPlusDamp_ = params_.sigma0 * T + params_.sigma1;
    invSigma0_ = 1.0 / params_.sigma0;
    invStribeck_ = 1.0 / params_.stribeckVelocity;
    minusTwoOverVs_ = -2.0 * invStribeck_;
    pMax_ = 1e18 / T;
    d0_ = 1.0 + kd_ * params_.sigma2 + kd_ * stiffTPlusDamp_;
    d1_ = (1.0 + kd_ * params_.sigma2) * T;
    reset(0);
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::reset(std::uint64_t seed) noexcept {
    resonator_.reset();
    rng_.setSeed(seed);
    z_ = v_ = force_ = exciterX_ = exciterV_ = lastExternal_ = p_ = pPrev_ = 0;
    stats_ = FrictionSolveStats{};
}

template <typename Real>
inline double ElastoPlasticFrictionT<Real>::alphaOf(double z, double v, double zss,
                                                    double zba) const noexcept {
    if (v == 0.0 || (z > 0) != (v > 0)) return 0.0; // opposite signs: elastic only
    const double az = std::fabs(z), ass = std::fabs(zss);
    if (az <= zba) return 0.0;
    if (az >= ass) return 1.0;
    const double t = 2.0 * (az - 0.5 * (ass + zba)) / (ass - zba); // in (-1, 1)
    if (params_.libmFunctions) return 0.5 * std::sin(0.5 * kPi * t) + 0.5;
    return 0.5 * frictionSinHalfPi(t) + 0.5;
}

template <typename Real>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Pass
ElastoPlasticFrictionT<Real>::passAt(const SolveInput& in, double p) const noexcept {
    // The plain pass with the plastic factor fixed at p: d = 1 + T p (>= 1), the bristle
    // z1 = (z0 + T v1) / d and the force F = sC / d + dC + (ST / d + sigma2) v1 (sC = (sigma0 +
    // sigma1 / T) z0, dC = noise - sigma1 z0 / T, ST = sigma0 T + sigma1), whose coupling
    // v1 = vRelPred - kd F has the closed-form root v1 = (n0 + n1 p) / (d0 + d1 p) (numerator and
    // denominator multiplied by d: n0 = A - kd sC, n1 = A T, d0 = B + kd ST, d1 = B T with
    // A = vRelPred - kd dC, B = 1 + kd sigma2).
    Pass x;
    x.invD = 1.0 / (1.0 + T_ * p);
    x.invDen = 1.0 / (d0_ + d1_ * p);
    x.v = (in.n0 + in.n1 * p) * x.invDen;
    x.z = (in.z0 + T_ * x.v) * x.invD;
    return x;
}

template <typename Real>
template <bool Libm>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Plastic
ElastoPlasticFrictionT<Real>::plasticRate(const SolveInput& in, double v, double z) const noexcept {
    // The same alpha as the fixed-point pass: the larger of alpha(z0, v) and alpha(z, v), i.e.
    // alpha at the candidate of v's sign with the larger |z| (0 when neither has v's sign or
    // the candidate is within the break-away). With s = sgn(v), a candidate of v's sign has
    // s z > 0 and the other sign s z <= 0 <= z_ba, so the candidate is the larger of s z0 and
    // s z, and it counts when it exceeds z_ba (z0 on a tie, as alphaOf's max).
    if (v == 0.0) return {0.0, 0.0, 0.0};
    const double sgn = v > 0.0 ? 1.0 : -1.0;
    const double s0 = sgn * in.z0, s1 = sgn * z;
    const bool trial = s1 > s0; // z_c is the trial's z
    const double az = trial ? s1 : s0;
    if (!(az > in.zba)) return {0.0, 0.0, 0.0};
    // |z_ss(v)| = (f_c + (f_s - f_c) e) / sigma0, e = exp(-(v / v_s)^2) (Stribeck).
    const double u = v * invStribeck_;
    const double e = Libm ? std::exp(-u * u) : frictionExpNeg(-u * u);
    const double ass = in.zssC + in.zssD * e;
    if (!(ass > 0.0)) return {0.0, 0.0, 0.0}; // z_ss = 0: alpha is taken as 0 (as alphaOf)
    const double dAss = minusTwoOverVs_ * u * (in.zssD * e); // d|z_ss| / dv
    const double invAss = 1.0 / ass;
    double a = 1.0, daDz = 0.0, daDass = 0.0;
    if (az < ass) {
        // raised sine in t = 2 (|z| - (|z_ss| + z_ba) / 2) / (|z_ss| - z_ba) in (-1, 1)
        const double invW = 1.0 / (ass - in.zba);
        const double t = 2.0 * (az - 0.5 * (ass + in.zba)) * invW;
        const double sn = Libm ? std::sin(0.5 * kPi * t) : frictionSinHalfPi(t);
        a = 0.5 * sn + 0.5;
        // da/dt = (pi / 4) cos(pi t / 2), cos = sqrt(1 - sin^2) >= 0 on [-1, 1] (only the
        // Newton step uses derivatives: their rounding does not change the converged solution)
        const double dadt = 0.25 * kPi * std::sqrt(std::max(0.0, 1.0 - sn * sn));
        daDz = dadt * 2.0 * invW;          // d a / d|z|
        daDass = -dadt * (1.0 + t) * invW; // d a / d|z_ss|
    }
    const double r = std::fabs(v) * invAss; // |v| / |z_ss|
    // (capped at pMax_, where T p ~ 1e18 leaves z1 = (z0 + T v1) / (1 + T p) at 0 to double
    // precision: |z_ss| can underflow towards 0 with mu_d = 0 at high speed, and p with it to inf;
    // the derivatives are then not finite, and the step falls back to the bracket)
    const double p = a * r < pMax_ ? a * r : pMax_;
    const double dv = sgn * a * invAss + (r * daDass - p * invAss) * dAss;
    const double dz = trial ? r * daDz * sgn : 0.0;
    return {p, dv, dz};
}

template <typename Real>
double ElastoPlasticFrictionT<Real>::lastSolveResidual() const noexcept {
    const SolveInput& in = in_;
    if (!(in.zssC > 0.0 || in.zssD > 0.0)) return 0.0;
    const Plastic P = params_.libmFunctions ? plasticRate<true>(in, in.vOut, in.zOut)
                                            : plasticRate<false>(in, in.vOut, in.zOut);
    const Pass x = passAt(in, P.p);
    const double vs = params_.stribeckVelocity;
    return std::max(std::fabs(x.v - in.vOut) / std::max(std::fabs(x.v), vs),
                    std::fabs(x.z - in.zOut) / std::max(std::fabs(x.z), T_ * vs));
}

template <typename Real>
template <bool Libm>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Pass
ElastoPlasticFrictionT<Real>::solveNewton(const SolveInput& in, double vRelPred, int& passes,
                                          bool& converged) noexcept {
    // Newton on the plastic rate p. A plain pass with the plastic factor fixed at p is
    // psi(p) = (v1, z1) (passAt, with d = 1 + T p); the solution is the fixed point
    // p = P(psi(p)), P = plasticRate. g(p) = P(psi(p)) - p is continuous, g(0) >= 0 and g < 0
    // for large p (P(psi(p)) stays bounded as psi(p) tends to z1 = 0), so a root lies in
    // [lo, hi]; Newton steps with g' = grad P . psi'(p) - 1 stay inside the bracket or are
    // replaced by a bisection (or, before an upper end is known, by the plain pass p <- P).
    const double T = T_, tol = params_.tolerance;
    const double vScale = params_.stribeckVelocity, zScale = T * params_.stribeckVelocity;
    // Warm start: the last two samples' p extrapolated linearly (p varies smoothly while
    // slipping; 0 while sticking).
    double pk = params_.warmStart ? std::max(0.0, 2.0 * p_ - pPrev_)
                                  : plasticRate<Libm>(in, vRelPred, in.z0).p;
    // lo: the largest trial with g > 0 (-1 before one: g(0) >= 0 anyway); hi: the smallest
    // with g < 0. The root lies in [max(lo, 0), hi].
    double lo = -1.0, hi = HUGE_VAL;
    double lastStep = 0.0;
    Pass x = passAt(in, pk);
    while (true) {
        const Plastic P = plasticRate<Libm>(in, x.v, x.z);
        ++passes;
        const double g = P.p - pk;
        if (g == 0.0) { // pk is a fixed point (a sticking sample: p = 0 = P)
            converged = true;
            break;
        }
        if (g > 0.0)
            lo = pk;
        else
            hi = pk;
        // psi'(p): dv/dp = (n1 - d1 v) / (d0 + d1 p), dz/dp = T (dv/dp - z) / d.
        const double dvdp = (in.n1 - d1_ * x.v) * x.invDen;
        const double dzdp = T * (dvdp - x.z) * x.invD;
        const double gp = P.dv * dvdp + P.dz * dzdp - 1.0;
        double next = pk - g / gp;
        if (next < 0.0) next = 0.0; // (p >= 0; a NaN step fails the bracket test below)
        if (!(next > lo && next < hi)) next = hi < HUGE_VAL ? 0.5 * (std::max(lo, 0.0) + hi) : P.p;
        const double step = std::fabs(next - pk);
        // Contraction of this step against the last one: the error left after a step of a
        // sequence contracting by theta < 1 is at most theta / (1 - theta) times the step
        // (for Newton far less: about theta^2 times it). With no earlier step, factor 1: the
        // fixed-point criterion itself (a pass that moves by at most tol).
        const double theta = lastStep > 0.0 ? step / lastStep : 1.0;
        const double factor = theta < 0.5 ? theta / (1.0 - theta) : 1.0;
        lastStep = step;
        pk = next;
        const double vb = x.v, zb = x.z;
        x = passAt(in, pk);
        // Converged when the error left in v and z (estimated from the step as above) is at
        // most tol relative to max(|v|, v_s) and max(|z|, T v_s): the plain passes' criterion
        // (a pass that moves by at most tol leaves an error of about theta / (1 - theta) tol,
        // theta up to ~0.5 there).
        if (factor * std::fabs(x.v - vb) <= tol * std::max(std::fabs(x.v), vScale) &&
            factor * std::fabs(x.z - zb) <= tol * std::max(std::fabs(x.z), zScale)) {
            converged = true;
            break;
        }
        if (passes >= params_.maxIterations) break;
    }
    pPrev_ = p_;
    p_ = pk;
    return x;
}

template <typename Real>
double ElastoPlasticFrictionT<Real>::processSample(double normal, double drive, double anchorX,
                                                   double anchorV) noexcept {
    const double T = T_, M = params_.exciterMassKg;
    const double N = std::max(0.0, normal);
    const double fc = params_.dynamicCoefficient * N, fs = params_.staticCoefficient * N;
    // Roughness noise acts only while the surfaces are pressed together.
    const double noise = N > 0.0 ? params_.sigma3 * rng_.bipolar() : 0.0;

    // Predictions without a new friction force (old force held, drive ramped).
    const double k = params_.driveStiffness, c = params_.driveDamping;
    const double aNow = (lastExternal_ - force_) / M;
    const double g0 = (drive + k * anchorX + c * anchorV) / M; // external push at n+1, per kg
    const double r1 = exciterX_ + T * exciterV_ + T * T * (aNow / 3.0 + g0 / 6.0);
    const double r2 = exciterV_ + 0.5 * T * (aNow + g0);
    const double xePred = (m22_ * r1 - m12_ * r2) / det_; // exciter at n+1 without friction
    const double vePred = (m11_ * r2 - m21_ * r1) / det_;
    resonator_.predict();
    const double vRelPred = vePred - resonator_.predictedVelocity(0);

    // Friction force as a function of the relative velocity at n+1.
    const double z0 = z_;
    const double inContact = N > 0.0 ? 1.0 : 0.0; // no load, no contact: no friction at all
    // The relative velocity at n+1 solves h(v) = v - vRelPred + kd F(v) = 0, with the bristle
    // integrated by backward Euler, z1 = z0 + T v1 (1 - alpha z1 / z_ss). With the plastic factor
    // alpha / z_ss taken at a trial state (vp, zp), z1 = (z0 + T v1) / d with
    // d = 1 + T vp alpha / z_ss >= 1 (vp / z_ss >= 0): F is linear in v1 and h has a closed-form
    // root. Fixed-point passes refine the trial, starting from the previous sample's relative
    // velocity (warm start), until a pass moves v1 and z1 by at most `tolerance` relative to
    // max(|v1|, v_s) and max(|z1|, T v_s), at most maxIterations passes. alpha is taken at the
    // larger of its values at z0 and at the trial z1, so a stiff bristle cannot overshoot z_ss
    // within a sample (with alpha = 1, z1 is a weighted mean of z0 and z_ss). The force applied
    // is exactly the one the root was solved with (consistency keeps the coupling stable). Each
    // pass costs at most one exp and one sine: bounded work per sample.
    const double zba = params_.breakAway * fc / params_.sigma0;
    const double vScale = params_.stribeckVelocity, zScale = T * params_.stribeckVelocity;
    const double tol = params_.tolerance;
    double v1 = params_.warmStart ? v_ : vRelPred, z1 = 0.0, force = 0.0, zp = z0;
    int passes = 0, plain = 0; // plain: passes since the last extrapolation
    bool converged = false;
    double vBefore = 0.0, zBefore = 0.0; // the trial of the previous pass
    if (inContact > 0.0 && params_.newton) {
        // Shipped: Newton on the plastic rate (solveNewton); the output is the plain pass at
        // the final p, whose force is the one its v1 was solved with.
        SolveInput in;
        in.z0 = z0;
        in.sC = stiffPlusDamp_ * z0;
        in.dC = -dampOverT_ * z0 + noise;
        const double A = vRelPred - kd_ * in.dC;
        in.n0 = A - kd_ * in.sC;
        in.n1 = A * T;
        in.zssC = fc * invSigma0_;
        in.zssD = (fs - fc) * invSigma0_;
        in.zba = zba;
        const Pass x = params_.libmFunctions ? solveNewton<true>(in, vRelPred, passes, converged)
                                             : solveNewton<false>(in, vRelPred, passes, converged);
        v1 = x.v;
        z1 = x.z;
        force = in.sC * x.invD + in.dC + (stiffTPlusDamp_ * x.invD + params_.sigma2) * x.v;
        if (trackResidual_) {
            in.vOut = v1;
            in.zOut = z1;
            in_ = in;
        }
    }
    if (trackResidual_ && !(inContact > 0.0 && params_.newton)) in_.zssC = in_.zssD = 0.0;
    while (inContact > 0.0 && !params_.newton && passes < params_.maxIterations) {
        const double vp = v1;
        // alpha is the larger of its values at z0 and at the trial zp. alphaOf is 0 for a z of
        // the other sign than vp or with |z| <= z_ba, and non-decreasing in |z| otherwise (a
        // raised sine between z_ba and |z_ss|, then 1): the larger value is the one at the
        // candidate of vp's sign with the larger |z|, so one alphaOf (at most one sine) gives it.
        // The Stribeck exp is only needed when that candidate is past the break-away (sticking
        // samples skip it). Same values as evaluating both, in fewer operations.
        const bool ok0 = vp != 0.0 && (z0 > 0) == (vp > 0);
        const bool okp = vp != 0.0 && (zp > 0) == (vp > 0);
        double zc = 0.0;
        if (ok0 && okp)
            zc = std::fabs(zp) > std::fabs(z0) ? zp : z0;
        else if (ok0 || okp)
            zc = ok0 ? z0 : zp;
        double a = 0.0, zss = 0.0;
        if ((ok0 || okp) && std::fabs(zc) > zba) {
            const double sgn = vp >= 0.0 ? 1.0 : -1.0;
            const double vs = vp / params_.stribeckVelocity;
            const double stribeck =
                params_.libmFunctions ? std::exp(-vs * vs) : frictionExpNeg(-vs * vs);
            zss = sgn * (fc + (fs - fc) * stribeck) / params_.sigma0;
            if (zss != 0.0) a = alphaOf(zc, vp, zss, zba);
        }
        // (1/d computed once; sigma0 + sigma1 / T and sigma0 T + sigma1 precomputed: the same
        // quantities as sigma0 z0 / d + sigma1 (z0 / d - z0) / T and sigma0 T / d + sigma1 / d,
        // rounded differently)
        const double invD = a > 0.0 ? 1.0 / (1.0 + T * vp * a / zss) : 1.0;
        const double zd = z0 * invD;
        const double constant = stiffPlusDamp_ * zd - dampOverT_ * z0 + noise;
        const double slope = stiffTPlusDamp_ * invD + params_.sigma2;
        v1 = (vRelPred - kd_ * constant) / (1.0 + kd_ * slope);
        z1 = (z0 + T * v1) * invD;
        force = constant + slope * v1;
        ++passes;
        if (std::fabs(v1 - vp) <= tol * std::max(std::fabs(v1), vScale) &&
            std::fabs(z1 - zp) <= tol * std::max(std::fabs(z1), zScale)) {
            converged = true;
            break;
        }
        // Aitken's delta-squared on each of v and z after two plain passes: the passes converge
        // linearly (ratios ~0.1 to 0.5 while slipping), the extrapolation skips most of them.
        // Only the trial changes: convergence is still judged on a plain pass (its result equals
        // its trial), so the solution is the same fixed point.
        double vNext = v1, zNext = z1;
        if (params_.extrapolate && ++plain >= 2) {
            const double dv0 = vp - vBefore, dv1 = v1 - vp, dz0 = zp - zBefore, dz1 = z1 - zp;
            const double denV = dv1 - dv0, denZ = dz1 - dz0;
            if (denV != 0.0 && denZ != 0.0) {
                vNext = v1 - dv1 * dv1 / denV;
                zNext = z1 - dz1 * dz1 / denZ;
                plain = 0;
            }
        }
        vBefore = vp;
        zBefore = zp;
        v1 = vNext;
        zp = zNext;
    }
    if (inContact > 0.0) {
        ++stats_.samples;
        stats_.passes += static_cast<std::uint64_t>(passes);
        if (!converged) ++stats_.capHits;
        stats_.maxPassesInOneSample = std::max(stats_.maxPassesInOneSample, passes);
    }
    // Commit: friction acts against the exciter's relative motion, with it on the resonator.
    exciterX_ = xePred - px_ * force;
    exciterV_ = vePred - pv_ * force;
    resonator_.commit(0, force);
    z_ = snapToZero(z1);
    v_ = exciterV_ - resonator_.contactVelocity();
    force_ = force;
    lastExternal_ = drive + k * (anchorX - exciterX_) + c * (anchorV - exciterV_);
    return resonator_.velocity(0);
}

template class ElastoPlasticFrictionT<double>;
template class ElastoPlasticFrictionT<float>;

} // namespace underfoot::engine
