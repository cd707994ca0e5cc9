// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/StimulusRender.h"

#include "app/wiring/Players.h"
#include "engine/render/Renderer.h"
#include "engine/render/SafetyLimiter.h"
#include "engine/wading/Wading.h"
#include "experiment/Clips.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

namespace underfoot::wiring {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;

namespace {

/// Fade at the end of a clip (the soundscape plays to the last sample).
constexpr double kClipFadeSeconds = 0.020;

bool wading(const exp::Stimulus& s) {
    return !s.wading.empty() || s.surface == "water";
}

/// The soundscape mixed in as the live scene mixes it (same seed, unity gain), over the whole
/// buffer; haptic-only stimuli have no headphone mix.
void mixSoundscape(const exp::Stimulus& s, std::uint64_t seed, eng::AudioBuffer& audio) {
    if (!s.soundscape || s.modalities == exp::Modalities::Haptic) return;
    soundscapes::SoundscapeRenderer ambience(soundscapes::loadSoundscape(*s.soundscape));
    ambience.prepare({audio.sampleRateHz, 1024});
    ambience.reset(seed);
    const std::size_t n = audio.frames();
    std::vector<float> l(n), r(n);
    ambience.process(l.data(), r.data(), static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) {
        audio.samples[2 * i] += l[i];
        audio.samples[2 * i + 1] += r[i];
    }
}

/// The output limiter of the live engine (-0.3 dBFS; the samples are untouched when it does not
/// act).
void limit(eng::AudioBuffer& audio) {
    const std::size_t n = audio.frames();
    std::vector<float> l(n), r(n);
    for (std::size_t i = 0; i < n; ++i) {
        l[i] = audio.samples[2 * i];
        r[i] = audio.samples[2 * i + 1];
    }
    eng::StereoSafetyLimiter limiter;
    limiter.prepare(audio.sampleRateHz);
    limiter.process(l.data(), r.data(), static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) {
        audio.samples[2 * i] = l[i];
        audio.samples[2 * i + 1] = r[i];
    }
}

eng::AudioBuffer footsteps(const StimulusRender& q, double walkSeconds, double tailSeconds) {
    const eng::GrfSignal grf =
        q.grf ? *q.grf
              : eng::walkerGrf(q.stimulus.input.kind == exp::InputKind::Walker
                                   ? walkerFromStimulus(q.stimulus.input.walker)
                                   : eng::WalkerParameters{},
                               walkSeconds, q.sampleRateHz, q.seed);
    eng::RenderOptions options;
    options.sampleRateHz = q.sampleRateHz;
    options.blockSize = q.blockSize;
    options.seed = q.seed;
    options.tailSeconds = tailSeconds;
    if (q.stimulus.reverb) options.scene.impulseResponse = *q.stimulus.reverb;
    // The live engine limits each output after the soundscape is mixed in: so does this.
    options.limit = false;
    return eng::renderSurface(q.stimulus.surface, grf, options).audio;
}

eng::AudioBuffer water(const StimulusRender& q, double seconds) {
    eng::WadingOptions options =
        eng::wadingOptionsFromParameters(exp::parameterStrings(q.stimulus.wading));
    options.seed = q.seed;
    options.sampleRateHz = q.sampleRateHz;
    return eng::renderWading(options, seconds);
}

void fitToClip(eng::AudioBuffer& audio, std::size_t frames) {
    audio.samples.resize(frames * static_cast<std::size_t>(audio.channels), 0.0f);
    const std::size_t fade = std::min(frames, clipFrames(kClipFadeSeconds, audio.sampleRateHz));
    for (std::size_t k = 0; k < fade; ++k) {
        // Raised cosine from 1 to 0 over the last `fade` frames (the last one is silent).
        const double x = static_cast<double>(k + 1) / static_cast<double>(fade);
        const auto g = static_cast<float>(0.5 * (1.0 + std::cos(std::numbers::pi * x)));
        const std::size_t i = frames - fade + k;
        for (int c = 0; c < audio.channels; ++c)
            audio.samples[i * static_cast<std::size_t>(audio.channels) +
                          static_cast<std::size_t>(c)] *= g;
    }
}

} // namespace

std::size_t clipFrames(double seconds, double sampleRateHz) {
    return static_cast<std::size_t>(std::llround(seconds * sampleRateHz));
}

eng::AudioBuffer renderStimulus(const StimulusRender& q) {
    const bool ambience = q.stimulus.soundscape && q.stimulus.modalities != exp::Modalities::Haptic;
    if (q.clipSeconds) {
        const double seconds = *q.clipSeconds;
        const std::size_t frames = clipFrames(seconds, q.sampleRateHz);
        eng::AudioBuffer audio;
        if (wading(q.stimulus)) {
            audio = water(q, seconds);
        } else {
            const double tail = std::min(1.0, seconds / 5.0);
            audio = footsteps(q, seconds - tail, tail);
        }
        audio.samples.resize(frames * static_cast<std::size_t>(audio.channels), 0.0f);
        mixSoundscape(q.stimulus, q.seed, audio);
        if (!wading(q.stimulus) || ambience) limit(audio);
        fitToClip(audio, frames);
        return audio;
    }
    if (wading(q.stimulus)) {
        auto audio = water(q, q.walkSeconds);
        if (ambience) {
            mixSoundscape(q.stimulus, q.seed, audio);
            limit(audio);
        }
        return audio;
    }
    auto audio = footsteps(q, q.walkSeconds, 1.0);
    mixSoundscape(q.stimulus, q.seed, audio);
    limit(audio);
    return audio;
}

std::string samplesSha256(const eng::AudioBuffer& audio) {
    std::string bytes(audio.samples.size() * sizeof(float), '\0');
    static_assert(sizeof(float) == 4);
    for (std::size_t i = 0; i < audio.samples.size(); ++i) {
        std::uint32_t u = 0;
        std::memcpy(&u, &audio.samples[i], 4);
        for (int b = 0; b < 4; ++b)
            bytes[4 * i + static_cast<std::size_t>(b)] = static_cast<char>((u >> (8 * b)) & 0xffu);
    }
    return exp::sha256Hex(bytes);
}

} // namespace underfoot::wiring
