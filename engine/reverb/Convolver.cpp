// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/Convolver.h"

#include <fmt/format.h>
#include <zita-convolver.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <sched.h>
#include <unistd.h>

#if ZITA_CONVOLVER_MAJOR_VERSION != 4
#error "Convolver.cpp is written against the zita-convolver 4.x API"
#endif

namespace underfoot::engine {

/// One uniformly partitioned FFT stage (a threadless zita-convolver instance).
struct Convolver::Stage {
    Convproc zita;
    int partition = 0;
    int fill = 0;                  // samples of the current block already consumed
    std::vector<float> outL, outR; // this stage's output for the current block

    ~Stage() {
        if (zita.state() == Convproc::ST_PROC) zita.stop_process();
        while (!zita.check_stop()) usleep(100); // no thread: returns at once
        zita.cleanup();
    }
    void start() {
        // quantum == minpart: start_process() starts no thread.
        if (zita.start_process(0, SCHED_OTHER) != 0)
            throw std::runtime_error("Convolver: zita-convolver could not start processing");
        std::fill(outL.begin(), outL.end(), 0.0f);
        std::fill(outR.begin(), outR.end(), 0.0f);
        fill = 0;
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
    for (const auto& s : stages_) sizes.push_back(s->partition);
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

    // FFT stages: [64, 1024) with partition 64, [1024, end) with partition 1024.
    struct Range {
        std::size_t begin, end;
        int partition;
    };
    std::vector<Range> ranges;
    if (len > q) ranges.push_back({q, std::min<std::size_t>(len, kLongPartition), kHeadLength});
    if (len > static_cast<std::size_t>(kLongPartition))
        ranges.push_back({static_cast<std::size_t>(kLongPartition), len, kLongPartition});
    for (const auto& r : ranges) {
        auto stage = std::make_unique<Stage>();
        stage->partition = r.partition;
        const auto p = static_cast<std::size_t>(r.partition);
        // Taps [begin, end) are loaded at positions [begin - P, end - P).
        const auto first = static_cast<int>(r.begin - p), last = static_cast<int>(r.end - p);
        stage->zita.set_options(Convproc::OPT_VECTOR_MODE); // SIMD multiply-add when built in
        int err = stage->zita.configure(
            1, 2, static_cast<std::uint32_t>(last), static_cast<std::uint32_t>(p),
            static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(p), 0.0f);
        if (err != 0)
            throw std::runtime_error(fmt::format(
                "Convolver: zita-convolver configure failed ({}) for an IR of {} samples", err,
                len));
        std::vector<float> taps(left.begin() + static_cast<long>(r.begin),
                                left.begin() + static_cast<long>(r.end));
        err = stage->zita.impdata_create(0, 0, 1, taps.data(), first, last);
        if (err == 0) {
            if (ir.channels == 2) {
                taps.assign(right.begin() + static_cast<long>(r.begin),
                            right.begin() + static_cast<long>(r.end));
                err = stage->zita.impdata_create(0, 1, 1, taps.data(), first, last);
            } else {
                err = stage->zita.impdata_link(0, 0, 0, 1);
            }
        }
        if (err != 0)
            throw std::runtime_error(
                fmt::format("Convolver: zita-convolver could not load the IR ({})", err));
        stage->outL.assign(p, 0.0f);
        stage->outR.assign(p, 0.0f);
        stage->start();
        stages_.push_back(std::move(stage));
    }
}

void Convolver::reset() {
    std::fill(history_.begin(), history_.end(), 0.0f);
    historyPos_ = 0;
    for (auto& s : stages_) {
        if (s->zita.state() == Convproc::ST_PROC) s->zita.stop_process();
        while (!s->zita.check_stop()) usleep(100);
        s->start(); // start_process() clears zita's buffers
    }
}

void Convolver::process(const float* in, float* outL, float* outR, int n) noexcept {
    if (irLength_ == 0) {
        for (int i = 0; i < n; ++i) outL[i] = outR[i] = 0.0f;
        return;
    }
    constexpr int q = kHeadLength;
    for (int i = 0; i < n; ++i) {
        const float x = in[i];
        history_[static_cast<std::size_t>(historyPos_)] = x;
        history_[static_cast<std::size_t>(historyPos_ + q)] = x;
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
        double yl = 0.0, yr = 0.0;
        for (int j = 0; j < 8; ++j) yl += accL[j], yr += accR[j];
        historyPos_ = (historyPos_ + 1) % q;
        for (auto& sp : stages_) {
            Stage& s = *sp;
            const auto f = static_cast<std::size_t>(s.fill);
            yl += s.outL[f];
            yr += s.outR[f];
            s.zita.inpdata(0)[f] = x;
            if (++s.fill == s.partition) {
                s.fill = 0;
                s.zita.process(true); // inline: no level has a thread
                std::memcpy(s.outL.data(), s.zita.outdata(0), sizeof(float) * s.outL.size());
                std::memcpy(s.outR.data(), s.zita.outdata(1), sizeof(float) * s.outR.size());
            }
        }
        outL[i] = static_cast<float>(yl);
        outR[i] = static_cast<float>(yr);
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
