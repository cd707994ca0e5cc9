// SPDX-License-Identifier: GPL-3.0-or-later
// The convolver's public side: prepare() builds the head and the stages (partition spectra,
// FFTW plans, schedules), process() runs the head sample by sample and a stage slice every
// kTick input samples.
#include "engine/reverb/Convolver.h"

#include "engine/dsp/Denormals.h"
#include "engine/reverb/ConvolverStage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace underfoot::engine {

using namespace convolver_detail;

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
