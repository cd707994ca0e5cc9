// SPDX-License-Identifier: GPL-3.0-or-later
// The convolver's kernels: products over partitions (SSE, AVX) and the direct-form head (SSE,
// AVX, AVX-512), each giving the same sums whatever the instruction set.
#include "engine/reverb/ConvolverKernels.h"

#include "engine/dsp/Simd.h"

namespace underfoot::engine::convolver_detail {

// Per bin: s = s + (xr hr - xi hi), t = t + (xr hi + xi hr), partition after partition, no FMA:
// the SSE and AVX kernels (and so every CPU) give the same sums.
#define UNDERFOOT_MAC_KERNEL(NAME, ATTR, V, W, LOAD, STORE, ADD, SUB, MUL, ZERO)                   \
    template <int C>                                                                               \
    ATTR void NAME(const MacRun& r) noexcept {                                                     \
        for (int k = 0; k < r.blocks; ++k) {                                                       \
            const float* xb = r.x + static_cast<std::size_t>(k) * r.xBlock;                        \
            const float* hb = r.h + static_cast<std::size_t>(k) * r.hBlock;                        \
            const std::size_t ab = static_cast<std::size_t>(k) * kLanes;                           \
            for (int w = 0; w < kLanes; w += W) {                                                  \
                V sr[C], si[C];                                                                    \
                for (int c = 0; c < C; ++c) {                                                      \
                    float* ar = r.accRe + c * r.accStride + ab + w;                                \
                    float* ai = r.accIm + c * r.accStride + ab + w;                                \
                    sr[c] = r.first ? ZERO() : LOAD(ar);                                           \
                    si[c] = r.first ? ZERO() : LOAD(ai);                                           \
                }                                                                                  \
                const float* hq = hb + w;                                                          \
                for (int q = 0; q < r.count; ++q, hq += C * kRecord) {                             \
                    const float* xq = xb + r.slotOff[q] + w;                                       \
                    const V xr = LOAD(xq), xi = LOAD(xq + kLanes);                                 \
                    for (int c = 0; c < C; ++c) {                                                  \
                        const V hr = LOAD(hq + c * kRecord), hi = LOAD(hq + c * kRecord + kLanes); \
                        sr[c] = ADD(sr[c], SUB(MUL(xr, hr), MUL(xi, hi)));                         \
                        si[c] = ADD(si[c], ADD(MUL(xr, hi), MUL(xi, hr)));                         \
                    }                                                                              \
                }                                                                                  \
                for (int c = 0; c < C; ++c) {                                                      \
                    STORE(r.accRe + c * r.accStride + ab + w, sr[c]);                              \
                    STORE(r.accIm + c * r.accStride + ab + w, si[c]);                              \
                }                                                                                  \
            }                                                                                      \
        }                                                                                          \
    }

UNDERFOOT_MAC_KERNEL(macSse, , __m128, 4, _mm_loadu_ps, _mm_storeu_ps, _mm_add_ps, _mm_sub_ps,
                     _mm_mul_ps, _mm_setzero_ps)
UNDERFOOT_MAC_KERNEL(macAvx, __attribute__((target("avx"))), __m256, 8, _mm256_loadu_ps,
                     _mm256_storeu_ps, _mm256_add_ps, _mm256_sub_ps, _mm256_mul_ps,
                     _mm256_setzero_ps)
#undef UNDERFOOT_MAC_KERNEL

/// A record is kLanes wide, so AVX-512 runs the AVX kernel (same sums).
template <int C>
void mac(Convolver::Simd simd, const MacRun& r) noexcept {
    if (simd == Convolver::Simd::Sse)
        macSse<C>(r);
    else
        macAvx<C>(r);
}

template void mac<1>(Convolver::Simd, const MacRun&) noexcept;
template void mac<2>(Convolver::Simd, const MacRun&) noexcept;

namespace {
/// The direct head's last outputs of a run, one at a time (the same sums as the vectors).
inline void headScalar(const float* hl, const float* hr, const float* line, int t0, int m,
                       float* yl, float* yr) noexcept {
    constexpr int q = Convolver::kHeadLength;
    for (int t = t0; t < m; ++t) {
        float l = 0.0f, r = 0.0f;
        for (int k = 0; k < q; ++k) {
            const float x = line[q - 1 + t - k];
            l = l + hl[k] * x;
            r = r + hr[k] * x;
        }
        yl[t] = l;
        yr[t] = r;
    }
}
} // namespace

void headSse(const float* hl, const float* hr, const float* line, int m, float* yl,
             float* yr) noexcept {
    constexpr int q = Convolver::kHeadLength;
    int t = 0;
    for (; t + 4 <= m; t += 4) {
        __m128 l = _mm_setzero_ps(), r = l;
        for (int k = 0; k < q; ++k) {
            const __m128 x = _mm_loadu_ps(line + q - 1 + t - k);
            l = _mm_add_ps(l, _mm_mul_ps(_mm_set1_ps(hl[k]), x));
            r = _mm_add_ps(r, _mm_mul_ps(_mm_set1_ps(hr[k]), x));
        }
        _mm_storeu_ps(yl + t, l);
        _mm_storeu_ps(yr + t, r);
    }
    headScalar(hl, hr, line, t, m, yl, yr);
}

// The wide heads: pairs of vectors of W outputs share the tap broadcasts, then single vectors,
// then TAIL finishes the last < W outputs from t on. Each output's sum runs over the taps in the
// same order as in headScalar: every kernel gives the same sums.
#define UNDERFOOT_HEAD_KERNEL(NAME, ATTR, V, W, LOAD, STORE, ADD, MUL, ZERO, SET1, TAIL)           \
    ATTR void NAME(const float* hl, const float* hr, const float* line, int m, float* yl,          \
                   float* yr) noexcept {                                                           \
        constexpr int q = Convolver::kHeadLength;                                                  \
        int t = 0;                                                                                 \
        for (; t + 2 * (W) <= m; t += 2 * (W)) {                                                   \
            V l0 = ZERO(), l1 = l0, r0 = l0, r1 = l0;                                              \
            for (int k = 0; k < q; ++k) {                                                          \
                const V x0 = LOAD(line + q - 1 + t - k);                                           \
                const V x1 = LOAD(line + q - 1 + t - k + (W));                                     \
                const V a = SET1(hl[k]), b = SET1(hr[k]);                                          \
                l0 = ADD(l0, MUL(a, x0));                                                          \
                l1 = ADD(l1, MUL(a, x1));                                                          \
                r0 = ADD(r0, MUL(b, x0));                                                          \
                r1 = ADD(r1, MUL(b, x1));                                                          \
            }                                                                                      \
            STORE(yl + t, l0);                                                                     \
            STORE(yl + t + (W), l1);                                                               \
            STORE(yr + t, r0);                                                                     \
            STORE(yr + t + (W), r1);                                                               \
        }                                                                                          \
        for (; t + (W) <= m; t += (W)) {                                                           \
            V l = ZERO(), r = l;                                                                   \
            for (int k = 0; k < q; ++k) {                                                          \
                const V x = LOAD(line + q - 1 + t - k);                                            \
                l = ADD(l, MUL(SET1(hl[k]), x));                                                   \
                r = ADD(r, MUL(SET1(hr[k]), x));                                                   \
            }                                                                                      \
            STORE(yl + t, l);                                                                      \
            STORE(yr + t, r);                                                                      \
        }                                                                                          \
        TAIL;                                                                                      \
    }

UNDERFOOT_HEAD_KERNEL(headAvx, __attribute__((target("avx"))), __m256, 8, _mm256_loadu_ps,
                      _mm256_storeu_ps, _mm256_add_ps, _mm256_mul_ps, _mm256_setzero_ps,
                      _mm256_set1_ps, headScalar(hl, hr, line, t, m, yl, yr))
// AVX-512F has fused multiply-adds, into which GCC would contract the intrinsics' products and
// sums (-ffp-contract=fast is its default): not in this kernel, whose results must be those of
// the SSE and AVX ones (tested). Its last < 16 outputs go through the AVX kernel.
UNDERFOOT_HEAD_KERNEL(headAvx512, __attribute__((target("avx512f"), optimize("fp-contract=off"))),
                      __m512, 16, _mm512_loadu_ps, _mm512_storeu_ps, _mm512_add_ps, _mm512_mul_ps,
                      _mm512_setzero_ps, _mm512_set1_ps,
                      if (t < m) headAvx(hl, hr, line + t, m - t, yl + t, yr + t))
#undef UNDERFOOT_HEAD_KERNEL

Convolver::Simd cpuSimd() noexcept {
    if (simdAllowsAvx512()) return Convolver::Simd::Avx512;
    if (simdAllowsAvx()) return Convolver::Simd::Avx;
    return Convolver::Simd::Sse;
}

} // namespace underfoot::engine::convolver_detail
