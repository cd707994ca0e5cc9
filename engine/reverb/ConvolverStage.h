// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// One uniformly partitioned overlap-save stage of the convolver (internal to engine/reverb):
/// its buffers and spectra, and the schedule that cuts the work of one input block into
/// slices of about equal cost, one slice every kTick input samples (Convolver.h).
#include "engine/reverb/ConvolverKernels.h"

#include <vector>

namespace underfoot::engine {

/// One uniformly partitioned overlap-save stage: partition P, N partitions, taps [T, T + N P).
struct Convolver::Stage {
    using FftwFloats = convolver_detail::FftwFloats;
    using Plan = convolver_detail::Plan;

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
    FftwFloats cA, cB;           // 2n floats each: complex work buffers
    std::vector<float> twF, twI; // 2n: W_n^(+-i1 k2) at i1 n2 + k2, interleaved
    // group1 / group3 DFTs, new-array execution
    Plan step1F, step3F, step1I, step3I;
    std::vector<Item> items;
    std::vector<int> sliceBegin; // P / kTick + 1 indices into items
    int play = 0;                // which half of out is playing
    int pos = 0;                 // samples of the current period, 0 .. P
    long long block = -1;        // index of the block whose work the slices do (-1: none yet)

    float* outBuf(int c, int which) {
        return out.data() + (static_cast<std::size_t>(c) * 2 + static_cast<std::size_t>(which)) *
                                static_cast<std::size_t>(P);
    }

    void clear() noexcept;

    int slot(long long k) const {
        const long long s = k % N;
        return static_cast<int>(s < 0 ? s + N : s);
    }

    void runForward() noexcept;

    /// The newest input spectrum (interleaved complex, bins 0..P) into xNew. It reaches the ring
    /// in the next period, bin range by bin range, in the older products' runs (runMac): the
    /// scattered writes are spread over that period's slices.
    void storeInput(const float* z) noexcept {
        convolver_detail::storeRecords(z, bins, xNew.data(), convolver_detail::kRecord);
    }

    /// acc[c] (+)= sum over j in [j0, j1) of X[block - j] * H[c][j], bin by bin, in the order of
    /// j; `first`: the sums start from 0. Bins [b0, b1) only (multiples of kLanes): the order of
    /// the operations per bin does not depend on the range.
    /// (The schedule never mixes the newest partition, j = 0, with the older ones in a run, and
    /// runs the older ones over all of [1, N) per bin range: such a run first copies that range
    /// of the previous period's newest spectrum into the ring.)
    void runMac(int j0, int j1, bool first, int b0, int b1) noexcept;

    /// Both channels' inverse as one complex FFT of L + i R (its real part is l, its imaginary
    /// part r), as the split stages do: one FFTW call instead of two real ones.
    void runInversePair() noexcept;

    void runInverse(int c) noexcept;

    // --- split transforms (see the members) ---
    void runStep1(const Plan& plan, const std::vector<float>& tw, int r0, int r1) noexcept;

    void runStep3(const Plan& plan, int c0, int c1) noexcept;

    /// cA (2P interleaved complex) from both channels' accumulated spectra, bins [k0, k1) of
    /// [0, P]: G[k] = L[k] + i R[k] for k <= P, G[2P - k] = conj(L[k]) + i conj(R[k]), whose
    /// inverse is l + i r (both real). (Mono: the one channel twice.)
    void loadPair(std::size_t k0, std::size_t k1) noexcept;

    void runSplit(const Item& it) noexcept;

    void runSlice(int s) noexcept;

    /// Called every kTick input samples, after they were stored.
    void tick() noexcept;

    /// Cuts the work of one block into P / kTick slices of about equal estimated cost,
    /// keeping the order: older products, forward FFT, newest product, inverse FFTs.
    void schedule();
};

} // namespace underfoot::engine
