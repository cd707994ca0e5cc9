// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/Convolver.h"

#include "engine/dsp/Denormals.h"

#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define UNDERFOOT_CONV_SSE 1
#endif

namespace underfoot::engine {

namespace {

/// FFTW's planner is not thread-safe (fftwf_execute is): every plan is made and destroyed
/// under this lock, outside the audio thread.
std::mutex& plannerMutex() {
    static std::mutex m;
    return m;
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

constexpr int kLanes = 4; // bins per SIMD vector; the spectra are padded to a multiple of it

} // namespace

/// One uniformly partitioned overlap-save stage: partition P, N partitions, taps [T, T + N P).
struct Convolver::Stage {
    enum class Kind { Mac, Forward, Inverse };
    struct Item {
        Kind kind;
        int j0 = 0, j1 = 0; // Mac: partitions [j0, j1)
        bool first = false; // Mac: the first product of the period (clears the accumulators)
        int channel = 0;    // Inverse
    };

    int P = 0, N = 0, T = 0, channels = 1, bins = 0, stride = 0;
    bool slack = false;  // T == 2P: the work of a block may take the whole next period
    FftwFloats frame;    // 2P: previous and current input block (the forward FFT's input)
    FftwFloats spectrum; // 2 (P + 1): interleaved complex, FFT output / inverse input
    FftwFloats time;     // 2P: inverse FFT output
    Plan forward, inverse;
    std::vector<float> cur;          // P: the input block being filled
    std::vector<float> hRe, hIm;     // [channel][partition][stride], scaled by 1 / 2P
    std::vector<float> xRe, xIm;     // [slot][stride], ring of the last N input spectra
    std::vector<float> accRe, accIm; // [channel][stride]
    std::vector<float> out;          // [channel][2][P]: playing and being computed
    std::vector<int> offsets;        // N: per partition, the ring offset of its spectrum
    std::vector<Item> items;
    std::vector<int> sliceBegin; // P / kTick + 1 indices into items
    int play = 0;                // which half of out is playing
    int pos = 0;                 // samples of the current period, 0 .. P
    long long block = -1;        // index of the block whose work the slices do (-1: none yet)

    float* outBuf(int c, int which) {
        return out.data() + (static_cast<std::size_t>(c) * 2 + static_cast<std::size_t>(which)) *
                                static_cast<std::size_t>(P);
    }

    void clear() {
        std::fill(frame.p, frame.p + 2 * P, 0.0f);
        std::fill(cur.begin(), cur.end(), 0.0f);
        std::fill(xRe.begin(), xRe.end(), 0.0f);
        std::fill(xIm.begin(), xIm.end(), 0.0f);
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
        const std::size_t base = static_cast<std::size_t>(slot(block)) * stride;
        float* re = xRe.data() + base;
        float* im = xIm.data() + base;
        const float* z = spectrum.p;
        for (int b = 0; b < bins; ++b) {
            re[b] = z[2 * b];
            im[b] = z[2 * b + 1];
        }
    }

    /// acc[c] (+)= sum over j in [j0, j1) of X[block - j] * H[c][j], bin by bin.
    void runMac(int j0, int j1, bool first) noexcept {
        for (int j = j0; j < j1; ++j)
            offsets[static_cast<std::size_t>(j)] = slot(block - j) * stride;
        const float* xr = xRe.data();
        const float* xi = xIm.data();
        for (int c = 0; c < channels; ++c) {
            float* ar = accRe.data() + static_cast<std::size_t>(c) * stride;
            float* ai = accIm.data() + static_cast<std::size_t>(c) * stride;
            const float* hr = hRe.data() + static_cast<std::size_t>(c) * N * stride;
            const float* hi = hIm.data() + static_cast<std::size_t>(c) * N * stride;
            for (int b = 0; b < stride; b += kLanes) {
#ifdef UNDERFOOT_CONV_SSE
                __m128 sr = first ? _mm_setzero_ps() : _mm_loadu_ps(ar + b);
                __m128 si = first ? _mm_setzero_ps() : _mm_loadu_ps(ai + b);
                for (int j = j0; j < j1; ++j) {
                    const int o = offsets[static_cast<std::size_t>(j)] + b;
                    const std::size_t h = static_cast<std::size_t>(j) * stride + b;
                    const __m128 a = _mm_loadu_ps(xr + o), bb = _mm_loadu_ps(xi + o);
                    const __m128 c1 = _mm_loadu_ps(hr + h), d = _mm_loadu_ps(hi + h);
                    sr = _mm_add_ps(sr, _mm_sub_ps(_mm_mul_ps(a, c1), _mm_mul_ps(bb, d)));
                    si = _mm_add_ps(si, _mm_add_ps(_mm_mul_ps(a, d), _mm_mul_ps(bb, c1)));
                }
                _mm_storeu_ps(ar + b, sr);
                _mm_storeu_ps(ai + b, si);
#else
                for (int l = 0; l < kLanes; ++l) {
                    float sr = first ? 0.0f : ar[b + l], si = first ? 0.0f : ai[b + l];
                    for (int j = j0; j < j1; ++j) {
                        const int o = offsets[static_cast<std::size_t>(j)] + b + l;
                        const std::size_t h = static_cast<std::size_t>(j) * stride + b + l;
                        sr += xr[o] * hr[h] - xi[o] * hi[h];
                        si += xr[o] * hi[h] + xi[o] * hr[h];
                    }
                    ar[b + l] = sr;
                    ai[b + l] = si;
                }
#endif
            }
        }
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
                runMac(it.j0, it.j1, it.first);
                break;
            case Kind::Inverse:
                runInverse(it.channel);
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
        const double n = 2.0 * P;
        const double fftCost = 0.6 * n * std::log2(n) + n; // FFT plus (de)interleaving
        const double macCost = 3.0 * channels * stride;    // per partition
        struct Atom {
            Item item;
            double cost;
        };
        std::vector<Atom> atoms;
        for (int j = 1; j < N; ++j) atoms.push_back({{Kind::Mac, j, j + 1, false, 0}, macCost});
        atoms.push_back({{Kind::Forward}, fftCost});
        atoms.push_back({{Kind::Mac, 0, 1, false, 0}, macCost});
        for (auto& a : atoms) // the first product of the period clears the accumulators
            if (a.item.kind == Kind::Mac) {
                a.item.first = true;
                break;
            }
        for (int c = 0; c < channels; ++c)
            atoms.push_back({{Kind::Inverse, 0, 0, false, c}, fftCost});
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
            // Merge a product with the previous one when both fall in the same slice.
            if (!items.empty() && s == last && a.item.kind == Kind::Mac &&
                items.back().kind == Kind::Mac && items.back().j1 == a.item.j0 && !a.item.first) {
                items.back().j1 = a.item.j1;
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

    // Direct-form head, reversed.
    constexpr auto q = static_cast<std::size_t>(kHeadLength);
    headL_.assign(q, 0.0f);
    headR_.assign(q, 0.0f);
    for (std::size_t k = 0; k < std::min(len, q); ++k) {
        headL_[q - 1 - k] = left[k];
        headR_[q - 1 - k] = right[k];
    }
    history_.assign(2 * q, 0.0f);
    historyPos_ = 0;
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
        s->time.allocate(P2);
        {
            std::lock_guard<std::mutex> lock(plannerMutex());
            s->forward.p = fftwf_plan_dft_r2c_1d(
                2 * P, s->frame.p, reinterpret_cast<fftwf_complex*>(s->spectrum.p), FFTW_ESTIMATE);
            s->inverse.p = fftwf_plan_dft_c2r_1d(
                2 * P, reinterpret_cast<fftwf_complex*>(s->spectrum.p), s->time.p, FFTW_ESTIMATE);
        }
        if (s->forward.p == nullptr || s->inverse.p == nullptr)
            throw std::runtime_error(
                fmt::format("Convolver: FFTW could not plan a {}-point transform", 2 * P));
        s->cur.assign(static_cast<std::size_t>(P), 0.0f);
        s->hRe.assign(ch * N * stride, 0.0f);
        s->hIm.assign(ch * N * stride, 0.0f);
        s->xRe.assign(N * stride, 0.0f);
        s->xIm.assign(N * stride, 0.0f);
        s->accRe.assign(ch * stride, 0.0f);
        s->accIm.assign(ch * stride, 0.0f);
        s->out.assign(ch * 2 * static_cast<std::size_t>(P), 0.0f);
        s->offsets.assign(N, 0);
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
                float* re = s->hRe.data() + (c * N + j) * stride;
                float* im = s->hIm.data() + (c * N + j) * stride;
                for (int b = 0; b < s->bins; ++b) {
                    re[b] = s->spectrum.p[2 * b];
                    im[b] = s->spectrum.p[2 * b + 1];
                }
            }
        }
        s->schedule();
        s->clear();
        stages_.push_back(std::move(s));
    }
}

void Convolver::reset() {
    std::fill(history_.begin(), history_.end(), 0.0f);
    historyPos_ = 0;
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
    int i = 0;
    while (i < n) {
        // Up to the next tick: the same operations per sample whatever the host block.
        const int m = std::min(n - i, kTick - phase_);
        float x[kTick];
        double yl[kTick], yr[kTick];
        std::memcpy(x, in + i, sizeof(float) * static_cast<std::size_t>(m)); // in may alias out
        for (int t = 0; t < m; ++t) {
            history_[static_cast<std::size_t>(historyPos_)] = x[t];
            history_[static_cast<std::size_t>(historyPos_ + q)] = x[t];
            const float* window = history_.data() + historyPos_ + 1;
            // Float products summed in 8 independent lanes (vectorisable).
            float accL[8] = {}, accR[8] = {};
            const float* hl = headL_.data();
            const float* hr = headR_.data();
            for (int k = 0; k < q; k += 8)
                for (int j = 0; j < 8; ++j) {
                    accL[j] += hl[k + j] * window[k + j];
                    accR[j] += hr[k + j] * window[k + j];
                }
            double l = 0.0, r = 0.0;
            for (int j = 0; j < 8; ++j) l += accL[j], r += accR[j];
            yl[t] = l;
            yr[t] = r;
            historyPos_ = (historyPos_ + 1) % q;
        }
        for (auto& sp : stages_) {
            Stage& s = *sp;
            std::memcpy(s.cur.data() + s.pos, x, sizeof(float) * static_cast<std::size_t>(m));
            const float* pl = s.outBuf(0, s.play) + s.pos;
            const float* pr = s.outBuf(s.channels - 1, s.play) + s.pos;
            for (int t = 0; t < m; ++t) {
                yl[t] += pl[t];
                yr[t] += pr[t];
            }
            s.pos += m;
        }
        for (int t = 0; t < m; ++t) {
            outL[i + t] = static_cast<float>(yl[t]);
            outR[i + t] = static_cast<float>(yr[t]);
        }
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
