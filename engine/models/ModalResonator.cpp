// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/ModalResonator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace underfoot::engine {
namespace {

// Two modes per step: the per-mode loops below work on pairs of lanes with GCC/Clang vector
// extensions (SSE2 on x86-64: every operation is the IEEE operation of each lane, as in scalar
// code, so results do not depend on the machine), over arrays padded to an even length with
// modes whose coefficients are all zero. The pickup sums keep one partial sum per lane (even and
// odd modes) added at the end: a fixed order, so the output is bit-for-bit reproducible.
template <typename Real>
struct Pair {
    typedef Real type __attribute__((vector_size(2 * sizeof(Real))));
};
template <typename Real>
using V2 = typename Pair<Real>::type;
typedef double D2 __attribute__((vector_size(16)));

template <typename T, typename V>
inline V load2(const T* p) noexcept {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <typename T, typename V>
inline void store2(T* p, V v) noexcept {
    std::memcpy(p, &v, sizeof v);
}
inline std::size_t padded(std::size_t n) noexcept {
    return (n + 1) & ~std::size_t(1);
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
    b.pairs.assign(n2 / 2, PairCoefficients{});
    pairGains_.assign(n2 / 2, PairGains{});
    for (std::size_t i = 0; i < n2; ++i) {
        auto& c = b.pairs[i / 2];
        const std::size_t l = i % 2;
        c.a00[l] = b.a00[i], c.a01[l] = b.a01[i], c.a10[l] = b.a10[i], c.a11[l] = b.a11[i];
        c.b0x[l] = b.b0x[i], c.b0v[l] = b.b0v[i], c.b1x[l] = b.b1x[i], c.b1v[l] = b.b1v[i];
        c.lv[l] = b.lv[i], c.lx[l] = b.lx[i];
        auto& gg = pairGains_[i / 2];
        gg.g0[l] = contactGain_[i], gg.go[l] = outGain_[i];
        gg.kin[l] = kinetic_[i], gg.pot[l] = potential_[i];
    }
}

template <typename Real>
void ModalResonatorT<Real>::prepare(double sampleRateHz, int fineSubsteps) {
    pending_ = false; // the state is reset below
    sampleRateHz_ = sampleRateHz;
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
void ModalResonatorT<Real>::predict(double heldScale) noexcept {
    using V = V2<Real>;
    const std::size_t pairs = q_.size() / 2;
    const PairCoefficients* c = bank().pairs.data();
    const PairGains* gg = pairGains_.data();
    D2 x0 = {0.0, 0.0}, v0 = {0.0, 0.0}, vo = {0.0, 0.0};
    predictedEnergyValid_ = false;
    if (pending_ && heldScale == 0.0) settle(); // (the passivity guard's trials; rare)
    if (heldZero_ || heldScale == 0.0) {
        // Free ringing (no force held from the last sample): the same values without the
        // force terms (they would add exactly zero).
        const Real *q = q_.data(), *v = v_.data();
        Real *qh = qh_.data(), *vh = vh_.data();
        for (std::size_t k = 0; k < pairs; ++k) {
            const std::size_t i = 2 * k;
            const V qi = load2<Real, V>(q + i), vi = load2<Real, V>(v + i);
            const V x = load2<Real, V>(c[k].a00) * qi + load2<Real, V>(c[k].a01) * vi;
            const V y = load2<Real, V>(c[k].a10) * qi + load2<Real, V>(c[k].a11) * vi;
            store2(qh + i, x);
            store2(vh + i, y);
            const D2 xd = __builtin_convertvector(x, D2), yd = __builtin_convertvector(y, D2);
            const D2 g0 = load2<double, D2>(gg[k].g0);
            x0 += g0 * xd;
            v0 += g0 * yd;
            vo += load2<double, D2>(gg[k].go) * yd;
        }
    } else {
        const Real h = static_cast<Real>(heldScale);
        D2 e = {0.0, 0.0}, slope = {0.0, 0.0};
        // One pass over the modes: with a commit pending (the last sample's force, see commit())
        // the state is first completed from the last prediction, as a separate commit pass
        // would (the same operations: the same values), then predicted. `held` is false when
        // heldScale is 1 (1 x u is u: the multiplication is skipped, same values).
        auto run = [&](auto withEnergy, auto fused, auto held) {
            Real *q = q_.data(), *v = v_.data(), *u = u_.data();
            Real *qh = qh_.data(), *vh = vh_.data();
            const Real* gm = gainOverMass_.data() + pendingPickup_ * q_.size();
            const Real f = pendingForce_;
            for (std::size_t k = 0; k < pairs; ++k) {
                const std::size_t i = 2 * k;
                V qi, vi, uc;
                if constexpr (decltype(fused)::value) {
                    uc = load2<Real, V>(gm + i) * f;
                    qi = load2<Real, V>(qh + i) + load2<Real, V>(c[k].b1x) * uc;
                    vi = load2<Real, V>(vh + i) + load2<Real, V>(c[k].b1v) * uc;
                    store2(q + i, qi);
                    store2(v + i, vi);
                    store2(u + i, uc);
                } else {
                    qi = load2<Real, V>(q + i);
                    vi = load2<Real, V>(v + i);
                    uc = load2<Real, V>(u + i);
                }
                V ui = uc;
                if constexpr (decltype(held)::value) ui = h * uc;
                const V x = load2<Real, V>(c[k].a00) * qi + load2<Real, V>(c[k].a01) * vi +
                            load2<Real, V>(c[k].b0x) * ui;
                const V y = load2<Real, V>(c[k].a10) * qi + load2<Real, V>(c[k].a11) * vi +
                            load2<Real, V>(c[k].b0v) * ui;
                store2(qh + i, x);
                store2(vh + i, y);
                const D2 xd = __builtin_convertvector(x, D2), yd = __builtin_convertvector(y, D2);
                const D2 g0 = load2<double, D2>(gg[k].g0);
                x0 += g0 * xd;
                v0 += g0 * yd;
                vo += load2<double, D2>(gg[k].go) * yd;
                if constexpr (decltype(withEnergy)::value) {
                    // The prediction's energy and the slope of E(F) (energyIfCommitted).
                    e += load2<double, D2>(gg[k].kin) * (yd * yd) +
                         load2<double, D2>(gg[k].pot) * (xd * xd);
                    slope += load2<double, D2>(c[k].lv) * yd + load2<double, D2>(c[k].lx) * xd;
                }
            }
        };
        using T = std::true_type;
        using F = std::false_type;
        const bool fused = pending_, held = heldScale != 1.0;
        pending_ = false;
        if (trackEnergy_) {
            if (fused)
                held ? run(T{}, T{}, T{}) : run(T{}, T{}, F{});
            else
                held ? run(T{}, F{}, T{}) : run(T{}, F{}, F{});
            predictedEnergy_ = e[0] + e[1];
            predictedEnergySlope_ = slope[0] + slope[1];
            predictedEnergyValid_ = true;
        } else {
            if (fused)
                held ? run(F{}, T{}, T{}) : run(F{}, T{}, F{});
            else
                held ? run(F{}, F{}, T{}) : run(F{}, F{}, F{});
        }
    }
    predictedX0_ = x0[0] + x0[1];
    predictedV0_ = v0[0] + v0[1];
    predictedVo_ = vo[0] + vo[1];
}

template <typename Real>
void ModalResonatorT<Real>::applyPending() const noexcept {
    using V = V2<Real>;
    pending_ = false;
    const std::size_t n2 = q_.size();
    const Real f = pendingForce_;
    const Real* gm = gainOverMass_.data() + pendingPickup_ * n2;
    const PairCoefficients* c = bank().pairs.data();
    const Real *qh = qh_.data(), *vh = vh_.data();
    Real *q = q_.data(), *v = v_.data(), *u = u_.data();
    for (std::size_t i = 0; i < n2; i += 2) {
        const PairCoefficients& ci = c[i / 2];
        const V ui = load2<Real, V>(gm + i) * f;
        store2(q + i, load2<Real, V>(qh + i) + load2<Real, V>(ci.b1x) * ui);
        store2(v + i, load2<Real, V>(vh + i) + load2<Real, V>(ci.b1v) * ui);
        store2(u + i, ui);
    }
}

template <typename Real>
void ModalResonatorT<Real>::commit(int p, double forceN) noexcept {
    settle();
    if (forceN == 0.0) {
        // No new force: the state is the prediction (swapping the buffers does not allocate),
        // and so are the pickup sums predict() computed.
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
        return;
    }
    heldZero_ = false;
    const std::size_t pp = static_cast<std::size_t>(p);
    const Bank& b = bank();
    // The per-mode update q = qh + b1x u, v = vh + b1v u, u = F g / m is deferred into the next
    // predict() (or settle()).
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
