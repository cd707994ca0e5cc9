// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Renderer.h"

#include "engine/dsp/Random.h"
#include "engine/io/AudioFile.h"
#include "soundscapes/SynthKit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace underfoot::soundscapes {

namespace {
constexpr std::uint64_t kCalibrationSeed = 0xCA11B4A7E;
constexpr double kBedCalibrationSeconds = 20.0;
constexpr double kBedWarmupSeconds = 1.0;
constexpr int kCalibrationEvents = 32;
constexpr double kLongestEventSeconds = 60.0;

double meanSquare(const std::vector<float>& x) {
    double s = 0;
    for (float v : x) s += static_cast<double>(v) * v;
    return x.empty() ? 0.0 : s / static_cast<double>(x.size());
}
} // namespace

struct SoundscapeRenderer::Layer {
    const LayerDefinition* def = nullptr;
    std::vector<engine::AudioBuffer> recordings; // as read (native rate)

    // Beds.
    std::unique_ptr<BedGenerator> bed;
    std::vector<float> loopL, loopR;
    std::size_t loopPos = 0;

    // Events.
    struct Voice {
        std::unique_ptr<EventVoice> synth;
        const std::vector<float>* clip = nullptr;
        std::size_t clipPos = 0;
        bool active = false;
        float gainL = 0, gainR = 0;
    };
    std::vector<std::vector<float>> clips; // mono, at the output rate
    std::vector<Voice> voices;
    engine::Random rng;
    double nextOnset = 0;    // in samples since reset
    double meanInterval = 1; // in samples
    long long now = 0;       // samples since reset

    double gain = 1.0;
    double unityPower = 0.0;     // long-term mean channel power at unity gain
    double referencePower = 0.0; // what level_db refers to (beds: long-term; events: sounding)
    LayerStats stats;

    double drawInterval() noexcept {
        const double j = def->jitter;
        return meanInterval * ((1.0 - j) + j * rng.exponential(1.0));
    }
    double drawEventGain() noexcept {
        return std::pow(10.0, rng.uniform(def->gainDbMin, def->gainDbMax) / 20.0);
    }
};

SoundscapeRenderer::SoundscapeRenderer(SoundscapeDefinition definition)
    : definition_(std::move(definition)) {
    for (const auto& ld : definition_.layers) {
        auto layer = std::make_unique<Layer>();
        layer->def = &ld;
        if (ld.source == LayerSource::Procedural) {
            if (ld.kind == LayerKind::Bed) layer->bed = makeBedGenerator(ld.generator, ld.params);
        } else {
            for (const auto& path : ld.files) {
                engine::AudioBuffer buffer;
                try {
                    buffer = engine::readAudioFile(path);
                } catch (const std::exception& e) {
                    throw DefinitionError(fmt::format("{}: layer '{}': cannot use the recording: "
                                                      "{}",
                                                      ld.location, ld.name, e.what()));
                }
                if (buffer.channels < 1 || buffer.channels > 2 || buffer.frames() == 0)
                    throw DefinitionError(fmt::format("{}: layer '{}': recording '{}' has {} "
                                                      "channels and {} frames (expected a "
                                                      "non-empty mono or stereo file)",
                                                      ld.location, ld.name, path, buffer.channels,
                                                      buffer.frames()));
                if (!(meanSquare(buffer.samples) > 1e-12))
                    throw DefinitionError(fmt::format("{}: layer '{}': recording '{}' is silent "
                                                      "(expected an audible recording)",
                                                      ld.location, ld.name, path));
                layer->recordings.push_back(std::move(buffer));
            }
        }
        layers_.push_back(std::move(layer));
    }
}

SoundscapeRenderer::~SoundscapeRenderer() = default;

std::size_t SoundscapeRenderer::layerCount() const noexcept {
    return layers_.size();
}
const LayerStats& SoundscapeRenderer::layerStats(std::size_t i) const noexcept {
    return layers_[i]->stats;
}
double SoundscapeRenderer::layerGain(std::size_t i) const noexcept {
    return layers_[i]->gain;
}
double SoundscapeRenderer::layerUnityPower(std::size_t i) const noexcept {
    return layers_[i]->unityPower;
}

void SoundscapeRenderer::prepare(const engine::ProcessSpec& spec) {
    if (!(spec.sampleRateHz >= 8000.0 && spec.sampleRateHz <= 384000.0) || spec.maxBlockSize < 1)
        throw std::invalid_argument("SoundscapeRenderer::prepare: sample rate must be 8-384 kHz "
                                    "and the block size at least 1");
    spec_ = spec;
    const auto block = static_cast<std::size_t>(spec.maxBlockSize);
    scratchL_.assign(block, 0.0f);
    scratchR_.assign(block, 0.0f);
    scratchMono_.assign(block, 0.0f);

    for (auto& lp : layers_) {
        Layer& layer = *lp;
        const LayerDefinition& d = *layer.def;
        // Recordings at the output rate.
        std::vector<engine::AudioBuffer> atRate;
        for (std::size_t k = 0; k < layer.recordings.size(); ++k) {
            const auto& rec = layer.recordings[k];
            try {
                atRate.push_back(rec.sampleRateHz == spec.sampleRateHz
                                     ? rec
                                     : engine::resample(rec, spec.sampleRateHz));
            } catch (const std::exception& e) {
                throw DefinitionError(fmt::format("{}: layer '{}': cannot resample '{}': {}",
                                                  d.location, d.name, d.files[k], e.what()));
            }
        }
        if (d.kind == LayerKind::Bed) {
            if (layer.bed) {
                layer.bed->prepare(spec);
            } else {
                // Seamless loop: the last X frames are crossfaded (equal power) into the first X,
                // and the loop is X frames shorter than the file.
                const auto& rec = atRate.front();
                const std::size_t n = rec.frames();
                const std::size_t x = std::min<std::size_t>(
                    static_cast<std::size_t>(d.crossfadeSeconds * spec.sampleRateHz), n / 2);
                const std::size_t len = n - x;
                layer.loopL.assign(len, 0.0f);
                layer.loopR.assign(len, 0.0f);
                for (std::size_t i = 0; i < len; ++i) {
                    for (int c = 0; c < 2; ++c) {
                        const int ch = std::min(c, rec.channels - 1);
                        double v = rec.at(i, ch);
                        if (i < x) {
                            const double a =
                                0.5 * kPi * (static_cast<double>(i) + 0.5) / static_cast<double>(x);
                            v = v * std::sin(a) + rec.at(len + i, ch) * std::cos(a);
                        }
                        (c == 0 ? layer.loopL : layer.loopR)[i] = static_cast<float>(v);
                    }
                }
            }
        } else {
            layer.clips.clear();
            for (const auto& rec : atRate) {
                std::vector<float> mono(rec.frames());
                for (std::size_t i = 0; i < mono.size(); ++i) {
                    double s = 0;
                    for (int c = 0; c < rec.channels; ++c) s += rec.at(i, c);
                    mono[i] = static_cast<float>(s / rec.channels);
                }
                layer.clips.push_back(std::move(mono));
            }
            layer.voices.clear();
            layer.voices.resize(static_cast<std::size_t>(d.maxVoices));
            for (auto& v : layer.voices) {
                if (d.source == LayerSource::Procedural) {
                    v.synth = makeEventVoice(d.generator, d.params);
                    v.synth->prepare(spec);
                }
            }
            layer.meanInterval = 60.0 / d.ratePerMinute * spec.sampleRateHz;
        }
    }

    // Level calibration (see the header): balance on the reference powers, then one common
    // factor so that the long-term powers add up to the target.
    double longTermSum = 0.0;
    for (auto& lp : layers_) {
        const Calibration c = calibrate(*lp);
        lp->unityPower = c.longTermPower;
        lp->referencePower = c.referencePower;
        if (!(c.longTermPower > 0.0 && c.referencePower > 0.0) || !std::isfinite(c.longTermPower) ||
            !std::isfinite(c.referencePower))
            throw DefinitionError(fmt::format("{}: layer '{}' renders silence or non-finite audio "
                                              "at calibration (expected an audible layer)",
                                              lp->def->location, lp->def->name));
        lp->gain = std::pow(10.0, lp->def->levelDb / 10.0) / c.referencePower; // power gain
        longTermSum += lp->gain * c.longTermPower;
    }
    const double scale = std::pow(10.0, definition_.targetLevelDbfs / 10.0) / longTermSum;
    for (auto& lp : layers_) lp->gain = std::sqrt(lp->gain * scale);
    prepared_ = true;
    reset(0);
}

SoundscapeRenderer::Calibration SoundscapeRenderer::calibrate(Layer& layer) {
    const LayerDefinition& d = *layer.def;
    const double fs = spec_.sampleRateHz;
    const int block = spec_.maxBlockSize;
    if (d.kind == LayerKind::Bed) {
        if (!layer.bed) {
            const double p = 0.5 * (meanSquare(layer.loopL) + meanSquare(layer.loopR));
            return {p, p};
        }
        layer.bed->reset(kCalibrationSeed);
        const auto warm = static_cast<long>(kBedWarmupSeconds * fs);
        const auto total = warm + static_cast<long>(kBedCalibrationSeconds * fs);
        double sum = 0.0;
        long measured = 0;
        for (long t = 0; t < total; t += block) {
            const int m = static_cast<int>(std::min<long>(block, total - t));
            layer.bed->process(scratchL_.data(), scratchR_.data(), m);
            // Sample-exact warm-up boundary: the calibration must not depend on the block size.
            for (int i = static_cast<int>(std::clamp<long>(warm - t, 0, m)); i < m; ++i) {
                sum += 0.5 * (static_cast<double>(scratchL_[i]) * scratchL_[i] +
                              static_cast<double>(scratchR_[i]) * scratchR_[i]);
                ++measured;
            }
        }
        const double p = sum / static_cast<double>(measured);
        return {p, p};
    }
    // Events: mean energy (mono samples squared) and mean duration (samples) per event.
    double energy = 0.0, frames = 0.0;
    if (d.source == LayerSource::Recording) {
        for (const auto& c : layer.clips) {
            energy += meanSquare(c) * static_cast<double>(c.size());
            frames += static_cast<double>(c.size());
        }
        energy /= static_cast<double>(layer.clips.size());
        frames /= static_cast<double>(layer.clips.size());
    } else {
        EventVoice& v = *layer.voices.front().synth;
        v.reset(kCalibrationSeed, kCalibrationSeed + 1);
        engine::Random rng(kCalibrationSeed);
        const long longest = static_cast<long>(kLongestEventSeconds * fs);
        for (int e = 0; e < kCalibrationEvents; ++e) {
            v.start(rng);
            long done = 0;
            int got = block;
            while (got == block && done < longest) {
                got = v.process(scratchMono_.data(), block);
                for (int i = 0; i < got; ++i)
                    energy += static_cast<double>(scratchMono_[i]) * scratchMono_[i];
                done += got;
            }
            frames += static_cast<double>(done);
        }
        energy /= kCalibrationEvents;
        frames /= kCalibrationEvents;
    }
    // E[g^2] for a gain uniform in dB over [a, b]: mean of 10^(x/10).
    const double a = d.gainDbMin, b = d.gainDbMax;
    const double k = std::log(10.0) / 10.0;
    const double meanG2 =
        (b - a) < 1e-9 ? std::exp(k * a) : (std::exp(k * b) - std::exp(k * a)) / (k * (b - a));
    // Equal-power panning: (gL^2 + gR^2) / 2 = 1/2 per event, whatever the position.
    const double eventsPerSample = d.ratePerMinute / 60.0 / fs;
    return {eventsPerSample * energy * meanG2 * 0.5,
            frames > 0.0 ? energy / frames * meanG2 * 0.5 : 0.0};
}

void SoundscapeRenderer::reset(std::uint64_t seed) noexcept {
    if (!prepared_) return;
    for (std::size_t i = 0; i < layers_.size(); ++i) {
        Layer& layer = *layers_[i];
        const std::uint64_t layerSeed = engine::Random::deriveSeed(seed, i);
        layer.stats = {};
        layer.now = 0;
        layer.rng.setSeed(layerSeed);
        if (layer.bed) layer.bed->reset(layerSeed);
        if (!layer.loopL.empty())
            layer.loopPos = layer.rng.below(static_cast<std::uint32_t>(layer.loopL.size()));
        for (std::size_t v = 0; v < layer.voices.size(); ++v) {
            auto& voice = layer.voices[v];
            voice.active = false;
            voice.clip = nullptr;
            if (voice.synth)
                voice.synth->reset(layerSeed, engine::Random::deriveSeed(layerSeed, 1000 + v));
        }
        if (layer.def->kind == LayerKind::Event) {
            const auto& first = layer.def->firstOnsetSeconds;
            if (first)
                layer.nextOnset =
                    layer.rng.uniform(first->first, first->second) * spec_.sampleRateHz;
            else { // a random phase of a regular process, or a Poisson wait
                // Two statements: the order of the draws is fixed, not the compiler's choice.
                const double phase = layer.rng.uniform();
                const double wait = layer.rng.exponential(1.0);
                layer.nextOnset = layer.meanInterval *
                                  ((1.0 - layer.def->jitter) * phase + layer.def->jitter * wait);
            }
        }
    }
}

void SoundscapeRenderer::process(float* left, float* right, int n) noexcept {
    if (n <= 0) return;
    std::fill(left, left + n, 0.0f);
    std::fill(right, right + n, 0.0f);
    if (!prepared_) return;
    for (int done = 0; done < n;) {
        const int m = std::min(spec_.maxBlockSize, n - done);
        processChunk(left + done, right + done, m);
        done += m;
    }
}

void SoundscapeRenderer::startEvent(Layer& layer) noexcept {
    Layer::Voice* free = nullptr;
    for (auto& v : layer.voices)
        if (!v.active) {
            free = &v;
            break;
        }
    if (!free) {
        ++layer.stats.eventsDropped;
        return;
    }
    const double eventGain = layer.drawEventGain();
    const double pan = layer.rng.uniform(layer.def->panMin, layer.def->panMax);
    float pl = 0, pr = 0;
    panGains(pan, pl, pr);
    free->gainL = static_cast<float>(eventGain) * pl;
    free->gainR = static_cast<float>(eventGain) * pr;
    free->active = true;
    if (free->synth) {
        free->synth->start(layer.rng);
    } else {
        free->clip = &layer.clips[layer.rng.below(static_cast<std::uint32_t>(layer.clips.size()))];
        free->clipPos = 0;
    }
    ++layer.stats.eventsStarted;
}

void SoundscapeRenderer::renderVoices(Layer& layer, float* left, float* right, int from,
                                      int to) noexcept {
    const int want = to - from;
    if (want <= 0) return;
    const auto g = static_cast<float>(layer.gain);
    for (auto& v : layer.voices) {
        if (!v.active) continue;
        int got = 0;
        if (v.synth) {
            got = v.synth->process(scratchMono_.data(), want);
        } else {
            const std::size_t remaining = v.clip->size() - v.clipPos;
            got =
                static_cast<int>(std::min<std::size_t>(remaining, static_cast<std::size_t>(want)));
            std::copy_n(v.clip->data() + v.clipPos, got, scratchMono_.data());
            v.clipPos += static_cast<std::size_t>(got);
        }
        const float gl = g * v.gainL, gr = g * v.gainR;
        for (int i = 0; i < got; ++i) {
            left[from + i] += gl * scratchMono_[i];
            right[from + i] += gr * scratchMono_[i];
        }
        layer.stats.framesComputed += static_cast<std::uint64_t>(got);
        if (got < want) v.active = false;
    }
}

void SoundscapeRenderer::processChunk(float* left, float* right, int n) noexcept {
    for (auto& lp : layers_) {
        Layer& layer = *lp;
        const auto g = static_cast<float>(layer.gain);
        if (layer.def->kind == LayerKind::Bed) {
            if (layer.bed) {
                layer.bed->process(scratchL_.data(), scratchR_.data(), n);
                for (int i = 0; i < n; ++i) {
                    left[i] += g * scratchL_[i];
                    right[i] += g * scratchR_[i];
                }
            } else {
                const std::size_t len = layer.loopL.size();
                for (int i = 0; i < n; ++i) {
                    left[i] += g * layer.loopL[layer.loopPos];
                    right[i] += g * layer.loopR[layer.loopPos];
                    if (++layer.loopPos >= len) layer.loopPos = 0;
                }
            }
            layer.stats.framesComputed += static_cast<std::uint64_t>(n);
            layer.now += n;
            continue;
        }

        // Events: voices are rendered in segments split at the onsets, so that a voice that
        // ends before an onset is free for it whatever the block size (output is independent
        // of how the host slices time).
        const double blockEnd = static_cast<double>(layer.now + n);
        int pos = 0;
        for (;;) {
            const bool onset = layer.nextOnset < blockEnd;
            const int segEnd =
                onset
                    ? std::clamp(static_cast<int>(layer.nextOnset - static_cast<double>(layer.now)),
                                 pos, n - 1)
                    : n;
            renderVoices(layer, left, right, pos, segEnd);
            pos = segEnd;
            if (!onset) break;
            startEvent(layer);
            layer.nextOnset += std::max(1.0, layer.drawInterval());
        }
        layer.now += n;
    }
}

} // namespace underfoot::soundscapes
