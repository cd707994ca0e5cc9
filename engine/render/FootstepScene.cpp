// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/FootstepScene.h"

#include "engine/dsp/Denormals.h"
#include "engine/dsp/Random.h"
#include "engine/io/AudioFile.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace underfoot::engine {

void FootstepScene::build(const std::string& surface, const SceneOptions& options) {
    if (options.voices < 1 || options.voices > 16)
        throw std::invalid_argument("a scene needs 1 to 16 voices");
    voices_.clear();
    panL_.clear();
    panR_.clear();
    for (int v = 0; v < options.voices; ++v) {
        voices_.push_back(Surface::loadById(surface, options.accuracy));
        // Constant-power pan position in [-spread, spread].
        const double pos =
            options.voices == 1 ? 0.0 : options.panSpread * (2.0 * v / (options.voices - 1) - 1.0);
        const double angle = (pos + 1.0) * kPi / 4.0;
        panL_.push_back(std::cos(angle) * std::sqrt(2.0));
        panR_.push_back(std::sin(angle) * std::sqrt(2.0));
    }
    reverb_.reset();
    const auto& info = voices_.front()->info();
    if (options.reverb == ReverbMode::AsPreset && !options.impulseResponse.empty()) {
        impulse_ = readAudioFile(findImpulseResponse(options.impulseResponse));
        reverb_ = std::make_unique<Convolver>();
        wet_ = dbToGain(options.impulseWetDb);
        dry_ = 1.0;
    } else if (options.reverb == ReverbMode::AsPreset && info.reverb) {
        impulse_ = readAudioFile(findImpulseResponse(info.reverb->impulseResponse));
        reverb_ = std::make_unique<Convolver>();
        wet_ = dbToGain(info.reverb->wetDb);
        dry_ = dbToGain(info.reverb->dryDb);
    } else {
        wet_ = 0.0;
        dry_ = 1.0;
    }
}

void FootstepScene::prepare(const ProcessSpec& spec) {
    for (auto& v : voices_) v->prepare(spec);
    const auto n = static_cast<std::size_t>(spec.maxBlockSize);
    mono_.assign(n, 0.0f);
    voiceOut_.assign(n, 0.0f);
    wetL_.assign(n, 0.0f);
    wetR_.assign(n, 0.0f);
    if (reverb_) reverb_->prepare(impulse_, spec.sampleRateHz, spec.maxBlockSize);
    cost_ = {};
    cost_.hasReverb = reverb_ != nullptr;
}

void FootstepScene::reset(std::uint64_t seed) noexcept {
    for (std::size_t v = 0; v < voices_.size(); ++v)
        voices_[v]->reset(Random::deriveSeed(seed, 100 + v));
    if (reverb_) reverb_->reset();
}

void FootstepScene::process(const float* const* grf, float* outL, float* outR, int n) noexcept {
    ScopedFlushDenormals noDenormals;
    flushingDenormals_ = ScopedFlushDenormals::active(); // measured, not assumed
    using Clock = std::chrono::steady_clock;
    const auto t0 = measure_ ? Clock::now() : Clock::time_point{};
    std::fill(outL, outL + n, 0.0f);
    std::fill(outR, outR + n, 0.0f);
    if (reverb_) std::fill(mono_.begin(), mono_.begin() + n, 0.0f);
    for (std::size_t v = 0; v < voices_.size(); ++v) {
        voices_[v]->process(grf[v], voiceOut_.data(), n);
        const float l = static_cast<float>(panL_[v] * dry_),
                    r = static_cast<float>(panR_[v] * dry_);
        for (int i = 0; i < n; ++i) {
            const float x = voiceOut_[static_cast<std::size_t>(i)];
            outL[i] += l * x;
            outR[i] += r * x;
        }
        if (reverb_)
            for (int i = 0; i < n; ++i)
                mono_[static_cast<std::size_t>(i)] += voiceOut_[static_cast<std::size_t>(i)];
    }
    const auto t1 = measure_ ? Clock::now() : Clock::time_point{};
    if (reverb_) {
        reverb_->process(mono_.data(), wetL_.data(), wetR_.data(), n);
        const float w = static_cast<float>(wet_);
        for (int i = 0; i < n; ++i) {
            outL[i] += w * wetL_[static_cast<std::size_t>(i)];
            outR[i] += w * wetR_[static_cast<std::size_t>(i)];
        }
    }
    if (measure_) {
        const auto t2 = Clock::now();
        cost_.voiceSeconds += std::chrono::duration<double>(t1 - t0).count();
        if (reverb_) cost_.reverbSeconds += std::chrono::duration<double>(t2 - t1).count();
    }
    ++cost_.blocks;
}

} // namespace underfoot::engine
