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

namespace {
int partitionFor(std::size_t irLength) noexcept {
    const double root = std::sqrt(static_cast<double>(irLength));
    int q = 64;
    while (q < 1024 && std::fabs(std::log2(q * 2.0 / root)) < std::fabs(std::log2(q / root)))
        q *= 2;
    return q;
}
} // namespace

Convolver::Convolver() = default;

Convolver::~Convolver() {
    release();
}

void Convolver::release() noexcept {
    if (!zita_) return;
    if (zita_->state() == Convproc::ST_PROC) zita_->stop_process();
    // No level has a thread (single partition size), so this returns at once.
    while (!zita_->check_stop()) usleep(100);
    zita_->cleanup();
    zita_.reset();
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
    q_ = partitionFor(len);
    const int q = q_;
    headL_.assign(q, 0.0f);
    headR_.assign(q, 0.0f);
    for (std::size_t k = 0; k < std::min<std::size_t>(len, q); ++k) {
        headL_[q - 1 - k] = left[k];
        headR_[q - 1 - k] = right[k];
    }
    history_.assign(2 * q, 0.0f);
    historyPos_ = 0;
    tailL_.assign(q, 0.0f);
    tailR_.assign(q, 0.0f);
    fill_ = 0;

    hasTail_ = len > static_cast<std::size_t>(q);
    if (!hasTail_) return;
    const auto tailLen = static_cast<std::uint32_t>(len - q);
    zita_ = std::make_unique<Convproc>();
    const auto part = static_cast<std::uint32_t>(q);
    int err = zita_->configure(1, 2, tailLen, part, part, part, 0.0f);
    if (err != 0)
        throw std::runtime_error(fmt::format(
            "Convolver: zita-convolver configure failed ({}) for an IR of {} samples", err, len));
    std::vector<float> tail(left.begin() + q, left.end());
    err = zita_->impdata_create(0, 0, 1, tail.data(), 0, static_cast<int>(tailLen));
    if (err == 0) {
        if (ir.channels == 2) {
            tail.assign(right.begin() + q, right.end());
            err = zita_->impdata_create(0, 1, 1, tail.data(), 0, static_cast<int>(tailLen));
        } else {
            err = zita_->impdata_link(0, 0, 0, 1);
        }
    }
    if (err != 0)
        throw std::runtime_error(
            fmt::format("Convolver: zita-convolver could not load the IR ({})", err));
    // quantum == minpart: start_process() starts no thread (the policy is never used; SCHED_OTHER
    // in case a future version does).
    if (zita_->start_process(0, SCHED_OTHER) != 0)
        throw std::runtime_error("Convolver: zita-convolver could not start processing");
}

void Convolver::reset() {
    std::fill(history_.begin(), history_.end(), 0.0f);
    std::fill(tailL_.begin(), tailL_.end(), 0.0f);
    std::fill(tailR_.begin(), tailR_.end(), 0.0f);
    historyPos_ = 0;
    fill_ = 0;
    if (zita_ && hasTail_) {
        if (zita_->state() == Convproc::ST_PROC) zita_->stop_process();
        while (!zita_->check_stop()) usleep(100);
        zita_->start_process(0, SCHED_OTHER); // clears zita's buffers
    }
}

void Convolver::process(const float* in, float* outL, float* outR, int n) noexcept {
    if (irLength_ == 0) {
        for (int i = 0; i < n; ++i) outL[i] = outR[i] = 0.0f;
        return;
    }
    const int q = q_;
    for (int i = 0; i < n; ++i) {
        const float x = in[i];
        history_[static_cast<std::size_t>(historyPos_)] = x;
        history_[static_cast<std::size_t>(historyPos_ + q)] = x;
        const float* window = history_.data() + historyPos_ + 1;
        // Float products summed in 8 independent float lanes (vectorisable); the error of a
        // 1024-tap dot product stays near float rounding (see the accuracy test).
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
        if (hasTail_) {
            const auto f = static_cast<std::size_t>(fill_);
            yl += tailL_[f];
            yr += tailR_[f];
            zita_->inpdata(0)[f] = x;
            if (++fill_ == q) {
                fill_ = 0;
                zita_->process(true); // inline: no level has a thread
                std::memcpy(tailL_.data(), zita_->outdata(0), sizeof(float) * q);
                std::memcpy(tailR_.data(), zita_->outdata(1), sizeof(float) * q);
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
