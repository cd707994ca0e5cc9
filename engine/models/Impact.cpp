// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Impact.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

template <typename Real>
void HuntCrossleyImpactT<Real>::configure(const ImpactParams& params, std::vector<Mode> modes,
                                          std::vector<std::vector<double>> gains, int listen) {
    if (!(std::isfinite(params.stiffness) && params.stiffness > 0))
        throw std::invalid_argument("impact stiffness must be finite and positive");
    if (!(std::isfinite(params.alpha) && params.alpha >= 1.0 && params.alpha <= 4.0))
        throw std::invalid_argument("impact alpha must lie in [1, 4]");
    if (!(std::isfinite(params.dissipation) && params.dissipation >= 0))
        throw std::invalid_argument("impact dissipation must be finite and >= 0");
    if (!(std::isfinite(params.exciterMassKg) && params.exciterMassKg > 0))
        throw std::invalid_argument("exciter mass must be finite and positive");
    if (params.newtonIterations < 1 || params.newtonIterations > 100)
        throw std::invalid_argument("newton iterations must be 1..100");
    if (params.oversampling != 1 && params.oversampling != 2 && params.oversampling != 4 &&
        params.oversampling != 8)
        throw std::invalid_argument("oversampling must be 1, 2, 4 or 8");
    params_ = params;
    resonator_.configure(std::move(modes), std::move(gains));
    if (listen < 0 || listen >= resonator_.pickupCount())
        throw std::invalid_argument("listen pickup out of range");
    listen_ = listen;
}

template <typename Real>
void HuntCrossleyImpactT<Real>::prepare(const ProcessSpec& spec) {
    fs_ = spec.sampleRateHz;
    internalFs_ = fs_ * params_.oversampling;
    T_ = 1.0 / internalFs_;
    resonator_.prepare(internalFs_);
    const double M = params_.exciterMassKg;
    kc_ = T_ * T_ / (6.0 * M) + resonator_.compliance(0);
    kd_ = T_ / (2.0 * M) + resonator_.mobility(0);
    if (params_.oversampling > 1)
        decimator_.design(FilterType::Lowpass, 8, internalFs_, 0.45 * fs_);
    reset();
}

template <typename Real>
void HuntCrossleyImpactT<Real>::reset() noexcept {
    resonator_.reset();
    decimator_.reset();
    exciterX_ = exciterV_ = lastForce_ = lastExternal_ = 0;
    inContact_ = false;
    awake_ = false;
    quietSamples_ = 0;
    stats_ = {};
    time_ = contactStart_ = 0;
}

template <typename Real>
void HuntCrossleyImpactT<Real>::strike(double velocity) noexcept {
    if (!std::isfinite(velocity)) return;
    if (inContact_) {
        exciterV_ += velocity;
    } else {
        exciterX_ = resonator_.position(0); // touching, zero compression
        exciterV_ = velocity + resonator_.velocity(0);
    }
    awake_ = true;
    quietSamples_ = 0;
}

template <typename Real>
double HuntCrossleyImpactT<Real>::contactForce(double c, double cdot) const noexcept {
    if (c <= 0.0) return 0.0;
    const double a = params_.alpha;
    const double ca = (a == 1.0)   ? c
                      : (a == 1.5) ? c * std::sqrt(c)
                      : (a == 2.0) ? c * c
                                   : std::pow(c, a);
    return std::max(0.0, params_.stiffness * ca * (1.0 + params_.dissipation * cdot));
}

template <typename Real>
double HuntCrossleyImpactT<Real>::step(double fextNow, double fextNext) noexcept {
    const double M = params_.exciterMassKg, T = T_;
    // Predictions with no new contact force (the force at n still acts through the hold).
    const double aNow = (fextNow - lastForce_) / M;
    const double aNextExt = fextNext / M;
    const double xPred = exciterX_ + T * exciterV_ + T * T * (aNow / 3.0 + aNextExt / 6.0);
    const double vPred = exciterV_ + 0.5 * T * (aNow + aNextExt);
    resonator_.predict();
    const double ch = xPred - resonator_.predictedPosition(0);
    const double dh = vPred - resonator_.predictedVelocity(0);

    double force = 0.0;
    if (params_.solver == ImpactSolver::Explicit) {
        force =
            contactForce(exciterX_ - resonator_.position(0), exciterV_ - resonator_.velocity(0));
    } else {
        const double fMax = contactForce(ch, dh);
        if (fMax > 0.0) {
            // g(F) = F - HC(ch - kc F, dh - kd F) is increasing; root in [0, fMax].
            double lo = 0.0, hi = fMax;
            double f = std::clamp(lastForce_, lo, hi);
            int it = 0;
            for (; it < params_.newtonIterations; ++it) {
                const double c = ch - kc_ * f, cd = dh - kd_ * f;
                const double hc = contactForce(c, cd);
                const double g = f - hc;
                if (g > 0)
                    hi = f;
                else
                    lo = f;
                if (std::fabs(g) <= 1e-12 * fMax) break;
                double dg = 1.0;
                if (hc > 0.0) {
                    // d HC / dF = -(k a c^(a-1) (1 + mu cd) kc + k c^a mu kd)
                    const double a = params_.alpha, k = params_.stiffness, mu = params_.dissipation;
                    const double ca = hc / (k * (1.0 + mu * cd)); // c^a, reused
                    dg += k * (a * ca / c * (1.0 + mu * cd) * kc_ + ca * mu * kd_);
                }
                double next = f - g / dg;
                if (!(next > lo && next < hi)) next = 0.5 * (lo + hi); // safeguard: bisect
                f = next;
            }
            stats_.solverIterations += it;
            stats_.maxIterationsInOneSample = std::max(stats_.maxIterationsInOneSample, it);
            force = f;
        }
    }

    // Commit the sample with the contact force at n+1.
    const double aNext = (fextNext - force) / M;
    exciterX_ += T * exciterV_ + T * T * (aNow / 3.0 + aNext / 6.0);
    exciterV_ += 0.5 * T * (aNow + aNext);
    resonator_.commit(0, force);
    lastForce_ = force;
    time_ += T;

    const bool contactNow = force > 0.0;
    if (contactNow) {
        ++stats_.solvedSamples;
        if (!inContact_) {
            contactStart_ = time_;
            stats_.peakForceN = 0;
            stats_.incomingVelocity = dh;
        }
        stats_.peakForceN = std::max(stats_.peakForceN, force);
    } else if (inContact_) {
        stats_.contactTimeSeconds = time_ - contactStart_;
        stats_.outgoingVelocity = exciterV_ - resonator_.velocity(0);
    }
    inContact_ = contactNow;
    return resonator_.velocity(listen_);
}

template <typename Real>
void HuntCrossleyImpactT<Real>::process(const float* fext, float* out, int n) noexcept {
    bool pushed = false;
    if (fext)
        for (int i = 0; i < n; ++i) pushed |= fext[i] != 0.0f;
    if (!awake_ && !pushed) {
        std::fill(out, out + n, 0.0f);
        return;
    }
    awake_ = true;
    const int os = params_.oversampling;
    double peak = 0.0;
    for (int i = 0; i < n; ++i) {
        const double fNext = fext ? double(fext[i]) : 0.0;
        double y = 0.0;
        for (int k = 0; k < os; ++k) {
            // Linear interpolation of the external force inside the sample.
            const double f1 = lastExternal_ + (fNext - lastExternal_) * double(k + 1) / os;
            const double f0 = lastExternal_ + (fNext - lastExternal_) * double(k) / os;
            y = step(f0, f1);
            if (os > 1) y = decimator_.processSample(y);
        }
        lastExternal_ = fNext;
        out[i] = static_cast<float>(y);
        peak = std::max(peak, std::fabs(y));
    }
    resonator_.flushTinyState();
    // Sleep when there is no contact, no push, the exciter is not approaching the floor and
    // the floor rings below ~-200 dB re 1 m/s (far below any audible output gain).
    const bool separating = exciterV_ - resonator_.velocity(0) <= 1e-9;
    const bool still = !inContact_ && !pushed && separating &&
                       resonator_.peakModalVelocity() < 1e-10 && peak < 1e-10;
    if (still) {
        awake_ = false;
        resonator_.reset();
        decimator_.reset();
        exciterX_ = exciterV_ = lastForce_ = lastExternal_ = 0;
    }
}

template <typename Real>
double HuntCrossleyImpactT<Real>::totalEnergy() const noexcept {
    const double c = exciterX_ - resonator_.position(0);
    double elastic = 0.0;
    if (c > 0.0)
        elastic = params_.stiffness * std::pow(c, params_.alpha + 1.0) / (params_.alpha + 1.0);
    return 0.5 * params_.exciterMassKg * exciterV_ * exciterV_ + resonator_.energy() + elastic;
}

template class HuntCrossleyImpactT<double>;
template class HuntCrossleyImpactT<float>;

} // namespace underfoot::engine
