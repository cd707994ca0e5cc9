// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/StepGrfPlayer.h"

#include "base/DataDir.h"
#include "engine/io/AudioFile.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace underfoot::engine {

namespace {

std::vector<std::vector<float>> monoChannels(const std::vector<GrfSignal>& signals, double rateHz,
                                             const char* what) {
    if (signals.empty())
        throw std::invalid_argument(fmt::format("StepGrfPlayer: the {} bank is empty", what));
    std::vector<std::vector<float>> out;
    for (std::size_t i = 0; i < signals.size(); ++i) {
        const GrfSignal& g = signals[i];
        if (g.channels.empty() || g.frames() == 0)
            throw std::invalid_argument(
                fmt::format("StepGrfPlayer: {} GRF {} has no samples", what, i + 1));
        if (g.sampleRateHz != rateHz)
            throw std::invalid_argument(
                fmt::format("StepGrfPlayer: {} GRF {} is at {} Hz, expected {} Hz", what, i + 1,
                            g.sampleRateHz, rateHz));
        for (float v : g.channels[0])
            if (!std::isfinite(v))
                throw std::invalid_argument(
                    fmt::format("StepGrfPlayer: {} GRF {} has a non-finite sample", what, i + 1));
        out.push_back(g.channels[0]);
    }
    return out;
}

} // namespace

StepGrfPlayer::StepGrfPlayer(GrfBank bank, const StepGrfPlayerConfig& config)
    : config_(config), random_(config.seed), steps_(std::max<std::size_t>(config.stepCapacity, 2)),
      playbacks_(std::max<std::size_t>(config.playbackCapacity, 2)) {
    seed_.store(config.seed, std::memory_order_relaxed);
    if (!(config_.sampleRateHz > 0) || !std::isfinite(config_.sampleRateHz))
        throw std::invalid_argument("StepGrfPlayer: sample rate must be a finite number > 0");
    if (config_.maxVoices == 0) throw std::invalid_argument("StepGrfPlayer: maxVoices is 0");
    if (!(config_.minGain >= 0 && config_.minGain <= 1))
        throw std::invalid_argument("StepGrfPlayer: minGain must be in [0, 1]");
    heel_ = monoChannels(bank.heel, config_.sampleRateHz, "heel");
    toe_ = monoChannels(bank.toe, config_.sampleRateHz, "toe");
    voices_.resize(config_.maxVoices);
}

GrfBank StepGrfPlayer::loadBank(const std::string& directory, double sampleRateHz) {
    GrfBank bank;
    GrfLoadOptions options;
    options.targetRateHz = sampleRateHz;
    for (const char* kind : {"heel", "toe"}) {
        auto& list = std::string_view(kind) == "heel" ? bank.heel : bank.toe;
        for (int i = 1;; ++i) {
            const std::string path = fmt::format("{}/{}_{}.wav", directory, kind, i);
            if (!std::filesystem::exists(path)) break;
            list.push_back(loadGrfFile(path, options));
        }
        if (list.empty())
            throw FileError(fmt::format("{}: expected {}_1.wav, {}_2.wav, ... (a GRF bank), found "
                                        "no {}_1.wav",
                                        directory, kind, kind, kind));
    }
    return bank;
}

GrfBank StepGrfPlayer::loadDefaultBank(double sampleRateHz) {
    return loadBank(base::dataDirectory(base::DataKind::GrfBank), sampleRateHz);
}

bool StepGrfPlayer::pushStep(const StepEvent& step) noexcept {
    if (steps_.push(step)) return true;
    stepsDropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
}

std::size_t StepGrfPlayer::channels() const noexcept {
    return config_.layout == GrfChannelLayout::PerFoot ? 2 : 4;
}

void StepGrfPlayer::start(const StepEvent& step) noexcept {
    const auto& list = step.part == FootPart::Heel ? heel_ : toe_;
    const std::uint32_t index = random_.below(static_cast<std::uint32_t>(list.size()));
    const float strength = std::isfinite(step.strength) ? std::clamp(step.strength, 0.0f, 1.0f) : 0;
    const float gain = config_.minGain + (1.0f - config_.minGain) * strength;
    Voice* voice = nullptr;
    for (Voice& v : voices_)
        if (!v.active) {
            voice = &v;
            break;
        }
    if (!voice) { // steal the oldest
        voice = &voices_[0];
        for (Voice& v : voices_)
            if (v.startSample < voice->startSample) voice = &v;
        voicesStolen_.fetch_add(1, std::memory_order_relaxed);
    }
    voice->data = list[index].data();
    voice->length = list[index].size();
    voice->position = 0;
    voice->channel = config_.layout == GrfChannelLayout::PerFoot
                         ? static_cast<std::size_t>(step.foot)
                         : shoeSensorIndex(step.foot, step.part);
    voice->gain = gain;
    voice->startSample = sample_;
    voice->active = true;
    StepPlayback record;
    record.step = step;
    record.bankIndex = index;
    record.gain = gain;
    record.startSample = sample_;
    if (!playbacks_.push(record)) playbacksDropped_.fetch_add(1, std::memory_order_relaxed);
}

void StepGrfPlayer::process(float* const* grf, std::size_t n) noexcept {
    StepEvent step;
    while (steps_.pop(step)) start(step);
    const std::size_t channelCount = channels();
    for (std::size_t c = 0; c < channelCount; ++c) std::fill(grf[c], grf[c] + n, 0.0f);
    std::size_t active = 0;
    for (Voice& v : voices_) {
        if (!v.active) continue;
        const std::size_t count = std::min(n, v.length - v.position);
        float* out = grf[v.channel];
        const float* in = v.data + v.position;
        for (std::size_t i = 0; i < count; ++i) out[i] += v.gain * in[i];
        v.position += count;
        if (v.position >= v.length)
            v.active = false;
        else
            ++active;
    }
    sample_ += n;
    activeVoices_.store(active, std::memory_order_relaxed);
}

bool StepGrfPlayer::popPlayback(StepPlayback& playback) noexcept {
    return playbacks_.pop(playback);
}

void StepGrfPlayer::reset(std::uint64_t seed) noexcept {
    for (Voice& v : voices_) v = Voice{};
    StepEvent e;
    while (steps_.pop(e)) {
    }
    random_.setSeed(seed);
    seed_.store(seed, std::memory_order_relaxed);
    sample_ = 0;
    activeVoices_.store(0, std::memory_order_relaxed);
}

} // namespace underfoot::engine
