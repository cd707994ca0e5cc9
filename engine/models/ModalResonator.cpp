// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/ModalResonator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace underfoot::engine {
namespace {

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
void ModalResonatorT<Real>::prepare(double sampleRateHz, int fineSubsteps) {
    sampleRateHz_ = sampleRateHz;
    fine_ = false;
    const std::size_t n = modes_.size(), np = gains_.size();
    coefficients_.resize(n);
    quasiStaticCount_ = 0;
    w0sq_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double s = std::log(1000.0) / modes_[i].t60Seconds;
        const double wd = kTwoPi * modes_[i].frequencyHz;
        w0sq_[i] = wd * wd + s * s;
        coefficients_[i] = computeModeCoefficients(modes_[i], sampleRateHz);
        quasiStaticCount_ += coefficients_[i].quasiStatic ? 1 : 0;
    }
    fineCoefficients_.clear();
    if (fineSubsteps > 1) {
        fineCoefficients_.resize(n);
        for (std::size_t i = 0; i < n; ++i)
            fineCoefficients_[i] =
                computeModeCoefficients(modes_[i], sampleRateHz * fineSubsteps, 0.5 * sampleRateHz);
    }
    gainOverMass_.assign(np * n, Real(0));
    kx_.assign(np, 0.0);
    kv_.assign(np, 0.0);
    kxFine_.assign(np, 0.0);
    kvFine_.assign(np, 0.0);
    for (std::size_t p = 0; p < np; ++p) {
        for (std::size_t i = 0; i < n; ++i) {
            const double g = gains_[p][i];
            gainOverMass_[p * n + i] = static_cast<Real>(g / modes_[i].massKg);
            kx_[p] += g * g / modes_[i].massKg * coefficients_[i].b1x;
            kv_[p] += g * g / modes_[i].massKg * coefficients_[i].b1v;
            if (!fineCoefficients_.empty()) {
                kxFine_[p] += g * g / modes_[i].massKg * fineCoefficients_[i].b1x;
                kvFine_[p] += g * g / modes_[i].massKg * fineCoefficients_[i].b1v;
            }
        }
    }
    setOutputPickup(std::min(outputPickup_, static_cast<int>(np) - 1));
    q_.assign(n, Real(0));
    v_.assign(n, Real(0));
    qh_.assign(n, Real(0));
    vh_.assign(n, Real(0));
    u_.assign(n, Real(0));
    heldZero_ = true;
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
}

template <typename Real>
void ModalResonatorT<Real>::predict(double heldScale) noexcept {
    const std::size_t n = q_.size();
    const Real h = static_cast<Real>(heldScale);
    const double* g0 = gains_.front().data();
    const double* go = outGain_.data();
    const ModeCoefficients* cs = active();
    double x0 = 0.0, v0 = 0.0, vo = 0.0;
    const bool free = heldZero_ || heldScale == 0.0;
    if (free) {
        // Free ringing (no force held from the last sample): the same values without the
        // force terms (they would add exactly zero).
        for (std::size_t i = 0; i < n; ++i) {
            const auto& c = cs[i];
            const Real q = q_[i], v = v_[i];
            qh_[i] = static_cast<Real>(c.a00) * q + static_cast<Real>(c.a01) * v;
            vh_[i] = static_cast<Real>(c.a10) * q + static_cast<Real>(c.a11) * v;
            x0 += g0[i] * double(qh_[i]);
            v0 += g0[i] * double(vh_[i]);
            vo += go[i] * double(vh_[i]);
        }
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            const auto& c = cs[i];
            const Real q = q_[i], v = v_[i], u = h * u_[i];
            qh_[i] = static_cast<Real>(c.a00) * q + static_cast<Real>(c.a01) * v +
                     static_cast<Real>(c.b0x) * u;
            vh_[i] = static_cast<Real>(c.a10) * q + static_cast<Real>(c.a11) * v +
                     static_cast<Real>(c.b0v) * u;
            x0 += g0[i] * double(qh_[i]);
            v0 += g0[i] * double(vh_[i]);
        }
    }
    predictedX0_ = x0;
    predictedV0_ = v0;
    predictedVo_ = vo;
    predictedVoValid_ = free;
}

template <typename Real>
double ModalResonatorT<Real>::predictedPosition(int p) const noexcept {
    if (p == 0) return predictedX0_;
    double x = 0;
    for (std::size_t i = 0; i < q_.size(); ++i)
        x += gains_[static_cast<std::size_t>(p)][i] * qh_[i];
    return x;
}

template <typename Real>
double ModalResonatorT<Real>::predictedVelocity(int p) const noexcept {
    if (p == 0) return predictedV0_;
    const std::size_t n = q_.size();
    double v = 0;
    for (std::size_t i = 0; i < n; ++i) v += gains_[static_cast<std::size_t>(p)][i] * vh_[i];
    return v;
}

template <typename Real>
void ModalResonatorT<Real>::commit(int p, double forceN) noexcept {
    if (forceN == 0.0) {
        // No new force: the state is the prediction (swapping the buffers does not allocate),
        // and so are the pickup sums predict() computed in the same order.
        q_.swap(qh_);
        v_.swap(vh_);
        if (!heldZero_) std::fill(u_.begin(), u_.end(), Real(0));
        heldZero_ = true;
        x0_ = predictedX0_;
        v0_ = predictedV0_;
        if (!predictedVoValid_) { // a held force was predicted (a contact just ended)
            const double* go = outGain_.data();
            double vo = 0.0;
            for (std::size_t i = 0; i < v_.size(); ++i) vo += go[i] * double(v_[i]);
            predictedVo_ = vo;
        }
        outputVelocity_ = predictedVo_;
        return;
    }
    heldZero_ = false;
    const std::size_t n = q_.size(), off = static_cast<std::size_t>(p) * n;
    const Real f = static_cast<Real>(forceN);
    const double* g0 = gains_.front().data();
    const double* go = outGain_.data();
    const ModeCoefficients* cs = active();
    double x0 = 0.0, v0 = 0.0, vo = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto& c = cs[i];
        const Real u = gainOverMass_[off + i] * f;
        q_[i] = qh_[i] + static_cast<Real>(c.b1x) * u;
        v_[i] = vh_[i] + static_cast<Real>(c.b1v) * u;
        u_[i] = u;
        x0 += g0[i] * double(q_[i]);
        v0 += g0[i] * double(v_[i]);
        vo += go[i] * double(v_[i]);
    }
    x0_ = x0;
    v0_ = v0;
    outputVelocity_ = vo;
}

template <typename Real>
double ModalResonatorT<Real>::energyIfCommitted(int p, double forceN) const noexcept {
    const std::size_t n = q_.size(), off = static_cast<std::size_t>(p) * n;
    double e = 0;
    const ModeCoefficients* cs = active();
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
    outputPickup_ = p;
    outGain_.assign(modes_.size(), 0.0);
    for (std::size_t i = 0; i < modes_.size(); ++i)
        if (i < coefficients_.size() && !coefficients_[i].quasiStatic)
            outGain_[i] = gains_.at(static_cast<std::size_t>(p))[i];
}

template <typename Real>
double ModalResonatorT<Real>::position(int p) const noexcept {
    if (p == 0) return x0_;
    double x = 0;
    for (std::size_t i = 0; i < q_.size(); ++i) x += gains_[static_cast<std::size_t>(p)][i] * q_[i];
    return x;
}

template <typename Real>
double ModalResonatorT<Real>::velocity(int p) const noexcept {
    // Quasi-static modes do not radiate (their "velocity" is a finite difference of a compliance).
    if (p == outputPickup_) return outputVelocity_;
    double v = 0;
    for (std::size_t i = 0; i < v_.size(); ++i)
        if (!coefficients_[i].quasiStatic) v += gains_[static_cast<std::size_t>(p)][i] * v_[i];
    return v;
}

template <typename Real>
double ModalResonatorT<Real>::energy() const noexcept {
    double e = 0;
    for (std::size_t i = 0; i < q_.size(); ++i) {
        const double q = q_[i], v = coefficients_[i].quasiStatic ? 0.0 : double(v_[i]);
        e += 0.5 * modes_[i].massKg * (v * v + w0sq_[i] * q * q);
    }
    return e;
}

template <typename Real>
void ModalResonatorT<Real>::flushTinyState() noexcept {
    for (std::size_t i = 0; i < q_.size(); ++i) {
        q_[i] = static_cast<Real>(snapToZero(q_[i]));
        v_[i] = static_cast<Real>(snapToZero(v_[i]));
        u_[i] = static_cast<Real>(snapToZero(u_[i]));
    }
}

template <typename Real>
double ModalResonatorT<Real>::peakModalVelocity() const noexcept {
    double m = 0;
    for (std::size_t i = 0; i < v_.size(); ++i) {
        const double wd = kTwoPi * modes_[i].frequencyHz;
        // Amplitude of the modal velocity including the part stored as displacement.
        m = std::max(m, std::fabs(double(v_[i])) + wd * std::fabs(double(q_[i])));
    }
    return m;
}

template class ModalResonatorT<double>;
template class ModalResonatorT<float>;

} // namespace underfoot::engine
