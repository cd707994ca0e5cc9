// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/ModalResonator.h"

#include "engine/models/ModalKernels.h"

#include "engine/dsp/Simd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace underfoot::engine {
namespace {

using namespace modal_simd;

inline std::size_t padded(std::size_t n) noexcept {
    return (n + 3) & ~std::size_t(3);
}

// 20-point Gauss–Legendre nodes/weights on [-1, 1] (Abramowitz & Stegun, Table 25.4).
constexpr std::array<double, 10> kGlNodes = {
    0.0765265211334973, 0.2277858511416451, 0.3737060887154195, 0.5108670019508271,
    0.6360536807265150, 0.7463319064601508, 0.8391169718222188, 0.9122344282513259,
    0.9639719272779138, 0.9931285991850949};
constexpr std::array<double, 10> kGlWeights = {
    0.1527533871307258, 0.1491729864726037, 0.1420961093183820, 0.1316886384491766,
    0.1181945319615184, 0.1019301198172404, 0.0832767415767048, 0.0626720483341091,
    0.0406014298003869, 0.0176140071391521};

} // namespace

ModeCoefficients computeModeCoefficients(const Mode& mode, double fs, double quasiStaticFromHz) {
    const double T = 1.0 / fs;
    const double s = std::log(1000.0) / mode.t60Seconds; // decay rate, 1/s
    const double wd = kTwoPi * mode.frequencyHz;         // damped angular frequency
    const double w0sq = wd * wd + s * s;
    ModeCoefficients c{};
    if (mode.frequencyHz >= (quasiStaticFromHz > 0.0 ? quasiStaticFromHz : 0.5 * fs)) {
        // Quasi-static: q[n+1] = u[n+1] / w0^2, v = (q[n+1] - q[n]) / T.
        c.quasiStatic = true;
        c.a00 = 0, c.a01 = 0, c.a10 = -1.0 / T, c.a11 = 0;
        c.b0x = 0, c.b0v = 0;
        c.b1x = 1.0 / w0sq;
        c.b1v = c.b1x / T;
        return c;
    }
    c.quasiStatic = false;
    const double e = std::exp(-s * T), cs = std::cos(wd * T), sn = std::sin(wd * T);
    c.a00 = e * (cs + s * sn / wd);
    c.a01 = e * sn / wd;
    c.a10 = -e * w0sq * sn / wd;
    c.a11 = e * (cs - s * sn / wd);
    // Column 2 of exp(M t): the response of [q, v] to a unit impulse of u.
    auto impulseQ = [&](double t) { return std::exp(-s * t) * std::sin(wd * t) / wd; };
    auto impulseV = [&](double t) {
        return std::exp(-s * t) * (std::cos(wd * t) - s * std::sin(wd * t) / wd);
    };
    // G0 = int_0^T h(t) dt,  G1 = (1/T) int_0^T h(t) (T - t) dt  (Gauss–Legendre, exact to
    // double precision for these smooth integrands over at most half a period).
    double g0x = 0, g0v = 0, g1x = 0, g1v = 0;
    for (std::size_t k = 0; k < kGlNodes.size(); ++k) {
        for (const double sign : {-1.0, 1.0}) {
            const double t = 0.5 * T * (1.0 + sign * kGlNodes[k]);
            const double w = 0.5 * T * kGlWeights[k];
            const double hq = impulseQ(t), hv = impulseV(t);
            g0x += w * hq;
            g0v += w * hv;
            g1x += w * hq * (T - t) / T;
            g1v += w * hv * (T - t) / T;
        }
    }
    c.b1x = g1x;
    c.b1v = g1v;
    c.b0x = g0x - g1x;
    c.b0v = g0v - g1v;
    return c;
}

template <typename Real>
void ModalResonatorT<Real>::configure(std::vector<Mode> modes,
                                      std::vector<std::vector<double>> gains) {
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const auto& m = modes[i];
        if (!(std::isfinite(m.frequencyHz) && m.frequencyHz > 0.0 && std::isfinite(m.t60Seconds) &&
              m.t60Seconds > 0.0 && std::isfinite(m.massKg) && m.massKg > 0.0))
            throw std::invalid_argument("mode " + std::to_string(i + 1) +
                                        ": frequency, t60 and mass must be finite and positive");
    }
    for (const auto& row : gains) {
        if (row.size() != modes.size())
            throw std::invalid_argument("each pickup needs one gain per mode");
        for (double g : row)
            if (!std::isfinite(g)) throw std::invalid_argument("pickup gains must be finite");
    }
    if (gains.empty()) gains.assign(1, std::vector<double>(modes.size(), 1.0));
    modes_ = std::move(modes);
    gains_ = std::move(gains);
    if (sampleRateHz_ > 0.0) prepare(sampleRateHz_);
}

template <typename Real>
void ModalResonatorT<Real>::Bank::assign(std::size_t n2, std::size_t np) {
    for (auto* a : {&a00, &a01, &a10, &a11, &b0x, &b0v, &b1x, &b1v}) a->assign(n2, Real(0));
    lv.assign(n2, 0.0);
    lx.assign(n2, 0.0);
    c2 = 0.0;
    dx0.assign(np, 0.0);
    dv0.assign(np, 0.0);
    dvo.assign(np, 0.0);
}

template <typename Real>
void ModalResonatorT<Real>::fillBank(Bank& b, const std::vector<ModeCoefficients>& cs) {
    const std::size_t n = modes_.size(), np = gains_.size(), n2 = padded(n);
    b.assign(n2, np);
    for (std::size_t i = 0; i < n; ++i) {
        const auto& c = cs[i];
        b.a00[i] = static_cast<Real>(c.a00);
        b.a01[i] = static_cast<Real>(c.a01);
        b.a10[i] = static_cast<Real>(c.a10);
        b.a11[i] = static_cast<Real>(c.a11);
        b.b0x[i] = static_cast<Real>(c.b0x);
        b.b0v[i] = static_cast<Real>(c.b0v);
        b.b1x[i] = static_cast<Real>(c.b1x);
        b.b1v[i] = static_cast<Real>(c.b1v);
        // E(F) around the prediction for a force at pickup 0 (u_i = gamma_i F):
        // sum kin_i (vh_i + gamma_i b1v_i F)^2 + pot_i (qh_i + gamma_i b1x_i F)^2.
        const double gamma = double(gainOverMass_[i]);
        const double bv = gamma * c.b1v, bx = gamma * c.b1x;
        b.lv[i] = 2.0 * kinetic_[i] * bv;
        b.lx[i] = 2.0 * potential_[i] * bx;
        b.c2 += kinetic_[i] * bv * bv + potential_[i] * bx * bx;
    }
    const double* g0 = gains_.front().data();
    for (std::size_t p = 0; p < np; ++p)
        for (std::size_t i = 0; i < n; ++i) {
            const double gamma = double(gainOverMass_[p * n2 + i]);
            b.dx0[p] += g0[i] * (gamma * double(b.b1x[i]));
            b.dv0[p] += g0[i] * (gamma * double(b.b1v[i]));
            b.dvo[p] += outGain_[i] * (gamma * double(b.b1v[i]));
        }
    b.quads.assign(n2 / 4, QuadCoefficients{});
    quadGains_.assign(n2 / 4, QuadGains{});
    for (std::size_t i = 0; i < n2; ++i) {
        auto& c = b.quads[i / 4];
        const std::size_t l = i % 4;
        c.a00[l] = b.a00[i], c.a01[l] = b.a01[i], c.a10[l] = b.a10[i], c.a11[l] = b.a11[i];
        c.b0x[l] = b.b0x[i], c.b0v[l] = b.b0v[i], c.b1x[l] = b.b1x[i], c.b1v[l] = b.b1v[i];
        c.lv[l] = b.lv[i], c.lx[l] = b.lx[i];
        auto& gg = quadGains_[i / 4];
        gg.g0[l] = contactGain_[i], gg.go[l] = outGain_[i];
        gg.kin[l] = kinetic_[i], gg.pot[l] = potential_[i];
    }
}

template <typename Real>
void ModalResonatorT<Real>::prepare(double sampleRateHz, int fineSubsteps) {
    pending_ = false; // the state is reset below
    sampleRateHz_ = sampleRateHz;
    allowAvx(avxAllowed_); // the kernels (the CPU's and UNDERFOOT_SIMD's limit are read once)
    fine_ = false;
    const std::size_t n = modes_.size(), np = gains_.size(), n2 = padded(n);
    coefficients_.resize(n);
    quasiStaticCount_ = 0;
    w0sq_.resize(n);
    kinetic_.assign(n2, 0.0);
    potential_.assign(n2, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double s = std::log(1000.0) / modes_[i].t60Seconds;
        const double wd = kTwoPi * modes_[i].frequencyHz;
        w0sq_[i] = wd * wd + s * s;
        coefficients_[i] = computeModeCoefficients(modes_[i], sampleRateHz);
        quasiStaticCount_ += coefficients_[i].quasiStatic ? 1 : 0;
        kinetic_[i] = coefficients_[i].quasiStatic ? 0.0 : 0.5 * modes_[i].massKg;
        potential_[i] = 0.5 * modes_[i].massKg * w0sq_[i];
    }
    fineCoefficients_.clear();
    if (fineSubsteps > 1) {
        fineCoefficients_.resize(n);
        for (std::size_t i = 0; i < n; ++i)
            fineCoefficients_[i] =
                computeModeCoefficients(modes_[i], sampleRateHz * fineSubsteps, 0.5 * sampleRateHz);
    }
    gainOverMass_.assign(np * n2, Real(0));
    contactGain_.assign(n2, 0.0);
    for (std::size_t i = 0; i < n; ++i) contactGain_[i] = gains_.front()[i];
    kx_.assign(np, 0.0);
    kv_.assign(np, 0.0);
    kxFine_.assign(np, 0.0);
    kvFine_.assign(np, 0.0);
    for (std::size_t p = 0; p < np; ++p) {
        for (std::size_t i = 0; i < n; ++i) {
            const double g = gains_[p][i];
            gainOverMass_[p * n2 + i] = static_cast<Real>(g / modes_[i].massKg);
            kx_[p] += g * g / modes_[i].massKg * coefficients_[i].b1x;
            kv_[p] += g * g / modes_[i].massKg * coefficients_[i].b1v;
            if (!fineCoefficients_.empty()) {
                kxFine_[p] += g * g / modes_[i].massKg * fineCoefficients_[i].b1x;
                kvFine_[p] += g * g / modes_[i].massKg * fineCoefficients_[i].b1v;
            }
        }
    }
    setOutputPickup(std::min(outputPickup_, static_cast<int>(np) - 1)); // fills the banks
    runSums_.assign(static_cast<std::size_t>(4 * kFreeRunMax), 0.0);
    runSums0_.assign(static_cast<std::size_t>(4 * kFreeRunMax), 0.0);
    q_.assign(n2, Real(0));
    v_.assign(n2, Real(0));
    qh_.assign(n2, Real(0));
    vh_.assign(n2, Real(0));
    u_.assign(n2, Real(0));
    heldZero_ = true;
    pending_ = false;
    predictedEnergyValid_ = false;
    energyValid_ = true;
    committedEnergy_ = 0.0;
}

template <typename Real>
void ModalResonatorT<Real>::reset() noexcept {
    std::fill(q_.begin(), q_.end(), Real(0));
    std::fill(v_.begin(), v_.end(), Real(0));
    std::fill(qh_.begin(), qh_.end(), Real(0));
    std::fill(vh_.begin(), vh_.end(), Real(0));
    std::fill(u_.begin(), u_.end(), Real(0));
    x0_ = v0_ = outputVelocity_ = predictedX0_ = predictedV0_ = predictedVo_ = 0.0;
    heldZero_ = true;
    pending_ = false;
    predictedEnergyValid_ = false;
    energyValid_ = true;
    committedEnergy_ = 0.0;
}

template <typename Real>
void ModalResonatorT<Real>::allowAvx(bool on) noexcept {
    avxAllowed_ = on;
    passes_ = kPasses[on && simdAllowsAvx() ? 1 : 0];
    ring_ = passes_ == kPasses[1] ? &ringAvx : &ringGeneric;
    ringChecked_ = passes_ == kPasses[1] ? &ringCheckedAvx : &ringCheckedGeneric;
}

template <typename Real>
template <bool Energy, bool Fused, bool Held, bool Free>
void ModalResonatorT<Real>::passGeneric(ModalResonatorT& r, Real h) noexcept {
    r.passBody<false, Energy, Fused, Held, Free>(h);
}

template <typename Real>
template <bool Energy, bool Fused, bool Held, bool Free>
UNDERFOOT_TARGET_AVX void ModalResonatorT<Real>::passAvx(ModalResonatorT& r, Real h) noexcept {
    r.passBody<true, Energy, Fused, Held, Free>(h);
}

// Free ringing over a run of n samples, quad by quad: each quad's state stays in registers over
// the run, and its contributions to the output pickup's sum are added to per-sample lane sums in
// runSums_, quads in order, starting from zero: per lane the additions of the free pass
// (passBody<..., Free>) in its order, and the lanes are added as it adds them, (lane 0 + lane 2)
// + (lane 1 + lane 3). The contact pickup's sums are needed only for the last sample (its
// prediction), and are added quad by quad as the free pass adds them. So every sample's output,
// and the state after the run, are those of n predict() / commit(p, 0) pairs, bit for bit.
// With Check (ringFreeUntilContact) the contact pickup's sums are kept per sample too (runSums0_,
// added likewise: the x0 step() would test, bit for bit), and the run is committed only when the
// body at soleX stays clear of every one; otherwise it returns the samples before the first
// touch with the state untouched (the run only read it and wrote the prediction buffers).
template <typename Real>
template <bool Wide, bool Check>
[[gnu::always_inline]] inline int ModalResonatorT<Real>::ringBody(int n, const double* soleX,
                                                                  double* voOut) noexcept {
    using V = typename Lanes<Real, Wide>::R;
    using D = typename Lanes<Real, Wide>::D;
    const std::size_t quads = q_.size() / 4;
    const QuadCoefficients* c = bank().quads.data();
    const QuadGains* gg = quadGains_.data();
    const Real *q = q_.data(), *v = v_.data();
    Real *qh = qh_.data(), *vh = vh_.data();
    double* sums = runSums_.data();
    double* sums0 = runSums0_.data();
    D x0{}, v0{};
    for (std::size_t k = 0; k < quads; ++k) {
        const std::size_t i = 4 * k;
        const QuadCoefficients& ck = c[k];
        V qi, vi, a00, a01, a10, a11;
        load4(qi, q + i);
        load4(vi, v + i);
        load4(a00, ck.a00);
        load4(a01, ck.a01);
        load4(a10, ck.a10);
        load4(a11, ck.a11);
        D g0, go, yd{};
        load4(g0, gg[k].g0);
        load4(go, gg[k].go);
        double* s = sums;
        double* s0 = sums0;
        for (int t = 0; t < n; ++t, s += 4, s0 += 4) {
            const V x = a00 * qi + a01 * vi;
            const V y = a10 * qi + a11 * vi;
            qi = x;
            vi = y;
            D so{};
            toDouble(yd, y);
            if (k > 0) load4(so, s);
            so += go * yd;
            store4(s, so);
            if constexpr (Check) {
                D sx{}, xd;
                toDouble(xd, x);
                if (k > 0) load4(sx, s0);
                sx += g0 * xd;
                store4(s0, sx);
            }
        }
        D xd;
        toDouble(xd, qi);
        x0 += g0 * xd;      // the last sample's contact position
        v0 += g0 * yd;      // and velocity
        store4(qh + i, qi); // the last sample's prediction
        store4(vh + i, vi);
    }
    if constexpr (Check) {
        const double* s0 = sums0;
        for (int t = 0; t < n; ++t, s0 += 4) {
            D sx;
            load4(sx, s0);
            if (!(soleX[t] - laneSum(sx) <= 0.0)) return t; // step() would find contact here
        }
    }
    const double* s = sums;
    for (int t = 0; t < n; ++t, s += 4) {
        D so;
        load4(so, s);
        const D2 voh = halves(so);
        voOut[t] = voh[0] + voh[1];
    }
    // The last sample's predict() (its prediction is in qh, vh), then its commit(p, 0).
    const D2 a = pairSum(halves(x0), halves(v0));
    predictedX0_ = a[0];
    predictedV0_ = a[1];
    predictedVo_ = voOut[n - 1];
    predictedEnergyValid_ = false;
    commitWithoutForce();
    return n;
}

template <typename Real>
int ModalResonatorT<Real>::ringCheckedGeneric(ModalResonatorT& r, int n, const double* soleX,
                                              double* vo) noexcept {
    return r.ringBody<false, true>(n, soleX, vo);
}

template <typename Real>
UNDERFOOT_TARGET_AVX int ModalResonatorT<Real>::ringCheckedAvx(ModalResonatorT& r, int n,
                                                               const double* soleX,
                                                               double* vo) noexcept {
    return r.ringBody<true, true>(n, soleX, vo);
}

template <typename Real>
void ModalResonatorT<Real>::ringGeneric(ModalResonatorT& r, int n, double* vo) noexcept {
    r.ringBody<false, false>(n, nullptr, vo);
}

template <typename Real>
UNDERFOOT_TARGET_AVX void ModalResonatorT<Real>::ringAvx(ModalResonatorT& r, int n,
                                                         double* vo) noexcept {
    r.ringBody<true, false>(n, nullptr, vo);
}

template <typename Real>
double ModalResonatorT<Real>::freeContactBound() const noexcept {
    settle();
    double bound = 0.0;
    for (std::size_t i = 0; i < modes_.size(); ++i) {
        const double q = double(q_[i]), v = double(v_[i]);
        bound += std::fabs(contactGain_[i]) * std::sqrt(q * q + v * v / w0sq_[i]);
    }
    return bound;
}

// [kernel][variant]: variant = 4 energy + 2 fused + held, or 8 for free ringing.
template <typename Real>
const typename ModalResonatorT<Real>::PassFn ModalResonatorT<Real>::kPasses[2][9] = {
    {&passGeneric<false, false, false, false>, &passGeneric<false, false, true, false>,
     &passGeneric<false, true, false, false>, &passGeneric<false, true, true, false>,
     &passGeneric<true, false, false, false>, &passGeneric<true, false, true, false>,
     &passGeneric<true, true, false, false>, &passGeneric<true, true, true, false>,
     &passGeneric<false, false, false, true>},
    {&passAvx<false, false, false, false>, &passAvx<false, false, true, false>,
     &passAvx<false, true, false, false>, &passAvx<false, true, true, false>,
     &passAvx<true, false, false, false>, &passAvx<true, false, true, false>,
     &passAvx<true, true, false, false>, &passAvx<true, true, true, false>,
     &passAvx<false, false, false, true>}};

template <typename Real>
void ModalResonatorT<Real>::applyPending() const noexcept {
    using V = typename Lanes<Real, false>::R;
    pending_ = false;
    const std::size_t n4 = q_.size();
    const Real f = pendingForce_;
    const Real* gm = gainOverMass_.data() + pendingPickup_ * n4;
    const QuadCoefficients* c = bank().quads.data();
    const Real *qh = qh_.data(), *vh = vh_.data();
    Real *q = q_.data(), *v = v_.data(), *u = u_.data();
    for (std::size_t i = 0; i < n4; i += 4) {
        V qi, vi, ui;
        completeCommit(qi, vi, ui, c[i / 4], gm + i, qh + i, vh + i, f, q + i, v + i, u + i);
    }
}

template <typename Real>
void ModalResonatorT<Real>::commitWithoutForce() noexcept {
    // No new force: the state is the prediction (swapping the buffers does not allocate), and so
    // are the pickup sums predict() computed.
    q_.swap(qh_);
    v_.swap(vh_);
    if (!heldZero_) std::fill(u_.begin(), u_.end(), Real(0));
    heldZero_ = true;
    x0_ = predictedX0_;
    v0_ = predictedV0_;
    outputVelocity_ = predictedVo_;
    energyValid_ = predictedEnergyValid_;
    committedEnergy_ = predictedEnergy_;
    predictedEnergyValid_ = false;
}

template <typename Real>
double ModalResonatorT<Real>::energyIfCommittedSlow(int p, double forceN) const noexcept {
    const std::size_t n = modes_.size();
    if (p == 0) {
        const Bank& b = bank();
        if (!predictedEnergyValid_) {
            double e = 0.0, slope = 0.0;
            for (std::size_t i = 0; i < n; ++i) {
                const double x = double(qh_[i]), y = double(vh_[i]);
                e += kinetic_[i] * (y * y) + potential_[i] * (x * x);
                slope += b.lv[i] * y + b.lx[i] * x;
            }
            predictedEnergy_ = e;
            predictedEnergySlope_ = slope;
            predictedEnergyValid_ = true;
        }
        return predictedEnergy_ + forceN * predictedEnergySlope_ + forceN * forceN * b.c2;
    }
    const std::size_t off = static_cast<std::size_t>(p) * q_.size();
    double e = 0;
    const ModeCoefficients* cs = fine_ ? fineCoefficients_.data() : coefficients_.data();
    for (std::size_t i = 0; i < n; ++i) {
        const auto& c = cs[i];
        const double u = double(gainOverMass_[off + i]) * forceN;
        const double q = double(qh_[i]) + c.b1x * u;
        const double v = c.quasiStatic ? 0.0 : double(vh_[i]) + c.b1v * u;
        e += 0.5 * modes_[i].massKg * (v * v + w0sq_[i] * q * q);
    }
    return e;
}

template <typename Real>
void ModalResonatorT<Real>::setOutputPickup(int p) {
    settle();
    outputPickup_ = p;
    outGain_.assign(padded(modes_.size()), 0.0);
    for (std::size_t i = 0; i < modes_.size(); ++i)
        if (i < coefficients_.size() && !coefficients_[i].quasiStatic)
            outGain_[i] = gains_.at(static_cast<std::size_t>(p))[i];
    if (coefficients_.size() == modes_.size() && !gainOverMass_.empty()) {
        fillBank(coarseBank_, coefficients_);
        if (!fineCoefficients_.empty()) fillBank(fineBank_, fineCoefficients_);
    }
    predictedEnergyValid_ = false;
}

template <typename Real>
double ModalResonatorT<Real>::pickupSum(const std::vector<Real>& x, int p,
                                        bool radiatingOnly) const noexcept {
    double sum = 0;
    const auto& g = gains_[static_cast<std::size_t>(p)];
    for (std::size_t i = 0; i < modes_.size(); ++i)
        if (!radiatingOnly || !coefficients_[i].quasiStatic) sum += g[i] * double(x[i]);
    return sum;
}

template <typename Real>
double ModalResonatorT<Real>::energyLoop() const noexcept {
    settle();
    double e = 0;
    for (std::size_t i = 0; i < modes_.size(); ++i) {
        const double q = q_[i], v = coefficients_[i].quasiStatic ? 0.0 : double(v_[i]);
        e += 0.5 * modes_[i].massKg * (v * v + w0sq_[i] * q * q);
    }
    return e;
}

template <typename Real>
void ModalResonatorT<Real>::flushTinyState() noexcept {
    settle();
    for (std::size_t i = 0; i < q_.size(); ++i) {
        q_[i] = static_cast<Real>(snapToZero(q_[i]));
        v_[i] = static_cast<Real>(snapToZero(v_[i]));
        u_[i] = static_cast<Real>(snapToZero(u_[i]));
    }
    energyValid_ = false; // the next energy() sums the modes again
    predictedEnergyValid_ = false;
}

template <typename Real>
double ModalResonatorT<Real>::peakModalVelocity() const noexcept {
    settle();
    double m = 0;
    for (std::size_t i = 0; i < modes_.size(); ++i) {
        const double wd = kTwoPi * modes_[i].frequencyHz;
        // Amplitude of the modal velocity including the part stored as displacement.
        m = std::max(m, std::fabs(double(v_[i])) + wd * std::fabs(double(q_[i])));
    }
    return m;
}

template class ModalResonatorT<double>;
template class ModalResonatorT<float>;

} // namespace underfoot::engine
