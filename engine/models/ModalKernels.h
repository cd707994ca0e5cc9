// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The modal resonator's per-mode SIMD kernel (ModalResonatorT::passBody) and its lane helpers,
/// for the translation units that inline it: ModalResonator.cpp (the pass table behind
/// predict()), Impact.cpp (the contact sub-steps) and Friction.cpp (its per-sample kernel), which
/// run the pass inline (ModalResonatorT::predictInline). Not a public header.
#include "engine/models/ModalResonator.h"

#include <cstddef>
#include <cstring>
#include <type_traits>

namespace underfoot::engine {
namespace modal_simd {

// Four modes per step: the per-mode loops below work on quads of lanes over arrays padded to a
// multiple of four with modes whose coefficients are all zero. The same source is compiled twice
// (passGeneric, passAvx, and likewise where it is inlined): with AVX (chosen at run time) a quad of
// doubles is one 256-bit vector (GCC/Clang vector extensions); without it, a quad is written out as
// two SSE2 pairs (`Pairs`: left to GCC's generic lowering, four-lane vectors of doubles kept their
// partial sums on the stack). Either way every lane does the IEEE operation of the scalar code (no
// FMA: neither target enables it), and the pickup sums keep one partial sum per lane, added at the
// end as (lane 0 + lane 2) + (lane 1 + lane 3): a fixed order, so the output is bit-for-bit the
// same on every x86-64 machine and for both kernels. (For up to four modes this is also the order
// of the earlier two-lane loops, whose lanes summed modes 0 + 2 and 1 + 3.)
template <typename Real>
struct Quad {
    typedef Real type __attribute__((vector_size(4 * sizeof(Real))));
};
template <typename Real>
using V4 = typename Quad<Real>::type;
typedef double D4 __attribute__((vector_size(32)));
typedef double D2 __attribute__((vector_size(16)));

// Four doubles as two SSE2 pairs (lanes 0, 1 and 2, 3).
struct Pairs {
    D2 lo, hi;
};
[[gnu::always_inline]] inline Pairs operator+(const Pairs& a, const Pairs& b) noexcept {
    return {a.lo + b.lo, a.hi + b.hi};
}
[[gnu::always_inline]] inline Pairs operator*(const Pairs& a, const Pairs& b) noexcept {
    return {a.lo * b.lo, a.hi * b.hi};
}
[[gnu::always_inline]] inline Pairs operator*(const Pairs& a, double s) noexcept {
    return {a.lo * s, a.hi * s};
}
[[gnu::always_inline]] inline Pairs operator*(double s, const Pairs& a) noexcept {
    return {s * a.lo, s * a.hi};
}
[[gnu::always_inline]] inline Pairs& operator+=(Pairs& a, const Pairs& b) noexcept {
    a.lo += b.lo;
    a.hi += b.hi;
    return a;
}

// The lane types of a kernel: R for the state's Real, D for the double sums.
template <typename Real, bool Wide>
struct Lanes {
    using R = V4<Real>; // float: four lanes in one SSE register either way
    using D = std::conditional_t<Wide, D4, Pairs>;
};
template <>
struct Lanes<double, false> {
    using R = Pairs;
    using D = Pairs;
};

// Loads and stores through references (no vector passed by value: no ABI change between the
// SSE2 and AVX compilations of the same helper).
template <typename V, typename T>
[[gnu::always_inline]] inline void load4(V& v, const T* p) noexcept {
    if constexpr (std::is_same_v<V, Pairs>) {
        std::memcpy(&v.lo, p, sizeof v.lo);
        std::memcpy(&v.hi, p + 2, sizeof v.hi);
    } else {
        std::memcpy(&v, p, sizeof v);
    }
}
template <typename T, typename V>
[[gnu::always_inline]] inline void store4(T* p, const V& v) noexcept {
    if constexpr (std::is_same_v<V, Pairs>) {
        std::memcpy(p, &v.lo, sizeof v.lo);
        std::memcpy(p + 2, &v.hi, sizeof v.hi);
    } else {
        std::memcpy(p, &v, sizeof v);
    }
}
// A quad of Real as a quad of doubles (the sums are in double); through a reference, as above.
template <typename D, typename R>
[[gnu::always_inline]] inline void toDouble(D& out, const R& x) noexcept {
    if constexpr (std::is_same_v<D, R>)
        out = x;
    else if constexpr (std::is_same_v<D, Pairs>)
        out = {D2{double(x[0]), double(x[1])}, D2{double(x[2]), double(x[3])}};
    else
        out = __builtin_convertvector(x, D4);
}
// (lane 0 + lane 2, lane 1 + lane 3)
[[gnu::always_inline]] inline D2 halves(const D4& v) noexcept {
    return D2{v[0], v[1]} + D2{v[2], v[3]};
}
[[gnu::always_inline]] inline D2 halves(const Pairs& v) noexcept {
    return v.lo + v.hi;
}
// (a[0] + a[1], b[0] + b[1])
[[gnu::always_inline]] inline D2 pairSum(const D2& a, const D2& b) noexcept {
    return D2{a[0], b[0]} + D2{a[1], b[1]};
}
template <typename D>
[[gnu::always_inline]] inline double laneSum(const D& v) noexcept {
    const D2 h = halves(v);
    return h[0] + h[1];
}
// Completes a deferred commit for modes i..i+3 (see commit()): u = F g / m, q = qh + b1x u,
// v = vh + b1v u, stored, and returned in (q, v, u) for the pass that goes on from there.
template <typename V, typename Real, typename Coefficients>
[[gnu::always_inline]] inline void completeCommit(V& qi, V& vi, V& uc, const Coefficients& ck,
                                                  const Real* gm, const Real* qh, const Real* vh,
                                                  Real f, Real* q, Real* v, Real* u) noexcept {
    V g, qp, vp, b1x, b1v;
    load4(g, gm);
    load4(qp, qh);
    load4(vp, vh);
    load4(b1x, ck.b1x);
    load4(b1v, ck.b1v);
    uc = g * f;
    qi = qp + b1x * uc;
    vi = vp + b1v * uc;
    store4(q, qi);
    store4(v, vi);
    store4(u, uc);
}

} // namespace modal_simd

// One pass over the modes, four per step (see the top of this file). With `Fused` (a commit
// pending: the last sample's force, see commit()) the state is first completed from the last
// prediction, as a separate commit pass would (the same operations: the same values), then
// predicted. `Held` scales the held force by h (false when h is 1: 1 x u is u, the
// multiplication is skipped, same values). `Free`: no force held (free ringing), the same values
// without the force terms (they would add exactly zero). `Energy`: also the prediction's energy
// and the slope of E(F) (energyIfCommitted).
template <typename Real>
template <bool Wide, bool Energy, bool Fused, bool Held, bool Free>
[[gnu::always_inline]] inline void ModalResonatorT<Real>::passBody(Real h) noexcept {
    using namespace modal_simd;
    using V = typename Lanes<Real, Wide>::R;
    using D = typename Lanes<Real, Wide>::D;
    const std::size_t quads = q_.size() / 4;
    const QuadCoefficients* c = bank().quads.data();
    const QuadGains* gg = quadGains_.data();
    Real *q = q_.data(), *v = v_.data(), *u = u_.data();
    Real *qh = qh_.data(), *vh = vh_.data();
    const Real* gm = gainOverMass_.data() + pendingPickup_ * q_.size();
    const Real f = pendingForce_;
    D x0{}, v0{}, vo{}, e{}, slope{};
    for (std::size_t k = 0; k < quads; ++k) {
        const std::size_t i = 4 * k;
        const QuadCoefficients& ck = c[k];
        V qi, vi, uc, a00, a01, a10, a11;
        if constexpr (Fused) {
            completeCommit(qi, vi, uc, ck, gm + i, qh + i, vh + i, f, q + i, v + i, u + i);
        } else {
            load4(qi, q + i);
            load4(vi, v + i);
            if constexpr (!Free) load4(uc, u + i);
        }
        load4(a00, ck.a00);
        load4(a01, ck.a01);
        load4(a10, ck.a10);
        load4(a11, ck.a11);
        V x, y;
        if constexpr (Free) {
            x = a00 * qi + a01 * vi;
            y = a10 * qi + a11 * vi;
        } else {
            V ui = uc, b0x, b0v;
            if constexpr (Held) ui = h * uc;
            load4(b0x, ck.b0x);
            load4(b0v, ck.b0v);
            x = a00 * qi + a01 * vi + b0x * ui;
            y = a10 * qi + a11 * vi + b0v * ui;
        }
        store4(qh + i, x);
        store4(vh + i, y);
        D xd, yd, g0, go;
        toDouble(xd, x);
        toDouble(yd, y);
        load4(g0, gg[k].g0);
        load4(go, gg[k].go);
        x0 += g0 * xd;
        v0 += g0 * yd;
        vo += go * yd;
        if constexpr (Energy) {
            D kin, pot, lv, lx;
            load4(kin, gg[k].kin);
            load4(pot, gg[k].pot);
            load4(lv, ck.lv);
            load4(lx, ck.lx);
            e += kin * (yd * yd) + pot * (xd * xd);
            slope += lv * yd + lx * xd;
        }
    }
    // Each sum is (lane 0 + lane 2) + (lane 1 + lane 3), two sums per SIMD step.
    const D2 x0h = halves(x0), v0h = halves(v0), voh = halves(vo);
    const D2 a = pairSum(x0h, v0h);
    predictedX0_ = a[0];
    predictedV0_ = a[1];
    if constexpr (Energy) {
        const D2 b = pairSum(voh, halves(e));
        predictedVo_ = b[0];
        predictedEnergy_ = b[1];
        predictedEnergySlope_ = laneSum(slope);
        predictedEnergyValid_ = true;
    } else {
        predictedVo_ = voh[0] + voh[1];
    }
}

// predict(1.0) with its pass inline, for a caller compiled for the kernel's instruction set
// (Wide: AVX): the variant predict() selects (passVariant; with a held scale of 1 the held
// variants, the odd ones, do not occur), as kPasses lists them.
template <typename Real>
template <bool Wide>
[[gnu::always_inline]] inline void ModalResonatorT<Real>::predictInline() noexcept {
    predictedEnergyValid_ = false;
    const int variant = passVariant(1.0);
    pending_ = false;
    switch (variant) {
    case 8:
        return passBody<Wide, false, false, false, true>(Real(1));
    case 6:
        return passBody<Wide, true, true, false, false>(Real(1));
    case 4:
        return passBody<Wide, true, false, false, false>(Real(1));
    case 2:
        return passBody<Wide, false, true, false, false>(Real(1));
    default:
        return passBody<Wide, false, false, false, false>(Real(1));
    }
}

} // namespace underfoot::engine
