// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/scene/LiveScene.h"

#include "engine/dsp/Denormals.h"
#include "engine/dsp/Random.h"
#include "engine/reverb/Convolver.h"
#include "engine/surfaces/Layer.h"
#include "engine/surfaces/Surface.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace underfoot::engine {

const char* toString(ControlKind kind) noexcept {
    switch (kind) {
    case ControlKind::Walker:
        return "walker";
    case ControlKind::Microphones:
        return "microphones";
    case ControlKind::GrfReplay:
        return "grf-replay";
    case ControlKind::External:
        return "external";
    }
    return "?";
}

const char* toString(OutputModality modality) noexcept {
    switch (modality) {
    case OutputModality::Audio:
        return "audio";
    case OutputModality::Haptic:
        return "haptic";
    case OutputModality::AudioHaptic:
        return "audio-haptic";
    }
    return "?";
}

const char* toString(HapticPairs pairs) noexcept {
    switch (pairs) {
    case HapticPairs::None:
        return "none";
    case HapticPairs::Heel:
        return "heel";
    case HapticPairs::Toe:
        return "toe";
    case HapticPairs::Both:
        return "both";
    }
    return "?";
}

const char* toString(SceneNode node) noexcept {
    switch (node) {
    case SceneNode::Control:
        return "control";
    case SceneNode::Voices:
        return "voices";
    case SceneNode::Reverb:
        return "reverb";
    case SceneNode::Ambience:
        return "ambience";
    case SceneNode::Haptics:
        return "haptics";
    case SceneNode::Mix:
        return "mix";
    case SceneNode::Count:
        break;
    }
    return "?";
}

OutputModality parseOutputModality(const std::string& text) {
    if (text == "audio") return OutputModality::Audio;
    if (text == "haptic") return OutputModality::Haptic;
    if (text == "both" || text == "audio-haptic" || text == "audiohaptic")
        return OutputModality::AudioHaptic;
    throw std::invalid_argument(
        fmt::format("modality \"{}\": expected audio, haptic or both (audio-haptic)", text));
}

std::shared_ptr<AudioRecorder> makeGrfRecorder(const std::string& path, int channels,
                                               double sampleRateHz) {
    // The scene writes newtons / kGrfFileFullScaleNewtons itself (see quantizeGrf), so the
    // recorder stores what it gets.
    return std::make_shared<AudioRecorder>(path, channels, sampleRateHz, 1.0);
}

float LiveScene::fadeGain(std::int64_t k, int frames) noexcept {
    if (frames <= 0 || k >= frames) return 1.0f;
    if (k <= 0) return 0.0f;
    return static_cast<float>(k) / static_cast<float>(frames);
}

LiveScene::~LiveScene() = default;

std::unique_ptr<LiveScene> LiveScene::create(LiveSceneDescription d, const ProcessSpec& spec,
                                             const ChannelMap& channels) {
    if (!(spec.sampleRateHz > 0) || spec.maxBlockSize < 1)
        throw std::invalid_argument("LiveScene: bad process spec");
    if (!(d.panSpread >= 0.0 && d.panSpread <= 1.0))
        throw std::invalid_argument(
            fmt::format("LiveScene: pan spread {}; expected 0 to 1", d.panSpread));
    if (!std::isfinite(d.impulseWetDb) || !std::isfinite(d.hapticGainDb) || d.hapticGainDb > 24.0)
        throw std::invalid_argument(
            "LiveScene: wet and haptic gains must be finite dB values (haptic at most +24 dB)");
    if (!(d.hapticLowHz > 0 && d.hapticLowHz < d.hapticHighHz &&
          d.hapticHighHz < 0.45 * spec.sampleRateHz))
        throw std::invalid_argument(fmt::format(
            "LiveScene: haptic band {}-{} Hz; expected 0 < low < high < 0.45 x the sample rate",
            d.hapticLowHz, d.hapticHighHz));

    auto s = std::unique_ptr<LiveScene>(new LiveScene());
    s->surfaceId_ = d.surface;
    s->seed_ = d.seed;
    s->control_ = d.control;
    s->modality_ = d.modality;
    s->spec_ = spec;
    s->channels_ = channels;
    const auto block = static_cast<std::size_t>(spec.maxBlockSize);

    // --- control
    int voices = 2;
    if (d.wading) {
        if (d.grfRecorder)
            throw std::invalid_argument("LiveScene: a water scene has no GRF to record (the "
                                        "wading node records its gait frames)");
        s->wading_ = std::move(d.wading);
        s->wading_->prepare(spec);
        s->surfaceId_ = "water";
        voices = 0;
    } else
        switch (d.control) {
        case ControlKind::Walker:
            s->walker_ = std::make_unique<VirtualWalker>(d.walker);
            s->walker_->prepare(spec);
            voices = 2;
            break;
        case ControlKind::Microphones:
            if (channels.microphones.empty())
                throw std::invalid_argument(
                    "LiveScene: microphone control needs microphone input channels in the audio "
                    "settings ([channels] microphones = [1, 2, 3, 4])");
            s->cook_ = std::make_unique<CookEnvelope>();
            s->cook_->prepare(spec, static_cast<int>(channels.microphones.size()));
            s->cook_->setSettings(d.microphones);
            s->micChannels_ = channels.microphones;
            s->micPtr_.assign(channels.microphones.size(), nullptr);
            voices = 1;
            break;
        case ControlKind::GrfReplay:
            if (d.grf.channels.empty() || d.grf.frames() == 0)
                throw std::invalid_argument("LiveScene: the GRF to replay has no samples");
            if (d.grf.channels.size() > 16)
                throw std::invalid_argument(
                    "LiveScene: the GRF to replay has more than 16 channels");
            if (std::fabs(d.grf.sampleRateHz - spec.sampleRateHz) > 1e-6)
                throw std::invalid_argument(
                    fmt::format("LiveScene: the GRF is at {} Hz, the device at {} Hz; load it with "
                                "targetRateHz",
                                d.grf.sampleRateHz, spec.sampleRateHz));
            s->replay_ = std::move(d.grf);
            voices = static_cast<int>(s->replay_.channels.size());
            break;
        case ControlKind::External:
            if (!d.external)
                throw std::invalid_argument("LiveScene: external control without source");
            voices = d.external->channelCount();
            if (voices < 1 || voices > 16)
                throw std::invalid_argument(fmt::format(
                    "LiveScene: the external GRF source has {} channels; expected 1 to 16",
                    voices));
            s->external_ = std::move(d.external);
            s->external_->prepare(spec);
            break;
        }
    const auto nv = static_cast<std::size_t>(voices);
    s->grf_.assign(nv, std::vector<float>(block, 0.0f));
    s->grfScaled_.assign(nv, std::vector<float>(block, 0.0f));
    for (std::size_t v = 0; v < nv; ++v) {
        s->grfPtr_.push_back(s->grf_[v].data());
        s->grfScaledPtr_.push_back(s->grfScaled_[v].data());
    }
    s->zeros_.assign(block, 0.0f);

    // --- voices, exactly as FootstepScene::build
    for (int v = 0; v < voices; ++v) {
        s->voices_.push_back(Surface::loadById(d.surface, d.accuracy));
        const double pos = voices == 1 ? 0.0 : d.panSpread * (2.0 * v / (voices - 1) - 1.0);
        const double angle = (pos + 1.0) * kPi / 4.0;
        s->panL_.push_back(std::cos(angle) * std::sqrt(2.0));
        s->panR_.push_back(std::sin(angle) * std::sqrt(2.0));
    }
    for (auto& v : s->voices_) v->prepare(spec);
    s->voiceOut_.assign(block, 0.0f);

    s->headphones_ = d.modality != OutputModality::Haptic;
    s->haptics_ = d.modality != OutputModality::Audio && channels.hasHaptics() &&
                  (d.hapticPairs[0] != HapticPairs::None || d.hapticPairs[1] != HapticPairs::None);

    // --- reverb: only what the headphones will let the participant hear
    if (s->headphones_) {
        AudioBuffer impulse;
        if (!d.impulseResponse.empty()) {
            impulse = readAudioFile(findImpulseResponse(d.impulseResponse));
            s->wet_ = dbToGain(d.impulseWetDb);
            s->dry_ = 1.0;
            s->reverbName_ = d.impulseResponse;
        } else if (!s->voices_.empty() && s->voices_.front()->info().reverb &&
                   !d.dryEvenIfPresetHasReverb) {
            const auto& info = s->voices_.front()->info();
            impulse = readAudioFile(findImpulseResponse(info.reverb->impulseResponse));
            s->wet_ = dbToGain(info.reverb->wetDb);
            s->dry_ = dbToGain(info.reverb->dryDb);
            s->reverbName_ = info.reverb->impulseResponse;
        }
        if (impulse.frames() > 0) {
            s->reverb_ = std::make_unique<Convolver>();
            s->reverb_->prepare(impulse, spec.sampleRateHz, spec.maxBlockSize);
            s->mono_.assign(block, 0.0f);
            s->wetL_.assign(block, 0.0f);
            s->wetR_.assign(block, 0.0f);
        }
        s->mixL_.assign(block, 0.0f);
        s->mixR_.assign(block, 0.0f);
        if (d.ambience) {
            s->ambience_ = std::move(d.ambience);
            s->ambience_->prepare(spec);
            s->ambL_.assign(block, 0.0f);
            s->ambR_.assign(block, 0.0f);
        }
    }

    // --- haptics
    if (s->haptics_) {
        s->hapticPairs_ = d.hapticPairs;
        s->hapticGain_ = static_cast<float>(dbToGain(d.hapticGainDb));
        for (auto& f : s->hapticFilter_)
            f.design(FilterType::Bandpass, 4, spec.sampleRateHz, d.hapticLowHz, d.hapticHighHz);
        for (auto& b : s->shoe_) b.assign(block, 0.0f);
        for (int v = 0; v < voices; ++v)
            s->voiceShoe_.push_back(voices == 1 ? 2 : (v < voices / 2 ? 0 : 1));
    }

    // --- recordings
    if (d.grfRecorder) {
        if (d.grfRecorder->channels() != voices)
            throw std::invalid_argument(fmt::format(
                "LiveScene: the GRF recorder has {} channels, the scene {} GRF channels",
                d.grfRecorder->channels(), voices));
        s->grfRecorder_ = std::move(d.grfRecorder);
    }
    if (d.outputRecorder) {
        if (d.outputRecorder->channels() != 2)
            throw std::invalid_argument("LiveScene: the output recorder must have 2 channels");
        s->outputRecorder_ = std::move(d.outputRecorder);
        if (s->mixL_.empty()) {
            s->mixL_.assign(block, 0.0f);
            s->mixR_.assign(block, 0.0f);
        }
        s->recL_.assign(block, 0.0f);
        s->recR_.assign(block, 0.0f);
    }
    s->gain_.assign(block, 1.0f);
    if (s->wading_ && s->mixL_.empty()) { // the node renders into the mix buffers
        s->mixL_.assign(block, 0.0f);
        s->mixR_.assign(block, 0.0f);
    }

    // --- deterministic start (FootstepScene::reset, walkerGrf, soundscape replay)
    for (std::size_t v = 0; v < s->voices_.size(); ++v)
        s->voices_[v]->reset(Random::deriveSeed(d.seed, 100 + v));
    if (s->walker_) s->walker_->reset(d.seed);
    if (s->cook_) s->cook_->reset();
    if (s->external_) s->external_->reset(d.seed);
    if (s->wading_) s->wading_->reset(d.seed);
    if (s->ambience_) s->ambience_->reset(d.seed);

    for (int i = 0; i < static_cast<int>(SceneNode::Count); ++i)
        s->cost_[static_cast<std::size_t>(i)].node = static_cast<SceneNode>(i);
    s->cost_[static_cast<std::size_t>(SceneNode::Control)].present = true;
    s->cost_[static_cast<std::size_t>(SceneNode::Voices)].present = true;
    s->cost_[static_cast<std::size_t>(SceneNode::Mix)].present = true;
    s->cost_[static_cast<std::size_t>(SceneNode::Reverb)].present = s->reverb_ != nullptr;
    s->cost_[static_cast<std::size_t>(SceneNode::Ambience)].present = s->ambience_ != nullptr;
    s->cost_[static_cast<std::size_t>(SceneNode::Haptics)].present = s->haptics_;
    return s;
}

bool LiveScene::hasNode(SceneNode node) const noexcept {
    if (node == SceneNode::Count) return false;
    return cost_[static_cast<std::size_t>(node)].present;
}

std::string LiveScene::summary() const {
    std::string s = wading_ ? wading_->summary()
                            : fmt::format("{}, {}, {} voice{}", surfaceId_, toString(control_),
                                          voices_.size(), voices_.size() == 1 ? "" : "s");
    if (!headphones_) s += ", headphones off";
    if (reverb_)
        s += fmt::format(", reverb {} ({:.2f} s)", reverbName_,
                         double(reverb_->impulseLength()) / spec_.sampleRateHz);
    if (ambience_) s += fmt::format(", soundscape {}", ambience_->name());
    if (haptics_)
        s += fmt::format(", haptics L:{} R:{}", toString(hapticPairs_[0]),
                         toString(hapticPairs_[1]));
    return s;
}

std::vector<SceneNodeCost> LiveScene::nodeCosts() const {
    return {cost_.begin(), cost_.end()};
}

void LiveScene::setFadeIn(int frames) noexcept {
    fadeInFrames_ = std::max(0, frames);
}

void LiveScene::startFadeOut(int frames) noexcept {
    if (fadingOut_) return;
    fadeStart_ = fadeGain(frames_, fadeInFrames_);
    fadingOut_ = true;
    fadePos_ = 0;
    fadeLength_ = std::max(0, frames);
}

bool LiveScene::fadedOut() const noexcept {
    return fadingOut_ && fadePos_ >= fadeLength_;
}

float LiveScene::quantizeGrf(float newtons, float& stored) noexcept {
    // What the GRF file stores (newtons / 1000 as float) and what loadGrfFile returns for it
    // (float(stored x 1000.0), computed in double): the voices hear the latter, so a replay
    // of the recording drives them with exactly the same numbers.
    stored = static_cast<float>(static_cast<double>(newtons) / kGrfFileFullScaleNewtons);
    return static_cast<float>(static_cast<double>(stored) * kGrfFileFullScaleNewtons);
}

void LiveScene::runControl(const float* const* inputs, int numInputs, int n) noexcept {
    switch (control_) {
    case ControlKind::Walker:
        walker_->process(grfPtr_[0], grfPtr_[1], n);
        break;
    case ControlKind::Microphones:
        for (std::size_t m = 0; m < micChannels_.size(); ++m)
            micPtr_[m] =
                micChannels_[m] < numInputs && inputs ? inputs[micChannels_[m]] : zeros_.data();
        cook_->process(micPtr_.data(), grfPtr_[0], n);
        break;
    case ControlKind::GrfReplay: {
        const std::size_t total = replay_.frames();
        for (std::size_t c = 0; c < grf_.size(); ++c)
            for (int i = 0; i < n; ++i) {
                const auto k = static_cast<std::size_t>(frames_) + static_cast<std::size_t>(i);
                grf_[c][static_cast<std::size_t>(i)] = k < total ? replay_.channels[c][k] : 0.0f;
            }
        break;
    }
    case ControlKind::External:
        external_->process(grfPtr_.data(), n);
        break;
    }
    float peak = 0.0f;
    for (std::size_t c = 0; c < grf_.size(); ++c)
        for (int i = 0; i < n; ++i) {
            float& g = grf_[c][static_cast<std::size_t>(i)];
            if (!std::isfinite(g) || g < 0.0f) g = 0.0f; // a force never pulls; no NaN inside
            g = quantizeGrf(g, grfScaled_[c][static_cast<std::size_t>(i)]);
            peak = std::max(peak, g);
        }
    grfPeak_ = peak;
}

void LiveScene::process(const float* const* inputs, int numInputs, float* const* outputs,
                        int numOutputs, int n) noexcept {
    using Clock = std::chrono::steady_clock;
    auto mark = measure_ ? Clock::now() : Clock::time_point{};
    auto account = [&](SceneNode node) {
        if (!measure_) return;
        const auto now = Clock::now();
        auto& c = cost_[static_cast<std::size_t>(node)];
        c.seconds += std::chrono::duration<double>(now - mark).count();
        ++c.blocks;
        mark = now;
    };

    // Fade gains of this block.
    for (int i = 0; i < n; ++i) {
        float g;
        if (fadingOut_) {
            g = fadePos_ >= fadeLength_ ? 0.0f
                                        : fadeStart_ * (1.0f - static_cast<float>(fadePos_) /
                                                                   static_cast<float>(fadeLength_));
            ++fadePos_;
        } else {
            g = fadeGain(frames_ + i, fadeInFrames_);
        }
        gain_[static_cast<std::size_t>(i)] = g;
    }

    {
        ScopedFlushDenormals noDenormals; // as FootstepScene::process
        if (!wading_) runControl(inputs, numInputs, n);
        if (grfRecorder_) grfRecorder_->push(grfScaledPtr_.data(), n);
        account(SceneNode::Control);

        // Voices and the dry/wet headphone mix: FootstepScene::process, operation for operation.
        if (headphones_) {
            std::fill(mixL_.begin(), mixL_.begin() + n, 0.0f);
            std::fill(mixR_.begin(), mixR_.begin() + n, 0.0f);
        }
        if (reverb_) std::fill(mono_.begin(), mono_.begin() + n, 0.0f);
        if (haptics_)
            for (auto& b : shoe_) std::fill(b.begin(), b.begin() + n, 0.0f);
        double voiceSeconds = 0, hapticSeconds = 0;
        for (std::size_t v = 0; v < voices_.size(); ++v) {
            voices_[v]->process(grf_[v].data(), voiceOut_.data(), n);
            if (headphones_) {
                const float l = static_cast<float>(panL_[v] * dry_),
                            r = static_cast<float>(panR_[v] * dry_);
                for (int i = 0; i < n; ++i) {
                    const float x = voiceOut_[static_cast<std::size_t>(i)];
                    mixL_[static_cast<std::size_t>(i)] += l * x;
                    mixR_[static_cast<std::size_t>(i)] += r * x;
                }
            }
            if (reverb_)
                for (int i = 0; i < n; ++i)
                    mono_[static_cast<std::size_t>(i)] += voiceOut_[static_cast<std::size_t>(i)];
            if (haptics_) {
                const auto t0 = measure_ ? Clock::now() : Clock::time_point{};
                const int shoe = voiceShoe_[v];
                for (int s = 0; s < 2; ++s)
                    if (shoe == s || shoe == 2)
                        for (int i = 0; i < n; ++i)
                            shoe_[static_cast<std::size_t>(s)][static_cast<std::size_t>(i)] +=
                                voiceOut_[static_cast<std::size_t>(i)];
                if (measure_)
                    hapticSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
            }
        }
        if (wading_) { // the water: gait frames -> stereo, in place of the voices
            wading_->process(mixL_.data(), mixR_.data(), n);
            for (int i = 0; i < n; ++i) {
                const auto k = static_cast<std::size_t>(i);
                if (reverb_) mono_[k] = 0.5f * (mixL_[k] + mixR_[k]);
                if (haptics_) {
                    shoe_[0][k] = mixL_[k];
                    shoe_[1][k] = mixR_[k];
                }
            }
        }
        if (measure_) {
            const auto now = Clock::now();
            voiceSeconds = std::chrono::duration<double>(now - mark).count() - hapticSeconds;
            auto& c = cost_[static_cast<std::size_t>(SceneNode::Voices)];
            c.seconds += voiceSeconds;
            ++c.blocks;
            mark = now;
        }

        if (reverb_) {
            reverb_->process(mono_.data(), wetL_.data(), wetR_.data(), n);
            const float w = static_cast<float>(wet_);
            for (int i = 0; i < n; ++i) {
                mixL_[static_cast<std::size_t>(i)] += w * wetL_[static_cast<std::size_t>(i)];
                mixR_[static_cast<std::size_t>(i)] += w * wetR_[static_cast<std::size_t>(i)];
            }
            account(SceneNode::Reverb);
        }

        if (haptics_) {
            for (std::size_t s = 0; s < 2; ++s) {
                if (hapticPairs_[s] == HapticPairs::None) continue;
                auto& b = shoe_[s];
                hapticFilter_[s].process(b.data(), n);
                const auto& map = channels_.haptic[s];
                const bool heel =
                    hapticPairs_[s] == HapticPairs::Heel || hapticPairs_[s] == HapticPairs::Both;
                const bool toe =
                    hapticPairs_[s] == HapticPairs::Toe || hapticPairs_[s] == HapticPairs::Both;
                for (int ch : {heel ? map.heel : -1, toe ? map.toe : -1}) {
                    if (ch < 0 || ch >= numOutputs) continue;
                    float* out = outputs[ch];
                    for (int i = 0; i < n; ++i)
                        out[i] += gain_[static_cast<std::size_t>(i)] * hapticGain_ *
                                  b[static_cast<std::size_t>(i)];
                }
            }
            if (measure_) {
                auto& c = cost_[static_cast<std::size_t>(SceneNode::Haptics)];
                const auto now = Clock::now();
                c.seconds += hapticSeconds + std::chrono::duration<double>(now - mark).count();
                ++c.blocks;
                mark = now;
            }
        }
    }

    // The soundscape runs outside the denormal scope, as `underfoot replay` renders it.
    if (ambience_) {
        ambience_->process(ambL_.data(), ambR_.data(), n);
        for (int i = 0; i < n; ++i) {
            mixL_[static_cast<std::size_t>(i)] += ambL_[static_cast<std::size_t>(i)];
            mixR_[static_cast<std::size_t>(i)] += ambR_[static_cast<std::size_t>(i)];
        }
        account(SceneNode::Ambience);
    }

    if (headphones_) {
        const int cl = channels_.headphonesLeft, cr = channels_.headphonesRight;
        for (int i = 0; i < n; ++i) {
            const float g = gain_[static_cast<std::size_t>(i)];
            const float l = g * mixL_[static_cast<std::size_t>(i)];
            const float r = g * mixR_[static_cast<std::size_t>(i)];
            if (cl < numOutputs) outputs[cl][i] += l;
            if (cr < numOutputs) outputs[cr][i] += r;
            if (outputRecorder_) {
                recL_[static_cast<std::size_t>(i)] = l;
                recR_[static_cast<std::size_t>(i)] = r;
            }
        }
    } else if (outputRecorder_) {
        std::fill(recL_.begin(), recL_.begin() + n, 0.0f);
        std::fill(recR_.begin(), recR_.begin() + n, 0.0f);
    }
    if (outputRecorder_) {
        const float* rec[2] = {recL_.data(), recR_.data()};
        outputRecorder_->push(rec, n);
    }
    account(SceneNode::Mix);
    frames_ += n;
}

} // namespace underfoot::engine
