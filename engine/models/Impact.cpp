// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Impact.h"

#include "engine/models/ModalKernels.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
    if (params.contactSubsteps != 1 && params.contactSubsteps != 2 && params.contactSubsteps != 4 &&
        params.contactSubsteps != 8 && params.contactSubsteps != 16)
        throw std::invalid_argument("contact sub-steps must be 1, 2, 4, 8 or 16");
    if (!(std::isfinite(params.substepForceChange) && params.substepForceChange >= 0.0))
        throw std::invalid_argument("sub-step force change must be finite and >= 0");
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
    const int sub = params_.contactSubsteps;
    resonator_.prepare(internalFs_, sub);
    resonator_.setOutputPickup(listen_);
    resonator_.setEnergyTracking(true); // the passivity guard's energies in O(1) per trial
    const double M = params_.exciterMassKg;
    stiffness_ = params_.stiffness;
    dissipation_ = params_.dissipation;
    stiffMu_ = stiffness_ * dissipation_;
    shape_ = params_.alpha == 1.0   ? Shape::Linear
             : params_.alpha == 1.5 ? Shape::Hertz
             : params_.alpha == 2.0 ? Shape::Square
                                    : Shape::General;
    coarseT_ = T_;
    coarseKc_ = T_ * T_ / (6.0 * M) + resonator_.compliance(0); // exact for a linear force ramp
    coarseKd_ = T_ / (2.0 * M) + resonator_.mobility(0);
    fineT_ = T_ / sub;
    resonator_.setFineRate(true);
    fineKc_ = fineT_ * fineT_ / (6.0 * M) + resonator_.compliance(0);
    fineKd_ = fineT_ / (2.0 * M) + resonator_.mobility(0);
    for (auto* sc : {&coarseConstants_, &fineConstants_}) {
        const double t = sc == &fineConstants_ ? fineT_ : coarseT_;
        *sc = {t * t / 3.0, t * t / 6.0, t * t / (6.0 * M), 0.5 * t / M, 0.5 * t, 1.0 / M};
    }
    setFineRate(false);
    if (params_.oversampling > 1)
        decimator_.design(FilterType::Lowpass, 8, internalFs_, 0.45 * fs_);
    reset();
}

template <typename Real>
void HuntCrossleyImpactT<Real>::setFineRate(bool fine) noexcept {
    resonator_.setFineRate(fine);
    T_ = fine ? fineT_ : coarseT_;
    kc_ = fine ? fineKc_ : coarseKc_;
    kd_ = fine ? fineKd_ : coarseKd_;
    hertzKc_ = 1.5 * kc_;
    hertzKd_ = stiffMu_ * kd_;
    stepConstants_ = fine ? fineConstants_ : coarseConstants_;
}

template <typename Real>
void HuntCrossleyImpactT<Real>::reset() noexcept {
    freeRetryIn_ = 0;
    substepNext_ = false;
    newtonStart_ = -1.0;
    subForce1_ = subForce2_ = 0.0;
    setFineRate(false);
    resonator_.reset();
    decimator_.reset();
    exciterX_ = exciterV_ = lastForce_ = lastExternal_ = contactEnergy_ = 0;
    inContact_ = false;
    awake_ = false;
    quietSamples_ = 0;
    sleepGrid_.reset();
    pushedSinceGridPoint_ = false;
    peakSinceGridPoint_ = 0.0;
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
        exciterV_ = velocity + resonator_.contactVelocity();
    }
    awake_ = true;
    quietSamples_ = 0;
}

namespace {
// Newton's start in a sub-step: the force extrapolated from the last sub-steps' (quadratically
// from three, linearly from two; inside a strike that saves about a third of the iterations);
// f the last force, f1 and f2 the two before it (0: none).
inline double newtonStartOf(double f, double f1, double f2) noexcept {
    return f > 0.0 && f1 > 0.0 ? std::max(0.0, f2 > 0.0 ? 3.0 * (f - f1) + f2 : 2.0 * f - f1) : f;
}

// IEEE square root without the errno branch std::sqrt keeps for negative arguments (the
// contact only takes roots of positive compressions): the same correctly rounded value. (x in
// both lanes: _mm_set_sd's zeroed upper lane compiles, with AVX, to a register form of vmovq
// that valgrind 3.19 cannot execute, and the project counts instructions with callgrind.)
inline double rootOf(double x) noexcept {
#if defined(__SSE2__)
    const __m128d v = _mm_set1_pd(x);
    return _mm_cvtsd_f64(_mm_sqrt_sd(v, v));
#else
    return std::sqrt(x);
#endif
}
} // namespace

template <typename Real>
[[gnu::always_inline]] inline double
HuntCrossleyImpactT<Real>::hertzLaw(double c, double cdot, double& root,
                                    double& stiff) const noexcept {
    // k c^1.5 (1 + mu cdot) as sqrt(c) (c (k + k mu cdot)): the root comes last, the rest is
    // computed while it is taken (solveShaped's Newton slope likewise).
    root = rootOf(c);
    stiff = stiffness_ + stiffMu_ * cdot;
    return std::max(0.0, root * (c * stiff));
}

template <typename Real>
template <typename HuntCrossleyImpactT<Real>::Shape S>
inline double HuntCrossleyImpactT<Real>::contactForceOf(double c, double cdot, double& ca,
                                                        double& slope) const noexcept {
    // c^alpha and its derivative alpha c^(alpha - 1): the shapes in use without pow or a
    // division (chosen once in prepare()), so that Newton's slope needs no division either.
    // (Hertz has its own form, hertzLaw, with the slope's terms it needs.)
    static_assert(S != Shape::Hertz);
    if constexpr (S == Shape::Linear) {
        ca = c;
        slope = 1.0;
    } else if constexpr (S == Shape::Square) {
        ca = c * c;
        slope = 2.0 * c;
    } else {
        ca = std::pow(c, params_.alpha);
        slope = params_.alpha * ca / c;
    }
    return std::max(0.0, stiffness_ * ca * (1.0 + dissipation_ * cdot));
}

template <typename Real>
template <typename HuntCrossleyImpactT<Real>::Shape S>
inline double HuntCrossleyImpactT<Real>::contactForceOf(double c, double cdot) const noexcept {
    if (c <= 0.0) return 0.0;
    if constexpr (S == Shape::Hertz) {
        double root, stiff;
        return hertzLaw(c, cdot, root, stiff);
    } else {
        double ca, slope;
        return contactForceOf<S>(c, cdot, ca, slope);
    }
}

template <typename Real>
template <typename F>
inline decltype(auto) HuntCrossleyImpactT<Real>::withShape(F&& f) const {
    using S = Shape;
    switch (shape_) { // the contact law's shape, as a compile-time constant for f
    case S::Linear:
        return f(std::integral_constant<S, S::Linear>{});
    case S::Hertz:
        return f(std::integral_constant<S, S::Hertz>{});
    case S::Square:
        return f(std::integral_constant<S, S::Square>{});
    default:
        return f(std::integral_constant<S, S::General>{});
    }
}

template <typename Real>
double HuntCrossleyImpactT<Real>::contactForce(double c, double cdot) const noexcept {
    return withShape([&](auto s) { return contactForceOf<decltype(s)::value>(c, cdot); });
}

template <typename Real>
double HuntCrossleyImpactT<Real>::solveForce(double ch, double dh) noexcept {
    if (params_.solver == ImpactSolver::Explicit)
        return contactForce(exciterX_ - resonator_.position(0),
                            exciterV_ - resonator_.contactVelocity());
    if (!(ch > 0.0)) return 0.0; // fMax = HC(ch, dh) = 0 (below): no contact (free flight)
    // Newton from the last force, or from a sub-step's extrapolated start (see substepSample)
    const double start = newtonStart_ >= 0.0 ? newtonStart_ : lastForce_;
    return withShape([&](auto s) { return solveShaped<decltype(s)::value>(ch, dh, start); });
}

template <typename Real>
template <typename HuntCrossleyImpactT<Real>::Shape S>
inline double HuntCrossleyImpactT<Real>::solveShaped(double ch, double dh, double start) noexcept {
    // g(F) = F - HC(ch - kc F, dh - kd F) is increasing in F; its root lies in [0, fMax],
    // fMax = HC(ch, dh) (HC falls as F compresses less and slower). Newton from `start`.
    double f = start;
    double c = ch - kc_ * f, cd = dh - kd_ * f;
    // HC at (c, cd), and c^alpha and alpha c^(alpha - 1) there for Newton's slope (left as they
    // were where c <= 0: HC is then 0 and the slope is not used).
    double ca = 0.0, slope = 0.0;
    // Hertz: sqrt(c) and k (1 + mu cd) at the last evaluation, for the slope below.
    double root = 0.0, stiff = 0.0;
    auto law = [&](double cc, double ccd) {
        if constexpr (S == Shape::Hertz) {
            return cc > 0.0 ? hertzLaw(cc, ccd, root, stiff) : 0.0;
        } else {
            return cc > 0.0 ? contactForceOf<S>(cc, ccd, ca, slope) : 0.0;
        }
    };
    double hc = law(c, cd);
    double g = f - hc;
    // A contact at rest (a sole pressed on the floor) is usually solved by the last force
    // already: |g| <= tol hc implies the criterion below, |g| <= tol fMax, as hc <= fMax; fMax is
    // then not needed (the same result as the loop, which would stop at once).
    if (f > 0.0 && std::fabs(g) <= 1e-10 * hc) return f;
    const double fMax = f == 0.0 ? hc : contactForceOf<S>(ch, dh);
    if (!(fMax > 0.0)) return 0.0;
    double lo = 0.0, hi = fMax;
    if (f > hi) { // start inside the bracket
        f = hi;
        c = ch - kc_ * f, cd = dh - kd_ * f;
        hc = law(c, cd);
        g = f - hc;
    }
    int it = 0;
    const int iterations = params_.newtonIterations;
    for (;;) { // g, hc, c, cd are at f
        if (g > 0)
            hi = f;
        else
            lo = f;
        if (std::fabs(g) <= 1e-10 * fMax) break;
        double dg = 1.0;
        if (hc > 0.0) {
            // dHC/dF = -(k a c^(a-1) (1 + mu cd) kc + k c^a mu kd); for Hertz
            // sqrt(c) (1.5 kc k (1 + mu cd) + c k mu kd): one multiplication after the root.
            if constexpr (S == Shape::Hertz) {
                dg += root * (hertzKc_ * stiff + c * hertzKd_);
            } else {
                const double k = stiffness_, mu = dissipation_;
                dg += k * (slope * (1.0 + mu * cd) * kc_ + ca * mu * kd_);
            }
        }
        const double delta = g / dg;
        double next = f - delta;
        const bool newton = next > lo && next < hi;
        if (!newton) next = 0.5 * (lo + hi); // safeguard: bisect
        f = next;
        if (++it == iterations) break; // (the last step is not evaluated)
        // A Newton step this small leaves an error of the order of its square (1e-12 fMax and
        // below, far inside the tolerance): accepted without evaluating HC again.
        if (newton && std::fabs(delta) <= 1e-6 * fMax) break;
        c = ch - kc_ * f, cd = dh - kd_ * f;
        hc = law(c, cd);
        g = f - hc;
    }
    stats_.solverIterations += it;
    stats_.maxIterationsInOneSample = std::max(stats_.maxIterationsInOneSample, it);
    return f;
}

template <typename Real>
inline typename HuntCrossleyImpactT<Real>::Trial
HuntCrossleyImpactT<Real>::trialAt(double fextNow, double fextNext, double held,
                                   double scale) noexcept {
    const double aNextExt = fextNext * stepConstants_.perMass;
    const double aNow = (fextNow - held * lastForce_) * stepConstants_.perMass;
    double xPred, vPred;
    soleWithoutContact(stepConstants_, T_, exciterX_, exciterV_, aNow, aNextExt, xPred, vPred);
    resonator_.predict(held);
    const double ch = xPred - resonator_.predictedPosition(0);
    const double dh = vPred - resonator_.predictedVelocity(0);
    Trial t{};
    t.force = scale * solveForce(ch, dh);
    t.x = xPred - stepConstants_.xPerForce * t.force;
    t.v = vPred - stepConstants_.vPerForce * t.force;
    return t;
}

// Energy of the bodies after a trial (the resonator's prediction must be the trial's).
template <typename Real>
inline void HuntCrossleyImpactT<Real>::evaluateTrial(Trial& t, double fextNow,
                                                     double fextNext) const noexcept {
    t.energy = 0.5 * params_.exciterMassKg * t.v * t.v + resonator_.energyIfCommitted(0, t.force);
    t.work = 0.5 * (fextNow + fextNext) * (t.x - exciterX_);
}

// The commit of step() and of the sub-step loop: the same operations in the same order on
// either's state. The contact statistics: `approach` is the relative velocity before the step.
template <typename Real>
[[gnu::always_inline]] inline void
HuntCrossleyImpactT<Real>::commitStep(const Trial& t, double absorbed, double& x, double& v,
                                      double& last, double& stored, double& time,
                                      bool& inContact) noexcept {
    const double force = t.force;
    const double approach = v - resonator_.contactVelocity(); // at n, for the stats
    x = t.x;
    v = t.v;
    resonator_.commit(0, force);
    last = force;
    // Energy stored in the contact; what is left when it opens is lost (dissipated).
    stored = force > 0.0 ? std::max(0.0, stored + absorbed) : 0.0;
    time += T_;
    if (force > 0.0) {
        ++stats_.solvedSamples;
        if (!inContact) {
            contactStart_ = time;
            stats_.peakForceN = 0;
            stats_.incomingVelocity = approach;
        }
        stats_.peakForceN = std::max(stats_.peakForceN, force);
    } else if (inContact) {
        stats_.contactTimeSeconds = time - contactStart_;
        stats_.outgoingVelocity = v - resonator_.contactVelocity();
    }
    inContact = force > 0.0;
}

template <typename Real>
typename HuntCrossleyImpactT<Real>::Trial
HuntCrossleyImpactT<Real>::correctPassivity(double fextNow, double fextNext, double bodiesBefore,
                                            double tolerance) noexcept {
    // The force held from the previous sample, and if needed the new force, is bisected until
    // the sample is passive; no force at all always is (see step()).
    auto evaluated = [&](double held, double scale) {
        Trial t = trialAt(fextNow, fextNext, held, scale);
        evaluateTrial(t, fextNow, fextNext);
        return t;
    };
    auto passive = [&](const Trial& x) {
        return contactEnergy_ + (bodiesBefore + x.work - x.energy) >= -tolerance;
    };
    ++stats_.passivityCorrections;
    double held = 1.0;
    Trial best = evaluated(0.0, 1.0);
    if (passive(best)) {
        double lo = 0.0, hi = 1.0; // held-force scale: lo passive, hi not
        for (int k = 0; k < 16; ++k) {
            const double mid = 0.5 * (lo + hi);
            const Trial m = evaluated(mid, 1.0);
            if (passive(m)) {
                lo = mid;
                best = m;
            } else {
                hi = mid;
            }
        }
        held = lo;
    } else {
        held = 0.0;
        double lo = 0.0, hi = 1.0;  // new-force scale
        best = evaluated(0.0, 0.0); // no force at all: the floor only loses energy
        for (int k = 0; k < 16; ++k) {
            const double mid = 0.5 * (lo + hi);
            const Trial m = evaluated(0.0, mid);
            if (passive(m)) {
                lo = mid;
                best = m;
            } else {
                hi = mid;
            }
        }
    }
    resonator_.predict(held);
    return best;
}

template <typename Real>
bool HuntCrossleyImpactT<Real>::step(double fextNow, double fextNext, bool abortOnContact,
                                     double& y) noexcept {
    const double M = params_.exciterMassKg;
    // Both bodies are integrated exactly for the linear force ramp, so their energy change is
    // exactly the ramp's work: the check below is then exactly "the contact returns no more
    // energy than it stored".
    Trial t = trialAt(fextNow, fextNext, 1.0, 1.0);
    if (abortOnContact && (t.force > 0.0 || lastForce_ > 0.0)) {
        // A transient (the contact opens, closes or its force changes fast) is sub-stepped:
        // return before anything is committed.
        const double change = std::fabs(t.force - lastForce_);
        if (t.force == 0.0 || lastForce_ == 0.0 ||
            change > params_.substepForceChange * std::max(t.force, lastForce_))
            return false;
    }
    double absorbed = 0.0;
    if (t.force > 0.0 || lastForce_ > 0.0) {
        // Passivity guard. Both bodies are integrated exactly for the linear force ramp, so the
        // energy they lose in a sample (plus the external work) is exactly the work the contact
        // absorbed (plus the floor's own damping, which is also lost). The contact is a passive
        // element when, since it began, it has returned no more than it absorbed: the stored
        // budget `contactEnergy_` must stay >= 0. A contact resolved by too few samples (stiff,
        // light, fast) can violate that in discrete time, mostly when the bodies separate while
        // the held force still ramps down (the Sound Design Toolkit bisects its force for the
        // same reason). Then correctPassivity() bisects the force held from the previous sample,
        // and if needed the new force, until the sample is passive; no force at all always is.
        // Bounded work: at most 2 + 2 x 16 extra trials, in rare samples (counted in
        // stats().passivityCorrections).
        const double bodiesBefore = 0.5 * M * exciterV_ * exciterV_ + resonator_.energy();
        const double tolerance = 1e-13 * bodiesBefore;
        evaluateTrial(t, fextNow, fextNext);
        if (!(contactEnergy_ + (bodiesBefore + t.work - t.energy) >= -tolerance)) [[unlikely]]
            t = correctPassivity(fextNow, fextNext, bodiesBefore, tolerance);
        absorbed = bodiesBefore + t.work - t.energy;
    }

    // Commit the sample with the contact force at n+1.
    commitStep(t, absorbed, exciterX_, exciterV_, lastForce_, contactEnergy_, time_, inContact_);
    y = resonator_.velocity(listen_);
    return true;
}

template <typename Real>
void HuntCrossleyImpactT<Real>::process(const float* fext, float* out, int n) noexcept {
    sleepGrid_.split(n, [&](int offset, int length, bool atGridPoint) {
        processSpan(fext ? fext + offset : nullptr, out + offset, length);
        if (atGridPoint) sleepDecision();
    });
}

template <typename Real>
void HuntCrossleyImpactT<Real>::advanceAsleep(int n) noexcept {
    sleepGrid_.split(n, [&](int, int, bool atGridPoint) {
        if (atGridPoint) sleepDecision();
    });
}

template <typename Real>
void HuntCrossleyImpactT<Real>::processSpan(const float* fext, float* out, int n) noexcept {
    bool pushed = false;
    if (fext)
        for (int i = 0; i < n && !pushed; ++i) pushed = fext[i] != 0.0f;
    pushedSinceGridPoint_ |= pushed;
    if (!awake_ && !pushed) {
        // Asleep: the state is the reset state, which stays exactly at rest without a push (so
        // waking at the start of this span or at its first push gives the same samples).
        std::fill(out, out + n, 0.0f);
        return;
    }
    awake_ = true;
    const double peak = params_.oversampling == 1 ? spanSamples<true>(fext, out, n)
                                                  : spanSamples<false>(fext, out, n);
    peakSinceGridPoint_ = std::max(peakSinceGridPoint_, peak);
}

template <typename Real>
template <bool Single>
double HuntCrossleyImpactT<Real>::spanSamples(const float* fext, float* out, int n) noexcept {
    // (Single: no oversampling, the shipped setting, as its own loop without the decimator)
    const int os = Single ? 1 : params_.oversampling;
    const int sub = params_.contactSubsteps;
    double peak = 0.0;
    const bool freeRuns = Single && freeRuns_ && params_.solver != ImpactSolver::Explicit &&
                          listen_ == resonator_.outputPickup(); // (see runFree)
    for (int i = 0; i < n; ++i) {
        if (freeRuns && !inContact_ && lastForce_ == 0.0) { // (runFree's cheap tests)
            // When the next sample would touch, runFree() finds no sample to run: after a failed
            // try, the next samples step without trying.
            if (freeRetryIn_ > 0) {
                --freeRetryIn_;
            } else {
                const FreeRun run = runFree(fext, i, n, out);
                if (run.samples > 0) {
                    peak = std::max(peak, run.peak);
                    i += run.samples - 1;
                    continue;
                }
                freeRetryIn_ = kFreeRetrySamples;
            }
        }
        const double fNext = fext ? double(fext[i]) : 0.0;
        double y = 0.0;
        // One step from force f0 to f1; when the bodies touch in it, `sub` exact sub-steps.
        // Inside a strike the single-step trial is discarded sample after sample (its force
        // changes by far more than substepForceChange): after a sample whose force changed by
        // more than kSubstepNextFactor times that, the next one is sub-stepped at once (see
        // substepSample). Sub-steps are never less accurate than the single step; where the
        // trial would have been discarded, the samples are exactly those of trying it first.
        const auto advance = [&](double f0, double f1) {
            if (substepNext_ || !step(f0, f1, sub > 1, y)) substepSample(f0, f1, y);
        };
        if constexpr (Single) { // (the same force values as the general interpolation below gives)
            advance(lastExternal_, lastExternal_ + (fNext - lastExternal_));
        } else {
            for (int k = 0; k < os; ++k) {
                // Linear interpolation of the external force inside the sample.
                advance(lastExternal_ + (fNext - lastExternal_) * double(k) / os,
                        lastExternal_ + (fNext - lastExternal_) * double(k + 1) / os);
                y = decimator_.processSample(y);
            }
        }
        lastExternal_ = fNext;
        out[i] = static_cast<float>(y);
        peak = std::max(peak, std::fabs(y));
    }
    return peak;
}

template <typename Real>
void HuntCrossleyImpactT<Real>::substepSample(double f0, double f1, double& y) noexcept {
    const int sub = params_.contactSubsteps;
    const double before = lastForce_;
    // A contact's transient ends the wait before the next free-run try (spanSamples): once the
    // sole leaves, free runs are tried at once (a wait left over from the failed try at the
    // strike's first sample would step the samples after the contact one by one).
    freeRetryIn_ = 0;
    // (still at the fine rate when the sample before was sub-stepped and chose this one)
    if (!resonator_.fineRate()) setFineRate(true);
    if (substepLoop_ && shape_ == Shape::Hertz && params_.solver == ImpactSolver::Newton) {
        if (resonator_.usesAvx())
            substepsAvx(f0, f1, y);
        else
            substepsGeneric(f0, f1, y);
    } else {
        for (int j = 0; j < sub; ++j) {
            const double f = lastForce_;
            newtonStart_ = newtonStartOf(f, subForce1_, subForce2_);
            step(f0 + (f1 - f0) * double(j) / sub, f0 + (f1 - f0) * double(j + 1) / sub, false, y);
            subForce2_ = subForce1_;
            subForce1_ = f;
        }
    }
    newtonStart_ = -1.0;
    substepNext_ =
        sub > 1 && lastForce_ > 0.0 &&
        std::fabs(lastForce_ - before) >
            kSubstepNextFactor * params_.substepForceChange * std::max(lastForce_, before);
    // The next sample is sub-stepped too: stay at the fine rate (switching settles the deferred
    // commit in a pass of its own; the next sub-step's pass then does it, with the same values).
    if (!substepNext_) {
        setFineRate(false);
        subForce1_ = subForce2_ = 0.0; // (the next sub-steps start a new history)
    }
}

// substepSample's loop for the Hertz law with Newton: per sub-step exactly what step(f_j,
// f_j+1, false, y) does with newtonStart_ set as above (the same operations in the same order:
// the same samples, state and statistics), with the sole's state, the contact's stored energy
// and the time kept in registers over the sub-steps, the resonator's pass (predictInline) and
// the Newton solve inline, and the passivity correction out of line (rare): a strike's block
// runs some forty of these sub-steps (about 550 instructions each instead of 735 through step()).
template <typename Real>
template <bool Wide>
[[gnu::always_inline]] inline void HuntCrossleyImpactT<Real>::substepLoop(double f0, double f1,
                                                                          double& y) noexcept {
    const int sub = params_.contactSubsteps;
    const StepConstants c = stepConstants_;
    const double M = params_.exciterMassKg, T = T_;
    double x = exciterX_, v = exciterV_, last = lastForce_, stored = contactEnergy_;
    double time = time_, s1 = subForce1_, s2 = subForce2_;
    bool inContact = inContact_;
    // The sole and the contact's stored energy back in the members (for correctPassivity, and
    // at the end of the sub-steps).
    auto storeSole = [&]() noexcept {
        exciterX_ = x;
        exciterV_ = v;
        lastForce_ = last;
        contactEnergy_ = stored;
    };
    double fextNext = f0 + (f1 - f0) * double(0) / sub;
    for (int j = 0; j < sub; ++j) {
        // (substepSample's external forces: sub-step j + 1 starts where sub-step j ends)
        const double fextNow = fextNext;
        fextNext = f0 + (f1 - f0) * double(j + 1) / sub;
        const double f = last;
        const double start = newtonStartOf(f, s1, s2);
        // trialAt(fextNow, fextNext, 1, 1)
        const double aNextExt = fextNext * c.perMass;
        const double aNow = (fextNow - last) * c.perMass; // (held 1: 1 x F is F)
        double xPred, vPred;
        soleWithoutContact(c, T, x, v, aNow, aNextExt, xPred, vPred);
        resonator_.template predictInline<Wide>();
        const double ch = xPred - resonator_.predictedPosition(0);
        const double dh = vPred - resonator_.predictedVelocity(0);
        Trial t{};
        t.force = ch > 0.0 ? solveShaped<Shape::Hertz>(ch, dh, start) : 0.0; // (solveForce)
        t.x = xPred - c.xPerForce * t.force;
        t.v = vPred - c.vPerForce * t.force;
        double absorbed = 0.0;
        if (t.force > 0.0 || last > 0.0) { // step()'s passivity guard
            const double bodiesBefore = 0.5 * M * v * v + resonator_.energy();
            const double tolerance = 1e-13 * bodiesBefore;
            t.energy = 0.5 * M * t.v * t.v + resonator_.energyIfCommitted(0, t.force);
            t.work = 0.5 * (fextNow + fextNext) * (t.x - x);
            if (!(stored + (bodiesBefore + t.work - t.energy) >= -tolerance)) [[unlikely]] {
                storeSole();
                newtonStart_ = start;
                t = correctPassivity(fextNow, fextNext, bodiesBefore, tolerance);
            }
            absorbed = bodiesBefore + t.work - t.energy;
        }
        commitStep(t, absorbed, x, v, last, stored, time, inContact); // (step()'s commit)
        s2 = s1;
        s1 = f;
    }
    storeSole();
    time_ = time;
    inContact_ = inContact;
    subForce1_ = s1;
    subForce2_ = s2;
    y = resonator_.velocity(listen_); // (the last sub-step's; the others' are not used)
}

template <typename Real>
void HuntCrossleyImpactT<Real>::substepsGeneric(double f0, double f1, double& y) noexcept {
    substepLoop<false>(f0, f1, y);
}

template <typename Real>
UNDERFOOT_TARGET_AVX void HuntCrossleyImpactT<Real>::substepsAvx(double f0, double f1,
                                                                 double& y) noexcept {
    substepLoop<true>(f0, f1, y);
}

// Free flight: between strikes the sole flies off the floor while the floor rings. A sample in
// which the sole cannot touch the floor is, in step(): the sole's trajectory under the external
// force alone (lastForce_ = 0), the floor's free prediction, no contact force (the compression
// ch = xPred - x0 is not positive), commit(0, 0). Here such samples run at once: the sole's
// trajectory first, with the same operations, for as long as it stays below -1.01 B, B a bound
// on the floor's contact displacement over all later free samples (freeContactBound: its modes'
// energies do not grow; the 1 % covers the rounding of the sums and of a run of at most
// kFreeRunMax samples); then the floor's modes for those samples in one call (ringFree, bit for
// bit the per-sample passes). Right after a contact the sole is still within B of the floor for
// a few hundred samples; then the floor's modes run with step()'s own contact test on each
// sample's contact position, the same values (ringFreeUntilContact), up to the first sample
// that would touch. The first sample that could touch goes through step() as before. So the
// samples, the state and the statistics are exactly those of step() sample by sample.
template <typename Real>
typename HuntCrossleyImpactT<Real>::FreeRun
HuntCrossleyImpactT<Real>::runFree(const float* fext, int from, int n, float* out) noexcept {
    // (the caller checked no contact, no force held, a single rate, an implicit solver and the
    // output pickup)
    if (!resonator_.ringsFree()) return {};
    const double margin = 1.01 * resonator_.freeContactBound(); // (NaN: no run)
    const int most = std::min(n - from, ModalResonatorT<Real>::kFreeRunMax);
    const double T = T_, held = lastForce_;
    const StepConstants constants = stepConstants_;
    double x = exciterX_, v = exciterV_, last = lastExternal_, time = time_;
    int count = 0;
    for (; count < most; ++count) {
        const double fNext = fext ? double(fext[from + count]) : 0.0;
        double xPred, vPred;
        soleInFreeRun(constants, T, held, last, fNext, x, v, xPred, vPred);
        if (!(xPred < -margin)) break;
        x = xPred;
        v = vPred;
        last = fNext;
        time += T;
    }
    if (count == 0) return runFreeTested(fext, from, most, out);
    resonator_.ringFree(count, freeVelocity_);
    return commitFreeRun(count, x, v, last, time, out + from);
}

// Right after a contact the bound (every later sample of the floor's ringing) is far looser
// than the floor's next samples: runFree() then runs the floor's modes while their contact point,
// computed for every sample, stays clear of the sole (step()'s own test on the same values). The
// first sample alone first: where it would touch (a contact under way), the try costs one
// sample's flight and pass. (Out of runFree()'s loop, which it made slower.)
template <typename Real>
typename HuntCrossleyImpactT<Real>::FreeRun
HuntCrossleyImpactT<Real>::runFreeTested(const float* fext, int from, int most,
                                         float* out) noexcept {
    const double T = T_, held = lastForce_;
    const StepConstants constants = stepConstants_;
    double last = lastExternal_;
    const auto fly = [&](int t0, int t1) { // the sole's flight for samples [t0, t1)
        for (int t = t0; t < t1; ++t) {
            const double fNext = fext ? double(fext[from + t]) : 0.0;
            soleInFreeRun(constants, T, held, last, fNext, t == 0 ? exciterX_ : soleX_[t - 1],
                          t == 0 ? exciterV_ : soleV_[t - 1], soleX_[t], soleV_[t]);
            last = fNext;
        }
    };
    fly(0, 1);
    if (resonator_.ringFreeUntilContact(1, soleX_, freeVelocity_) == 0) return {};
    fly(1, most);
    const int count = 1 + resonator_.ringFreeUntilContact(most - 1, soleX_ + 1, freeVelocity_ + 1);
    stats_.testedRunSamples += count;
    double time = time_;
    for (int t = 0; t < count; ++t) time += T;
    return commitFreeRun(count, soleX_[count - 1], soleV_[count - 1],
                         fext ? double(fext[from + count - 1]) : 0.0, time, out + from);
}

// The end of a free run of `count` samples: the sole's state, the external force, the time,
// the statistics and the output (the floor's velocities in freeVelocity_).
template <typename Real>
typename HuntCrossleyImpactT<Real>::FreeRun
HuntCrossleyImpactT<Real>::commitFreeRun(int count, double x, double v, double last, double time,
                                         float* out) noexcept {
    exciterX_ = x;
    exciterV_ = v;
    lastExternal_ = last;
    stats_.freeRunSamples += count;
    time_ = time;
    contactEnergy_ = 0.0;
    double peak = 0.0;
    for (int t = 0; t < count; ++t) {
        const double y = freeVelocity_[t];
        out[t] = static_cast<float>(y);
        peak = std::max(peak, std::fabs(y));
    }
    return {count, peak};
}

template <typename Real>
void HuntCrossleyImpactT<Real>::sleepDecision() noexcept {
    const bool pushed = pushedSinceGridPoint_;
    const double peak = peakSinceGridPoint_;
    pushedSinceGridPoint_ = false;
    peakSinceGridPoint_ = 0.0;
    if (!awake_) return;
    resonator_.flushTinyState();
    // Sleep when there is no contact, no push, the exciter is not approaching the floor and
    // the floor rings below the sleep velocity (layers set it to -120 dBFS at their output),
    // judged over the grid span that ends here.
    const bool separating = exciterV_ - resonator_.contactVelocity() <= 1e-9;
    const bool still = !inContact_ && !pushed && separating &&
                       resonator_.peakModalVelocity() < sleepVelocity_ && peak < sleepVelocity_;
    if (still) {
        awake_ = false;
        resonator_.reset();
        decimator_.reset();
        exciterX_ = exciterV_ = lastForce_ = lastExternal_ = 0;
    }
}

template <typename Real>
double HuntCrossleyImpactT<Real>::totalEnergy() const noexcept {
    return 0.5 * params_.exciterMassKg * exciterV_ * exciterV_ + resonator_.energy() +
           contactEnergy_;
}

template class HuntCrossleyImpactT<double>;
template class HuntCrossleyImpactT<float>;

} // namespace underfoot::engine
