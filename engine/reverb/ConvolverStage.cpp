// SPDX-License-Identifier: GPL-3.0-or-later
// The convolver's stages: the products, FFTs and split transforms of one block, run slice by
// slice, and the schedule that cuts them into slices.
#include "engine/reverb/ConvolverStage.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace underfoot::engine {

using namespace convolver_detail;

void Convolver::Stage::clear() noexcept {
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

void Convolver::Stage::runForward() noexcept {
    fftwf_execute(forward.p);
    storeInput(spectrum.p);
}

void Convolver::Stage::runMac(int j0, int j1, bool first, int b0, int b1) noexcept {
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

void Convolver::Stage::runInversePair() noexcept {
    loadPair(0, static_cast<std::size_t>(P) + 1);
    fftwf_execute(inversePair.p);
    deinterleave(cB.p + 2 * static_cast<std::size_t>(P), outBuf(0, 1 - play), outBuf(1, 1 - play),
                 0, static_cast<std::size_t>(P));
}

void Convolver::Stage::runInverse(int c) noexcept {
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

void Convolver::Stage::runStep1(const Plan& plan, const std::vector<float>& tw, int r0,
                                int r1) noexcept {
    auto* a = reinterpret_cast<fftwf_complex*>(cA.p);
    auto* b = reinterpret_cast<fftwf_complex*>(cB.p);
    for (int r = r0; r < r1; r += group1)
        fftwf_execute_dft(plan.p, a + r, b + static_cast<std::size_t>(r) * n2);
    const std::size_t from = static_cast<std::size_t>(r0) * static_cast<std::size_t>(n2);
    const std::size_t to = static_cast<std::size_t>(r1) * static_cast<std::size_t>(n2);
    cmulInPlace(cB.p + 2 * from, tw.data() + 2 * from, to - from);
}

void Convolver::Stage::runStep3(const Plan& plan, int c0, int c1) noexcept {
    auto* a = reinterpret_cast<fftwf_complex*>(cA.p);
    auto* b = reinterpret_cast<fftwf_complex*>(cB.p);
    for (int c = c0; c < c1; c += group3) fftwf_execute_dft(plan.p, b + c, a + c);
}

void Convolver::Stage::loadPair(std::size_t k0, std::size_t k1) noexcept {
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

void Convolver::Stage::runSplit(const Item& it) noexcept {
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
        deinterleave(cA.p + 2 * p, l, channels == 2 ? r : time.p, static_cast<std::size_t>(it.j0),
                     static_cast<std::size_t>(it.j1));
        break;
    }
    default:
        break;
    }
}

void Convolver::Stage::runSlice(int s) noexcept {
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

void Convolver::Stage::tick() noexcept {
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

void Convolver::Stage::schedule() {
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
            for (int i = 0; i < n_; i += P) atoms.push_back({{Kind::FwdLoad, i, i + P}, 0.35 * P});
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

} // namespace underfoot::engine
