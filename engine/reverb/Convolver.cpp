// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/Convolver.h"

#include "engine/dsp/Denormals.h"
#include "engine/dsp/RealFft.h"
#include "engine/dsp/Simd.h"

#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

#if !defined(__x86_64__)
#error "Convolver.cpp uses SSE/AVX intrinsics (x86-64)"
#endif
#include <immintrin.h>

namespace underfoot::engine {

namespace {

/// FFTW's planner is not thread-safe (fftwf_execute is): every plan is made and destroyed
/// under the one planner lock of both precisions, outside the audio thread.
std::mutex& plannerMutex() {
    return fftwPlannerMutex();
}

/// An FFTW-allocated (SIMD-aligned) float array.
struct FftwFloats {
    float* p = nullptr;
    FftwFloats() = default;
    void allocate(std::size_t n) {
        fftwf_free(p);
        p = fftwf_alloc_real(n);
        if (p == nullptr) throw std::bad_alloc();
        std::memset(p, 0, n * sizeof(float));
    }
    FftwFloats(const FftwFloats&) = delete;
    FftwFloats& operator=(const FftwFloats&) = delete;
    ~FftwFloats() { fftwf_free(p); }
};

struct Plan {
    fftwf_plan p = nullptr;
    ~Plan() {
        if (p == nullptr) return;
        std::lock_guard<std::mutex> lock(plannerMutex());
        fftwf_destroy_plan(p);
    }
};

constexpr int kLanes = 8; // bins per AVX vector; the spectra are padded to a multiple of it
constexpr double kPiConvolver = 3.14159265358979323846;
/// Stages with a partition of at least this many samples cut their FFTs into pieces.
constexpr int kSplitPartition = 1024;

/// The partition spectra and the ring of input spectra are stored in blocks of kLanes bins:
/// per block, one record per partition (input slot), holding per channel kLanes real parts then
/// kLanes imaginary parts. A product over partitions [j0, j1) for a range of blocks then reads
/// each block's records in one contiguous run, and keeps its sums in registers from the first
/// partition to the last (one load and one store of the accumulators per block and run, instead
/// of one per partition pair).
constexpr int kRecord = 2 * kLanes; // floats of one channel's record: kLanes re, kLanes im

/// One run of products: acc[c] (+)= sum over q < count of X[slot q] * H[c][j0 + q], per bin, in
/// the order q = 0, 1, ... (per bin the same IEEE operations whatever the SIMD level).
struct MacRun {
    const float* x;     // block k0's records of the input ring: x + slot * kRecord
    const float* h;     // block k0's record of partition j0, channel 0
    const int* slotOff; // [count]: offset of the input record paired with partition j0 + q
    int count = 0;      // partitions in the run
    std::size_t xBlock; // floats from one block's input records to the next block's
    std::size_t hBlock; // the same for the partition records
    float* accRe;       // [c * accStride + bin]
    float* accIm;
    std::size_t accStride;
    int blocks = 0;     // bin blocks k0 .. k0 + blocks - 1 (acc already offset to block k0)
    bool first = false; // the period's first product: the sums start at 0 (as 0 + product)
};

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

/// The direct-form head over a run of m <= kTick outputs: y[t] = sum over k of h[k] x[t - k],
/// with line[kHeadLength - 1 + t] = x[t] (the 63 inputs before the run in front). Vectorised
/// across outputs: every output is the same float sum in the same order (k = 0, 1, ...) in the
/// AVX, SSE and scalar code, whatever m and wherever the run starts.
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

__attribute__((target("avx"))) void headAvx(const float* hl, const float* hr, const float* line,
                                            int m, float* yl, float* yr) noexcept {
    constexpr int q = Convolver::kHeadLength;
    int t = 0;
    for (; t + 16 <= m; t += 16) { // two vectors of outputs share the tap broadcasts
        __m256 l0 = _mm256_setzero_ps(), l1 = l0, r0 = l0, r1 = l0;
        for (int k = 0; k < q; ++k) {
            const __m256 x0 = _mm256_loadu_ps(line + q - 1 + t - k);
            const __m256 x1 = _mm256_loadu_ps(line + q - 1 + t + 8 - k);
            const __m256 a = _mm256_broadcast_ss(hl + k), b = _mm256_broadcast_ss(hr + k);
            l0 = _mm256_add_ps(l0, _mm256_mul_ps(a, x0));
            l1 = _mm256_add_ps(l1, _mm256_mul_ps(a, x1));
            r0 = _mm256_add_ps(r0, _mm256_mul_ps(b, x0));
            r1 = _mm256_add_ps(r1, _mm256_mul_ps(b, x1));
        }
        _mm256_storeu_ps(yl + t, l0);
        _mm256_storeu_ps(yl + t + 8, l1);
        _mm256_storeu_ps(yr + t, r0);
        _mm256_storeu_ps(yr + t + 8, r1);
    }
    for (; t + 8 <= m; t += 8) {
        __m256 l = _mm256_setzero_ps(), r = l;
        for (int k = 0; k < q; ++k) {
            const __m256 x = _mm256_loadu_ps(line + q - 1 + t - k);
            l = _mm256_add_ps(l, _mm256_mul_ps(_mm256_broadcast_ss(hl + k), x));
            r = _mm256_add_ps(r, _mm256_mul_ps(_mm256_broadcast_ss(hr + k), x));
        }
        _mm256_storeu_ps(yl + t, l);
        _mm256_storeu_ps(yr + t, r);
    }
    headScalar(hl, hr, line, t, m, yl, yr);
}

// AVX-512F has fused multiply-adds, into which GCC would contract the intrinsics' products and
// sums (-ffp-contract=fast is its default): not in this kernel, whose results must be those of
// the SSE and AVX ones (tested).
#define UNDERFOOT_AVX512 __attribute__((target("avx512f"), optimize("fp-contract=off")))
UNDERFOOT_AVX512 void headAvx512(const float* hl, const float* hr, const float* line, int m,
                                 float* yl, float* yr) noexcept {
    constexpr int q = Convolver::kHeadLength;
    int t = 0;
    for (; t + 32 <= m; t += 32) { // two vectors of outputs share the tap broadcasts
        __m512 l0 = _mm512_setzero_ps(), l1 = l0, r0 = l0, r1 = l0;
        for (int k = 0; k < q; ++k) {
            const __m512 x0 = _mm512_loadu_ps(line + q - 1 + t - k);
            const __m512 x1 = _mm512_loadu_ps(line + q - 1 + t + 16 - k);
            const __m512 a = _mm512_set1_ps(hl[k]), b = _mm512_set1_ps(hr[k]);
            l0 = _mm512_add_ps(l0, _mm512_mul_ps(a, x0));
            l1 = _mm512_add_ps(l1, _mm512_mul_ps(a, x1));
            r0 = _mm512_add_ps(r0, _mm512_mul_ps(b, x0));
            r1 = _mm512_add_ps(r1, _mm512_mul_ps(b, x1));
        }
        _mm512_storeu_ps(yl + t, l0);
        _mm512_storeu_ps(yl + t + 16, l1);
        _mm512_storeu_ps(yr + t, r0);
        _mm512_storeu_ps(yr + t + 16, r1);
    }
    for (; t + 16 <= m; t += 16) {
        __m512 l = _mm512_setzero_ps(), r = l;
        for (int k = 0; k < q; ++k) {
            const __m512 x = _mm512_loadu_ps(line + q - 1 + t - k);
            l = _mm512_add_ps(l, _mm512_mul_ps(_mm512_set1_ps(hl[k]), x));
            r = _mm512_add_ps(r, _mm512_mul_ps(_mm512_set1_ps(hr[k]), x));
        }
        _mm512_storeu_ps(yl + t, l);
        _mm512_storeu_ps(yr + t, r);
    }
    if (t < m) headAvx(hl, hr, line + t, m - t, yl + t, yr + t); // the last < 16 outputs
}
#undef UNDERFOOT_AVX512

Convolver::Simd cpuSimd() noexcept { // (limited by UNDERFOOT_SIMD, engine/dsp/Simd.h)
    if (simdAllowsAvx512()) return Convolver::Simd::Avx512;
    if (simdAllowsAvx()) return Convolver::Simd::Avx;
    return Convolver::Simd::Sse;
}

// SSE2 passes of the split transforms. Each does per element exactly the IEEE operations of the
// scalar formula in its comment (no FMA), so results do not depend on the vector width.

/// y[i] *= w[i] for `count` interleaved complex numbers (count even):
/// (yr wr - yi wi, yi wr + yr wi).
inline void cmulInPlace(float* y, const float* w, std::size_t count) noexcept {
    const __m128 sign = _mm_castsi128_ps(
        _mm_set_epi32(0, static_cast<int>(0x80000000u), 0, static_cast<int>(0x80000000u)));
    for (std::size_t i = 0; i < 2 * count; i += 4) {
        const __m128 v = _mm_loadu_ps(y + i), t = _mm_loadu_ps(w + i);
        const __m128 wr = _mm_shuffle_ps(t, t, _MM_SHUFFLE(2, 2, 0, 0));
        const __m128 wi = _mm_shuffle_ps(t, t, _MM_SHUFFLE(3, 3, 1, 1));
        const __m128 sw = _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)); // yi, yr
        // (yr wr + -(yi wi), yi wr + yr wi)
        _mm_storeu_ps(y + i, _mm_add_ps(_mm_mul_ps(v, wr), _mm_xor_ps(_mm_mul_ps(sw, wi), sign)));
    }
}

/// z[2i] = x[i], z[2i + 1] = 0 for i in [i0, i1) (multiples of 4).
inline void realToComplex(const float* x, float* z, std::size_t i0, std::size_t i1) noexcept {
    const __m128 zero = _mm_setzero_ps();
    for (std::size_t i = i0; i < i1; i += 4) {
        const __m128 v = _mm_loadu_ps(x + i);
        _mm_storeu_ps(z + 2 * i, _mm_unpacklo_ps(v, zero));
        _mm_storeu_ps(z + 2 * i + 4, _mm_unpackhi_ps(v, zero));
    }
}

/// re[i] = z[2i], im[i] = z[2i + 1] for i in [i0, i1).
inline void deinterleave(const float* z, float* re, float* im, std::size_t i0,
                         std::size_t i1) noexcept {
    std::size_t i = i0;
    for (; i + 4 <= i1; i += 4) {
        const __m128 a = _mm_loadu_ps(z + 2 * i), b = _mm_loadu_ps(z + 2 * i + 4);
        _mm_storeu_ps(re + i, _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
        _mm_storeu_ps(im + i, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
    }
    for (; i < i1; ++i) {
        re[i] = z[2 * i];
        im[i] = z[2 * i + 1];
    }
}

/// Copies bins [0, bins) of an interleaved complex spectrum z into records: rec + k * recStep
/// is bin block k's record (kLanes real parts, then kLanes imaginary parts).
inline void storeRecords(const float* z, int bins, float* rec, std::size_t recStep) noexcept {
    int b = 0;
    for (; b + kLanes <= bins; b += kLanes, rec += recStep)
        deinterleave(z + 2 * b, rec, rec + kLanes, 0, kLanes);
    if (b < bins) deinterleave(z + 2 * b, rec, rec + kLanes, 0, static_cast<std::size_t>(bins - b));
}

} // namespace

/// One uniformly partitioned overlap-save stage: partition P, N partitions, taps [T, T + N P).
struct Convolver::Stage {
    enum class Kind {
        Mac,
        Forward,
        Inverse,     // one channel's real inverse FFT
        InversePair, // both channels in one complex inverse FFT (l + i r)
        // Split transforms (stages with P >= kSplitPartition): the 2P-point FFTs cut into pieces.
        FwdLoad,  // frame -> complex buffer (imaginary parts 0)
        FwdStep1, // DFTs over n2 of the rows [j0, j1), twiddled
        FwdStep3, // DFTs over n1 of the columns [j0, j1)
        FwdStore, // bins 0..P -> the spectrum ring
        InvLoad,  // the accumulators (L + i R) -> the full Hermitian-pair spectrum
        InvStep1,
        InvStep3,
        InvStore, // samples [P, 2P): real part -> left, imaginary part -> right
    };
    struct Item {
        Kind kind;
        int j0 = 0, j1 = 0; // Mac: partitions [j0, j1); steps: rows / columns [j0, j1)
        bool first = false; // Mac: the first product of the period (its sums start from 0)
        int channel = 0;    // Inverse
        int b0 = 0, b1 = 0; // Mac: bins [b0, b1) (multiples of kLanes)
    };

    int P = 0, N = 0, T = 0, channels = 1, bins = 0, stride = 0;
    bool slack = false;  // T == 2P: the work of a block may take the whole next period
    FftwFloats frame;    // 2P: previous and current input block (the forward FFT's input)
    FftwFloats spectrum; // 2 (P + 1): interleaved complex, FFT output / inverse input
    FftwFloats time;     // 2P: inverse FFT output
    Plan forward, inverse;
    Plan inversePair;       // stereo stages without split transforms: 2P-point complex, cA -> cB
    std::vector<float> cur; // P: the input block being filled
    // Records (see kRecord), the partitions' scaled by 1 / 2P. h0[(k channels + c) kRecord]: bin
    // block k of partition 0, channel c; h[((k (N - 1) + j - 1) channels + c) kRecord]: of
    // partition j >= 1; xNew[k kRecord]: of the newest input spectrum; x[(k N + slot) kRecord]: of
    // the input spectrum of block b in slot(b), a ring of the older ones (block b's record of bin
    // block k is copied there from xNew by period b + 1's products over bin block k, before they
    // read it). The newest product reads h0 and xNew, the older ones h and x: contiguous runs.
    std::vector<float> h0, h, x, xNew;
    std::vector<float> accRe, accIm; // [channel][stride]
    std::vector<int> slotOff;        // [N]: scratch of runMac (offsets of the input records)
    std::vector<float> out;          // [channel][2][P]: playing and being computed
    Convolver::Simd simd = Convolver::Simd::Sse; // kernels (all give the same results)
    // Split transforms: a complex FFT of n = 2P = n1 x n2 points as n1 DFTs of n2 points over
    // the strided input (index i1 + n1 i2), a twiddle W_n^(i1 k2), and n2 DFTs of n1 points
    // (the "four-step" FFT; Bailey 1990; output in natural order). Every piece is a few DFTs,
    // so that the work of one transform spreads over several ticks.
    bool split = false;
    int n1 = 0, n2 = 0, group1 = 0, group3 = 0;
    FftwFloats cA, cB;                   // 2n floats each: complex work buffers
    std::vector<float> twF, twI;         // 2n: W_n^(+-i1 k2) at i1 n2 + k2, interleaved
    Plan step1F, step3F, step1I, step3I; // group1 / group3 DFTs, new-array execution
    std::vector<Item> items;
    std::vector<int> sliceBegin; // P / kTick + 1 indices into items
    int play = 0;                // which half of out is playing
    int pos = 0;                 // samples of the current period, 0 .. P
    long long block = -1;        // index of the block whose work the slices do (-1: none yet)

    float* outBuf(int c, int which) {
        return out.data() + (static_cast<std::size_t>(c) * 2 + static_cast<std::size_t>(which)) *
                                static_cast<std::size_t>(P);
    }

    void clear() noexcept {
        std::fill(frame.p, frame.p + 2 * P, 0.0f);
        std::fill(cur.begin(), cur.end(), 0.0f);
        std::fill(x.begin(), x.end(), 0.0f);
        std::fill(xNew.begin(), xNew.end(), 0.0f);
        std::fill(accRe.begin(), accRe.end(), 0.0f);
        std::fill(accIm.begin(), accIm.end(), 0.0f);
        std::fill(out.begin(), out.end(), 0.0f);
        play = 0;
        pos = 0;
        block = -1;
    }

    int slot(long long k) const {
        const long long s = k % N;
        return static_cast<int>(s < 0 ? s + N : s);
    }

    void runForward() noexcept {
        fftwf_execute(forward.p);
        storeInput(spectrum.p);
    }

    /// The newest input spectrum (interleaved complex, bins 0..P) into xNew. It reaches the ring
    /// in the next period, bin range by bin range, in the older products' runs (runMac): the
    /// scattered writes are spread over that period's slices.
    void storeInput(const float* z) noexcept { storeRecords(z, bins, xNew.data(), kRecord); }

    /// acc[c] (+)= sum over j in [j0, j1) of X[block - j] * H[c][j], bin by bin, in the order of
    /// j; `first`: the sums start from 0. Bins [b0, b1) only (multiples of kLanes): the order of
    /// the operations per bin does not depend on the range.
    /// (The schedule never mixes the newest partition, j = 0, with the older ones in a run, and
    /// runs the older ones over all of [1, N) per bin range: such a run first copies that range
    /// of the previous period's newest spectrum into the ring.)
    void runMac(int j0, int j1, bool first, int b0, int b1) noexcept {
        const auto k0 = static_cast<std::size_t>(b0 / kLanes);
        const auto ch = static_cast<std::size_t>(channels);
        MacRun r{};
        if (j0 == 0) { // the newest spectrum
            slotOff[0] = 0;
            r.x = xNew.data() + k0 * kRecord;
            r.h = h0.data() + k0 * ch * kRecord;
            r.xBlock = kRecord;
            r.hBlock = ch * kRecord;
        } else {
            for (int j = j0; j < j1; ++j)
                slotOff[static_cast<std::size_t>(j - j0)] = slot(block - j) * kRecord;
            const auto n = static_cast<std::size_t>(N);
            r.x = x.data() + k0 * n * kRecord;
            if (j0 == 1) { // the previous period's newest spectrum into the ring, these bins first
                const auto previous = static_cast<std::size_t>(slot(block - 1));
                for (std::size_t k = k0; k < static_cast<std::size_t>(b1 / kLanes); ++k)
                    std::memcpy(x.data() + (k * n + previous) * kRecord, xNew.data() + k * kRecord,
                                sizeof(float) * kRecord);
            }
            r.h = h.data() + (k0 * (n - 1) + static_cast<std::size_t>(j0 - 1)) * ch * kRecord;
            r.xBlock = n * kRecord;
            r.hBlock = (n - 1) * ch * kRecord;
        }
        r.slotOff = slotOff.data();
        r.count = j1 - j0;
        r.accRe = accRe.data() + static_cast<std::size_t>(b0);
        r.accIm = accIm.data() + static_cast<std::size_t>(b0);
        r.accStride = static_cast<std::size_t>(stride);
        r.blocks = (b1 - b0) / kLanes;
        r.first = first;
        if (channels == 2)
            mac<2>(simd, r);
        else
            mac<1>(simd, r);
    }

    /// Both channels' inverse as one complex FFT of L + i R (its real part is l, its imaginary
    /// part r), as the split stages do: one FFTW call instead of two real ones.
    void runInversePair() noexcept {
        loadPair(0, static_cast<std::size_t>(P) + 1);
        fftwf_execute(inversePair.p);
        deinterleave(cB.p + 2 * static_cast<std::size_t>(P), outBuf(0, 1 - play),
                     outBuf(1, 1 - play), 0, static_cast<std::size_t>(P));
    }

    void runInverse(int c) noexcept {
        const float* ar = accRe.data() + static_cast<std::size_t>(c) * stride;
        const float* ai = accIm.data() + static_cast<std::size_t>(c) * stride;
        float* z = spectrum.p;
        for (int b = 0; b < bins; ++b) {
            z[2 * b] = ar[b];
            z[2 * b + 1] = ai[b];
        }
        fftwf_execute(inverse.p);
        std::memcpy(outBuf(c, 1 - play), time.p + P, sizeof(float) * static_cast<std::size_t>(P));
    }

    // --- split transforms (see the members) ---
    void runStep1(const Plan& plan, const std::vector<float>& tw, int r0, int r1) noexcept {
        auto* a = reinterpret_cast<fftwf_complex*>(cA.p);
        auto* b = reinterpret_cast<fftwf_complex*>(cB.p);
        for (int r = r0; r < r1; r += group1)
            fftwf_execute_dft(plan.p, a + r, b + static_cast<std::size_t>(r) * n2);
        const std::size_t from = static_cast<std::size_t>(r0) * static_cast<std::size_t>(n2);
        const std::size_t to = static_cast<std::size_t>(r1) * static_cast<std::size_t>(n2);
        cmulInPlace(cB.p + 2 * from, tw.data() + 2 * from, to - from);
    }

    void runStep3(const Plan& plan, int c0, int c1) noexcept {
        auto* a = reinterpret_cast<fftwf_complex*>(cA.p);
        auto* b = reinterpret_cast<fftwf_complex*>(cB.p);
        for (int c = c0; c < c1; c += group3) fftwf_execute_dft(plan.p, b + c, a + c);
    }

    /// cA (2P interleaved complex) from both channels' accumulated spectra, bins [k0, k1) of
    /// [0, P]: G[k] = L[k] + i R[k] for k <= P, G[2P - k] = conj(L[k]) + i conj(R[k]), whose
    /// inverse is l + i r (both real). (Mono: the one channel twice.)
    void loadPair(std::size_t k0, std::size_t k1) noexcept {
        const auto p = static_cast<std::size_t>(P);
        const std::size_t c1 = channels == 2 ? static_cast<std::size_t>(stride) : 0;
        const float* lr = accRe.data();
        const float* li = accIm.data();
        const float* rr = accRe.data() + c1;
        const float* ri = accIm.data() + c1;
        float* g = cA.p;
        std::size_t k = k0;
        auto one = [&](std::size_t q) {
            g[2 * q] = lr[q] - ri[q];
            g[2 * q + 1] = li[q] + rr[q];
            if (q > 0 && q < p) {
                g[2 * (2 * p - q)] = lr[q] + ri[q];
                g[2 * (2 * p - q) + 1] = rr[q] - li[q];
            }
        };
        for (; k < k1 && (k == 0 || k % 4 != 0); ++k) one(k);
        for (; k + 4 <= k1 && k + 4 <= p; k += 4) {
            const __m128 a = _mm_loadu_ps(lr + k), b = _mm_loadu_ps(li + k);
            const __m128 c = _mm_loadu_ps(rr + k), d = _mm_loadu_ps(ri + k);
            const __m128 re = _mm_sub_ps(a, d), im = _mm_add_ps(b, c);
            _mm_storeu_ps(g + 2 * k, _mm_unpacklo_ps(re, im));
            _mm_storeu_ps(g + 2 * k + 4, _mm_unpackhi_ps(re, im));
            // mirrors of k .. k + 3 at 2P - k .. 2P - k - 3: reversed order
            const __m128 mr =
                _mm_shuffle_ps(_mm_add_ps(a, d), _mm_add_ps(a, d), _MM_SHUFFLE(0, 1, 2, 3));
            const __m128 mi =
                _mm_shuffle_ps(_mm_sub_ps(c, b), _mm_sub_ps(c, b), _MM_SHUFFLE(0, 1, 2, 3));
            float* m = g + 2 * (2 * p - k - 3);
            _mm_storeu_ps(m, _mm_unpacklo_ps(mr, mi));
            _mm_storeu_ps(m + 4, _mm_unpackhi_ps(mr, mi));
        }
        for (; k < k1; ++k) one(k);
    }

    void runSplit(const Item& it) noexcept {
        const auto p = static_cast<std::size_t>(P);
        switch (it.kind) {
        case Kind::FwdLoad: // samples [j0, j1) of the frame
            realToComplex(frame.p, cA.p, static_cast<std::size_t>(it.j0),
                          static_cast<std::size_t>(it.j1));
            break;
        case Kind::FwdStep1:
            runStep1(step1F, twF, it.j0, it.j1);
            break;
        case Kind::FwdStep3:
            runStep3(step3F, it.j0, it.j1);
            break;
        case Kind::FwdStore: {
            // A real signal's DC and Nyquist bins are real (as FFTW's r2c gives).
            cA.p[1] = 0.0f;
            cA.p[2 * (bins - 1) + 1] = 0.0f;
            storeInput(cA.p);
            break;
        }
        case Kind::InvLoad: // bins [j0, j1) of [0, P]
            loadPair(static_cast<std::size_t>(it.j0), static_cast<std::size_t>(it.j1));
            break;
        case Kind::InvStep1:
            runStep1(step1I, twI, it.j0, it.j1);
            break;
        case Kind::InvStep3:
            runStep3(step3I, it.j0, it.j1);
            break;
        case Kind::InvStore: { // samples P + [j0, j1): left = real part, right = imaginary
            float* l = outBuf(0, 1 - play);
            float* r = outBuf(channels - 1, 1 - play); // mono: written after left, same values
            deinterleave(cA.p + 2 * p, l, channels == 2 ? r : time.p,
                         static_cast<std::size_t>(it.j0), static_cast<std::size_t>(it.j1));
            break;
        }
        default:
            break;
        }
    }

    void runSlice(int s) noexcept {
        if (block < 0) return; // no block complete yet: nothing to compute
        for (int i = sliceBegin[static_cast<std::size_t>(s)];
             i < sliceBegin[static_cast<std::size_t>(s) + 1]; ++i) {
            const Item& it = items[static_cast<std::size_t>(i)];
            switch (it.kind) {
            case Kind::Forward:
                runForward();
                break;
            case Kind::Mac:
                runMac(it.j0, it.j1, it.first, it.b0, it.b1);
                break;
            case Kind::Inverse:
                runInverse(it.channel);
                break;
            case Kind::InversePair:
                runInversePair();
                break;
            default:
                runSplit(it);
                break;
            }
        }
    }

    /// Called every kTick input samples, after they were stored.
    void tick() noexcept {
        if (pos == P) {                 // block complete
            if (slack) play = 1 - play; // the previous block's output starts now
            std::memcpy(frame.p, frame.p + P, sizeof(float) * static_cast<std::size_t>(P));
            std::memcpy(frame.p + P, cur.data(), sizeof(float) * static_cast<std::size_t>(P));
            pos = 0;
            ++block;
            runSlice(0);
            if (!slack) play = 1 - play; // computed at once, heard at once
        } else {
            runSlice(pos / kTick);
        }
    }

    /// Cuts the work of one block into P / kTick slices of about equal estimated cost,
    /// keeping the order: older products, forward FFT, newest product, inverse FFTs.
    void schedule() {
        const int slices = slack ? P / kTick : 1;
        // Estimated cost in ns, fitted to every item timed alone on this machine's AMD EPYC (Zen
        // 3, AVX; FFTW_ESTIMATE plans): e.g. on the hall, 2048 stage, a
        // run of the 49 older partitions over 96 bins ~3.4 us, the newest partition over all bins
        // ~3.5 us (a run of one partition pays the accumulators' load and store per bin), a group
        // of 8 strided 64-point DFTs 0.7-1.0 us. Only the relative costs matter: they decide
        // where the slices are cut.
        const double n = 2.0 * P;
        const double fwdCost = 150.0 + 0.2 * n * std::log2(n);   // r2c and its records
        const double invCost = 100.0 + 0.145 * n * std::log2(n); // c2r and its copy, per channel
        // Both channels: a complex FFT (measured: 128 points 141 ns, 512 points 597 ns) and the
        // passes that build L + i R and split l and r.
        const double invPairCost = 25.0 + 0.13 * n * std::log2(n) + 0.8 * (P + 1) + 0.44 * P;
        auto macRunCost = [&](int count, int binCount) {
            return binCount * channels * (0.37 * count + 0.47);
        };
        struct Atom {
            Item item;
            double cost;
        };
        std::vector<Atom> atoms;
        // The products are cut by bin ranges, each over all its partitions: a run reads its
        // records contiguously and keeps its sums in registers. Fine ranges here; the ranges
        // that fall in the same slice are merged below.
        const int blockCount = stride / kLanes;
        const int chunks = std::min(blockCount, 4 * slices);
        auto addMac = [&](int j0, int j1) {
            for (int k = 0; k < chunks; ++k) {
                Item it{Kind::Mac, j0, j1, false, 0};
                it.b0 = blockCount * k / chunks * kLanes;
                it.b1 = blockCount * (k + 1) / chunks * kLanes;
                atoms.push_back({it, macRunCost(j1 - j0, it.b1 - it.b0)});
            }
        };
        if (N > 1) addMac(1, N); // the older spectra's products
        // Split transforms: pieces of a few DFTs with their twiddles, and the passes over the
        // buffers in ranges.
        auto splitFft = [&](bool forwardFft) {
            const int n_ = static_cast<int>(n);
            if (forwardFft)
                for (int i = 0; i < n_; i += P)
                    atoms.push_back({{Kind::FwdLoad, i, i + P}, 0.35 * P});
            else
                for (int k = 0; k <= P; k += P / 4) {
                    const int k1 = std::min(k + P / 4, P + 1);
                    atoms.push_back({{Kind::InvLoad, k, k1}, 0.8 * (k1 - k)});
                }
            const Kind k1 = forwardFft ? Kind::FwdStep1 : Kind::InvStep1;
            const Kind k3 = forwardFft ? Kind::FwdStep3 : Kind::InvStep3;
            for (int r = 0; r < n1; r += group1)
                atoms.push_back(
                    {{k1, r, r + group1}, group1 * n2 * (0.25 * std::log2(double(n2)) + 0.35)});
            for (int c = 0; c < n2; c += group3)
                atoms.push_back({{k3, c, c + group3}, group3 * 0.23 * n1 * std::log2(double(n1))});
            if (forwardFft)
                atoms.push_back({{Kind::FwdStore, 0, bins}, 0.35 * bins});
            else
                atoms.push_back({{Kind::InvStore, 0, P}, 0.44 * P});
        };
        if (split)
            splitFft(true);
        else
            atoms.push_back({{Kind::Forward}, fwdCost});
        addMac(0, 1);
        // The first product of the period (all its bin ranges) clears the accumulators.
        int firstJ = -1;
        for (auto& a : atoms)
            if (a.item.kind == Kind::Mac) {
                if (firstJ < 0) firstJ = a.item.j0;
                if (a.item.j0 == firstJ) a.item.first = true;
            }
        if (split) // both channels in one complex inverse
            splitFft(false);
        else if (channels == 2)
            atoms.push_back({{Kind::InversePair}, invPairCost});
        else
            atoms.push_back({{Kind::Inverse, 0, 0, false, 0}, invCost});
        double total = 0;
        for (const auto& a : atoms) total += a.cost;
        const double share = total / slices;
        items.clear();
        sliceBegin.assign(static_cast<std::size_t>(slices) + 1, 0);
        std::vector<int> sliceOf;
        double cum = 0;
        int last = 0;
        for (const auto& a : atoms) {
            int s = static_cast<int>((cum + 0.5 * a.cost) / share);
            s = std::clamp(s, last, slices - 1); // monotone: the order is kept
            cum += a.cost;
            // Merge a product with the previous one when both fall in the same slice: the same
            // partitions over the next bins.
            if (!items.empty() && s == last && a.item.kind == Kind::Mac &&
                items.back().kind == Kind::Mac && items.back().j0 == a.item.j0 &&
                items.back().j1 == a.item.j1 && items.back().first == a.item.first &&
                items.back().b1 == a.item.b0) {
                items.back().b1 = a.item.b1;
            } else {
                items.push_back(a.item);
                sliceOf.push_back(s);
            }
            last = s;
        }
        // sliceBegin[s] = first item of slice s.
        std::size_t i = 0;
        for (int s = 0; s <= slices; ++s) {
            while (i < sliceOf.size() && sliceOf[i] < s) ++i;
            sliceBegin[static_cast<std::size_t>(s)] = static_cast<int>(i);
        }
        sliceBegin.back() = static_cast<int>(items.size());
    }
};

Convolver::Convolver() = default;

Convolver::~Convolver() {
    release();
}

void Convolver::release() noexcept {
    stages_.clear();
}

std::vector<int> Convolver::partitionSizes() const {
    std::vector<int> sizes;
    for (const auto& s : stages_) sizes.push_back(s->P);
    return sizes;
}

void Convolver::prepare(const AudioBuffer& impulseResponse, double sampleRateHz, int blockSize) {
    if (!(sampleRateHz > 0) || !std::isfinite(sampleRateHz))
        throw std::invalid_argument(
            fmt::format("Convolver: sample rate {} Hz must be positive and finite", sampleRateHz));
    if (blockSize < 1)
        throw std::invalid_argument(
            fmt::format("Convolver: block size {} must be >= 1", blockSize));
    if (impulseResponse.channels < 1 || impulseResponse.channels > 2)
        throw std::invalid_argument(fmt::format(
            "Convolver: impulse response has {} channels; expected 1 (mono) or 2 (stereo)",
            impulseResponse.channels));
    if (impulseResponse.frames() == 0)
        throw std::invalid_argument("Convolver: impulse response is empty");
    for (float v : impulseResponse.samples)
        if (!std::isfinite(v))
            throw std::invalid_argument("Convolver: impulse response holds non-finite samples");
    release();
    simd_ = std::min(cpuSimd(), simdLimit_);

    // Resample; keep the frequency response: taps scale with 1/rate.
    AudioBuffer ir = impulseResponse;
    if (ir.sampleRateHz != sampleRateHz) {
        if (!(ir.sampleRateHz > 0))
            throw std::invalid_argument("Convolver: impulse response has no sample rate");
        const double scale = ir.sampleRateHz / sampleRateHz;
        ir = resample(ir, sampleRateHz);
        for (float& v : ir.samples) v = static_cast<float>(v * scale);
        if (ir.frames() == 0) ir.samples.assign(ir.channels == 2 ? 2u : 1u, 0.0f);
    }
    // Stereo view (mono IR -> both sides).
    const std::size_t len = ir.frames();
    std::vector<float> left = ir.channel(0);
    std::vector<float> right = ir.channels == 2 ? ir.channel(1) : left;
    stereoIr_ = ir.channels == 2;
    ir_.sampleRateHz = sampleRateHz;
    ir_.channels = 2;
    ir_.samples.resize(2 * len);
    for (std::size_t i = 0; i < len; ++i)
        ir_.samples[2 * i] = left[i], ir_.samples[2 * i + 1] = right[i];
    irLength_ = len;

    // Direct-form head.
    constexpr auto q = static_cast<std::size_t>(kHeadLength);
    headL_.assign(q, 0.0f);
    headR_.assign(q, 0.0f);
    for (std::size_t k = 0; k < std::min(len, q); ++k) {
        headL_[k] = left[k];
        headR_[k] = right[k];
    }
    line_.assign(q - 1 + static_cast<std::size_t>(kTick), 0.0f);
    phase_ = 0;

    // FFT stages.
    constexpr int stageCount = static_cast<int>(std::size(kPartitions));
    for (int i = 0; i < stageCount; ++i) {
        const int P = kPartitions[i];
        const std::size_t begin = i == 0 ? q : 2 * static_cast<std::size_t>(P);
        if (len <= begin) break;
        const std::size_t end =
            i + 1 < stageCount ? std::min(len, 2 * static_cast<std::size_t>(kPartitions[i + 1]))
                               : len;
        auto s = std::make_unique<Stage>();
        s->P = P;
        s->T = static_cast<int>(begin);
        s->slack = begin == 2 * static_cast<std::size_t>(P);
        s->N = static_cast<int>((end - begin + static_cast<std::size_t>(P) - 1) /
                                static_cast<std::size_t>(P));
        s->channels = stereoIr_ ? 2 : 1;
        s->bins = P + 1;
        s->stride = (s->bins + kLanes - 1) / kLanes * kLanes;
        const auto P2 = 2 * static_cast<std::size_t>(P);
        const auto stride = static_cast<std::size_t>(s->stride);
        const auto N = static_cast<std::size_t>(s->N);
        const auto ch = static_cast<std::size_t>(s->channels);
        s->frame.allocate(P2);
        s->spectrum.allocate(2 * static_cast<std::size_t>(s->bins));
        // The inverse: split transforms in pieces, else one complex FFT for a stereo IR, else
        // (mono) a real one. The real forward FFT also computes the partitions' spectra below.
        // `time` only for a mono IR: the real inverse's output, or the split inverse's unused
        // imaginary part.
        const bool split = s->slack && P >= kSplitPartition;
        const bool realInverse = !split && !stereoIr_;
        if (!stereoIr_) s->time.allocate(P2);
        {
            std::lock_guard<std::mutex> lock(plannerMutex());
            s->forward.p = fftwf_plan_dft_r2c_1d(
                2 * P, s->frame.p, reinterpret_cast<fftwf_complex*>(s->spectrum.p), FFTW_ESTIMATE);
            if (realInverse)
                s->inverse.p =
                    fftwf_plan_dft_c2r_1d(2 * P, reinterpret_cast<fftwf_complex*>(s->spectrum.p),
                                          s->time.p, FFTW_ESTIMATE);
        }
        if (s->forward.p == nullptr || (realInverse && s->inverse.p == nullptr))
            throw std::runtime_error(
                fmt::format("Convolver: FFTW could not plan a {}-point transform", 2 * P));
        if (!split && stereoIr_) {
            const auto n = static_cast<std::size_t>(2 * P);
            s->cA.allocate(2 * n);
            s->cB.allocate(2 * n);
            std::lock_guard<std::mutex> lock(plannerMutex());
            s->inversePair.p = fftwf_plan_dft_1d(2 * P, reinterpret_cast<fftwf_complex*>(s->cA.p),
                                                 reinterpret_cast<fftwf_complex*>(s->cB.p),
                                                 FFTW_BACKWARD, FFTW_ESTIMATE);
            if (s->inversePair.p == nullptr)
                throw std::runtime_error(fmt::format(
                    "Convolver: FFTW could not plan a {}-point complex transform", 2 * P));
        }
        if (split) {
            s->split = true;
            s->n2 = 64;
            s->n1 = 2 * P / s->n2;
            s->group1 = 8;
            s->group3 = 8;
            const auto n = static_cast<std::size_t>(2 * P);
            s->cA.allocate(2 * n);
            s->cB.allocate(2 * n);
            s->twF.resize(2 * n);
            s->twI.resize(2 * n);
            for (int i1 = 0; i1 < s->n1; ++i1)
                for (int k2 = 0; k2 < s->n2; ++k2) {
                    const double a = -2.0 * kPiConvolver * double(i1) * double(k2) / double(n);
                    const std::size_t at =
                        2 * (static_cast<std::size_t>(i1) * s->n2 + static_cast<std::size_t>(k2));
                    s->twF[at] = static_cast<float>(std::cos(a));
                    s->twF[at + 1] = static_cast<float>(std::sin(a));
                    s->twI[at] = s->twF[at];
                    s->twI[at + 1] = -s->twF[at + 1];
                }
            auto* a = reinterpret_cast<fftwf_complex*>(s->cA.p);
            auto* b = reinterpret_cast<fftwf_complex*>(s->cB.p);
            const unsigned flags = FFTW_ESTIMATE;
            std::lock_guard<std::mutex> lock(plannerMutex());
            for (int sign : {FFTW_FORWARD, FFTW_BACKWARD}) {
                Plan& p1 = sign == FFTW_FORWARD ? s->step1F : s->step1I;
                Plan& p3 = sign == FFTW_FORWARD ? s->step3F : s->step3I;
                p1.p = fftwf_plan_many_dft(1, &s->n2, s->group1, a, nullptr, s->n1, 1, b, nullptr,
                                           1, s->n2, sign, flags);
                p3.p = fftwf_plan_many_dft(1, &s->n1, s->group3, b, nullptr, s->n2, 1, a, nullptr,
                                           s->n2, 1, sign, flags);
                if (p1.p == nullptr || p3.p == nullptr)
                    throw std::runtime_error(fmt::format(
                        "Convolver: FFTW could not plan the pieces of a {}-point transform", n));
            }
        }
        s->cur.assign(static_cast<std::size_t>(P), 0.0f);
        const std::size_t blocks = stride / kLanes;
        s->h0.assign(blocks * ch * kRecord, 0.0f);
        s->h.assign(blocks * (N - 1) * ch * kRecord, 0.0f);
        s->x.assign(blocks * N * kRecord, 0.0f);
        s->xNew.assign(blocks * kRecord, 0.0f);
        s->slotOff.assign(N, 0);
        s->accRe.assign(ch * stride, 0.0f);
        s->accIm.assign(ch * stride, 0.0f);
        s->out.assign(ch * 2 * static_cast<std::size_t>(P), 0.0f);
        s->simd = simd_;
        // Partition spectra: taps [begin + jP, begin + (j+1)P) zero-padded to 2P, scaled by
        // 1 / 2P (FFTW's inverse is unnormalised).
        const float scale = 1.0f / static_cast<float>(P2);
        for (std::size_t c = 0; c < ch; ++c) {
            const std::vector<float>& taps = c == 0 ? left : right;
            for (std::size_t j = 0; j < N; ++j) {
                std::fill(s->frame.p, s->frame.p + P2, 0.0f);
                for (std::size_t k = 0; k < static_cast<std::size_t>(P); ++k) {
                    const std::size_t t = begin + j * static_cast<std::size_t>(P) + k;
                    if (t < end) s->frame.p[k] = taps[t] * scale;
                }
                fftwf_execute(s->forward.p);
                if (j == 0)
                    storeRecords(s->spectrum.p, s->bins, s->h0.data() + c * kRecord, ch * kRecord);
                else
                    storeRecords(s->spectrum.p, s->bins, s->h.data() + ((j - 1) * ch + c) * kRecord,
                                 (N - 1) * ch * kRecord);
            }
        }
        s->schedule();
        s->clear();
        stages_.push_back(std::move(s));
    }
}

void Convolver::reset() noexcept {
    std::fill(line_.begin(), line_.end(), 0.0f);
    phase_ = 0;
    for (auto& s : stages_) s->clear();
}

void Convolver::tick() noexcept {
    for (auto& s : stages_) s->tick();
}

void Convolver::process(const float* in, float* outL, float* outR, int n) noexcept {
    if (irLength_ == 0) {
        for (int i = 0; i < n; ++i) outL[i] = outR[i] = 0.0f;
        return;
    }
    ScopedFlushDenormals flush;
    constexpr int q = kHeadLength;
    float* line = line_.data();
    int i = 0;
    while (i < n) {
        // Up to the next tick: the same operations per sample whatever the host block.
        const int m = std::min(n - i, kTick - phase_);
        const auto bytes = sizeof(float) * static_cast<std::size_t>(m);
        float yl[kTick], yr[kTick];
        std::memcpy(line + q - 1, in + i, bytes); // before any output: in may alias out
        if (simd_ == Simd::Avx512)
            headAvx512(headL_.data(), headR_.data(), line, m, yl, yr);
        else if (simd_ == Simd::Avx)
            headAvx(headL_.data(), headR_.data(), line, m, yl, yr);
        else
            headSse(headL_.data(), headR_.data(), line, m, yl, yr);
        for (auto& sp : stages_) {
            Stage& s = *sp;
            std::memcpy(s.cur.data() + s.pos, line + q - 1, bytes);
            const float* pl = s.outBuf(0, s.play) + s.pos;
            const float* pr = s.outBuf(s.channels - 1, s.play) + s.pos;
            for (int t = 0; t < m; ++t) {
                yl[t] += pl[t];
                yr[t] += pr[t];
            }
            s.pos += m;
        }
        std::memcpy(outL + i, yl, bytes);
        std::memcpy(outR + i, yr, bytes);
        std::memmove(line, line + m, sizeof(float) * (q - 1)); // keep the last 63 inputs
        phase_ += m;
        i += m;
        if (phase_ == kTick) {
            phase_ = 0;
            tick();
        }
    }
}

AudioBuffer convolveOffline(const std::vector<float>& input, double sampleRateHz,
                            const AudioBuffer& impulseResponse) {
    Convolver conv;
    constexpr int kBlock = 1024;
    conv.prepare(impulseResponse, sampleRateHz, kBlock);
    const std::size_t total = input.size() + conv.impulseLength() - 1;
    AudioBuffer out;
    out.sampleRateHz = sampleRateHz;
    out.channels = 2;
    out.samples.resize(2 * total);
    std::vector<float> in(kBlock), l(kBlock), r(kBlock);
    for (std::size_t pos = 0; pos < total; pos += kBlock) {
        const std::size_t m = std::min<std::size_t>(kBlock, total - pos);
        for (std::size_t i = 0; i < m; ++i) in[i] = pos + i < input.size() ? input[pos + i] : 0.0f;
        conv.process(in.data(), l.data(), r.data(), static_cast<int>(m));
        for (std::size_t i = 0; i < m; ++i) {
            out.samples[2 * (pos + i)] = l[i];
            out.samples[2 * (pos + i) + 1] = r[i];
        }
    }
    return out;
}

} // namespace underfoot::engine
