// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Friction.h"

#include <algorithm>
#include <cmath>
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
    params_ = p;
    resonator_.configure(std::move(modes), std::move(gains));
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::prepare(double fs) {
    T_ = 1.0 / fs;
    resonator_.prepare(fs);
    kd_ = T_ / (2.0 * params_.exciterMassKg) + resonator_.mobility(0);
    reset(0);
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::reset(std::uint64_t seed) noexcept {
    resonator_.reset();
    rng_.setSeed(seed);
    z_ = v_ = force_ = exciterX_ = exciterV_ = lastDrive_ = 0;
}

template <typename Real>
double ElastoPlasticFrictionT<Real>::alphaOf(double z, double v, double zss,
                                             double zba) const noexcept {
    if (v == 0.0 || (z > 0) != (v > 0)) return 0.0; // opposite signs: elastic only
    const double az = std::fabs(z), ass = std::fabs(zss);
    if (az <= zba) return 0.0;
    if (az >= ass) return 1.0;
    return 0.5 * std::sin(kPi * (az - 0.5 * (ass + zba)) / (ass - zba)) + 0.5;
}

template <typename Real>
double ElastoPlasticFrictionT<Real>::processSample(double normal, double drive) noexcept {
    const double T = T_, M = params_.exciterMassKg;
    const double N = std::max(0.0, normal);
    const double fc = params_.dynamicCoefficient * N, fs = params_.staticCoefficient * N;
    // Roughness noise acts only while the surfaces are pressed together.
    const double noise = N > 0.0 ? params_.sigma3 * rng_.bipolar() : 0.0;

    // Predictions without a new friction force (old force held, drive ramped).
    const double aNow = (lastDrive_ - force_) / M;
    const double aNextExt = drive / M;
    const double vePred = exciterV_ + 0.5 * T * (aNow + aNextExt);
    const double xePred = exciterX_ + T * exciterV_ + T * T * (aNow / 3.0 + aNextExt / 6.0);
    resonator_.predict();
    const double vRelPred = vePred - resonator_.predictedVelocity(0);

    // Friction force as a function of the relative velocity at n+1.
    const double z0 = z_;
    auto bristleAt = [&](double v1) {
        if (N <= 0.0) return 0.0; // no load: the bristles relax completely
        const double s = (v1 >= 0.0) ? 1.0 : -1.0;
        const double zss = s *
                           (fc + (fs - fc) * std::exp(-(v1 * v1) / (params_.stribeckVelocity *
                                                                    params_.stribeckVelocity))) /
                           params_.sigma0;
        const double zba = params_.breakAway * fc / params_.sigma0;
        // Backward Euler: z1 = z0 + T v1 (1 - a z1 / zss), linear in z1 for a given a
        // (v1 / zss >= 0). alpha is taken at z0, then re-taken at the predicted z1 when the step
        // crosses into the plastic region, so that a stiff bristle cannot overshoot z_ss within
        // one sample (with a = 1, z1 is a weighted mean of z0 and z_ss).
        if (zss == 0.0) return 0.0; // no friction capacity (mu_s = mu_d = 0)
        auto step = [&](double a) { return (z0 + T * v1) / (1.0 + T * v1 * a / zss); };
        const double a0 = alphaOf(z0, v1, zss, zba);
        double z1 = step(a0);
        if (a0 < 1.0) {
            const double a1 = alphaOf(z1, v1, zss, zba);
            if (a1 > a0) z1 = step(a1);
        }
        return z1;
    };
    // No load, no contact: no friction at all (the bristles relax, see bristleAt).
    const double inContact = N > 0.0 ? 1.0 : 0.0;
    auto forceAt = [&](double v1, double z1) {
        return inContact *
               (params_.sigma0 * z1 + params_.sigma1 * (z1 - z0) / T + params_.sigma2 * v1 + noise);
    };
    // The relative velocity at n+1 solves h(v) = v - vRelPred + kd F(v) = 0. With the plastic
    // factor alpha(z, v) / z_ss(v) taken at a trial velocity vp, backward Euler gives
    // z1 = (z0 + T v1) / d with d = 1 + T vp alpha / z_ss >= 1, F is linear in v1 and h has a
    // closed-form root. A few fixed-point passes (vp <- v1) make it consistent; each pass costs one
    // exp and at most one sine, so the work per sample is bounded (no bracketing, no open loop).
    // Sticking (alpha = 0) is exact in one pass.
    const double zba = params_.breakAway * fc / params_.sigma0;
    double v1 = vRelPred;
    for (int pass = 0; pass < params_.maxIterations && inContact > 0.0; ++pass) {
        const double vp = v1;
        const double sgn = vp >= 0.0 ? 1.0 : -1.0;
        const double vs = vp / params_.stribeckVelocity;
        const double zss = sgn * (fc + (fs - fc) * std::exp(-vs * vs)) / params_.sigma0;
        const double a = zss != 0.0 ? alphaOf(z0, vp, zss, zba) : 0.0;
        const double d = 1.0 + (a > 0.0 ? T * vp * a / zss : 0.0);
        const double constant =
            params_.sigma0 * z0 / d + params_.sigma1 * (z0 / d - z0) / T + noise;
        const double slope = params_.sigma0 * T / d + params_.sigma1 / d + params_.sigma2;
        const double next = (vRelPred - kd_ * constant) / (1.0 + kd_ * slope);
        const bool converged = std::fabs(next - v1) < 1e-9 || a == 0.0;
        v1 = next;
        if (converged && pass > 0) break;
    }
    const double z1 = bristleAt(v1);
    commitSample(v1, z1, forceAt(v1, z1), xePred, vePred, drive);
    return resonator_.velocity(0);
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::commitSample(double v1, double z1, double f, double xePred,
                                                double vePred, double drive) noexcept {
    // Friction acts against the exciter's relative motion, with it on the resonator.
    const double T = T_, M = params_.exciterMassKg;
    exciterX_ = xePred - T * T / (6.0 * M) * f;
    exciterV_ = vePred - 0.5 * T / M * f;
    resonator_.commit(0, f);
    z_ = snapToZero(z1);
    v_ = exciterV_ - resonator_.contactVelocity();
    (void)v1;
    force_ = f;
    lastDrive_ = drive;
}

template class ElastoPlasticFrictionT<double>;
template class ElastoPlasticFrictionT<float>;

} // namespace underfoot::engine
