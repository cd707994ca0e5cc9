// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The convolver's building blocks (internal to engine/reverb): FFTW buffers and plans made
/// under the planner lock, the record layout of the spectra, the products over partitions
/// (SSE, AVX), the direct-form head (SSE, AVX, AVX-512) and the SSE2 passes of the split
/// transforms. Every kernel does per bin and per output the same IEEE operations in the same
/// order (no FMA), so the output does not depend on the instruction set (Convolver.h).
#include "engine/dsp/RealFft.h"
#include "engine/reverb/Convolver.h"

#include <fftw3.h>

#include <cstddef>
#include <cstring>
#include <mutex>
#include <new>

#if !defined(__x86_64__)
#error "the convolver uses SSE/AVX intrinsics (x86-64)"
#endif
#include <immintrin.h>

namespace underfoot::engine::convolver_detail {

/// FFTW's planner is not thread-safe (fftwf_execute is): every plan is made and destroyed
/// under the one planner lock of both precisions, outside the audio thread.
inline std::mutex& plannerMutex() {
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

/// acc (+)= the run's products, for C = 1 or 2 channels, with the kernels of `simd`.
template <int C>
void mac(Convolver::Simd simd, const MacRun& r) noexcept;

/// The direct-form head over a run of m <= kTick outputs: y[t] = sum over k of h[k] x[t - k],
/// with line[kHeadLength - 1 + t] = x[t] (the 63 inputs before the run in front). Every
/// output is the same float sum in the same order (k = 0, 1, ...) in each kernel.
void headSse(const float* hl, const float* hr, const float* line, int m, float* yl,
             float* yr) noexcept;
__attribute__((target("avx"))) void headAvx(const float* hl, const float* hr, const float* line,
                                            int m, float* yl, float* yr) noexcept;
__attribute__((target("avx512f"), optimize("fp-contract=off"))) void
headAvx512(const float* hl, const float* hr, const float* line, int m, float* yl,
           float* yr) noexcept;

/// The widest kernels the CPU runs (limited by UNDERFOOT_SIMD, engine/dsp/Simd.h).
Convolver::Simd cpuSimd() noexcept;

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

} // namespace underfoot::engine::convolver_detail
