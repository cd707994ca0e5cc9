// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/CookEnvelope.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

void CookEnvelope::prepare(const ProcessSpec& spec, int numChannels) {
    if (numChannels < 1 || numChannels > kMaxChannels)
        throw std::invalid_argument(fmt::format("CookEnvelope: {} input channels; expected 1 to {}",
                                                numChannels, kMaxChannels));
    if (!(spec.sampleRateHz > 0) || !std::isfinite(spec.sampleRateHz))
        throw std::invalid_argument("CookEnvelope: sample rate must be a positive finite number");
    sampleRateHz_ = spec.sampleRateHz;
    numChannels_ = numChannels;
    applyCoefficients();
    reset();
}

void CookEnvelope::setSettings(const CookEnvelopeSettings& s) {
    auto bad = [](double v) { return !std::isfinite(v) || v < 0; };
    if (bad(s.attackMs) || bad(s.releaseMs) || !std::isfinite(s.gain))
        throw std::invalid_argument(fmt::format(
            "CookEnvelope: attack {} ms, release {} ms, gain {}; expected finite times >= 0 and a "
            "finite gain",
            s.attackMs, s.releaseMs, s.gain));
    settings_ = s;
    applyCoefficients();
}

void CookEnvelope::applyCoefficients() noexcept {
    for (auto& f : followers_) f.setTimesMs(settings_.attackMs, settings_.releaseMs, sampleRateHz_);
}

void CookEnvelope::reset() noexcept {
    for (auto& f : followers_) f.reset();
    loudest_ = 0;
}

float CookEnvelope::processFrame(const float* frame) noexcept {
    double best = -1.0;
    for (int c = 0; c < numChannels_; ++c) {
        const double e = followers_[static_cast<std::size_t>(c)].processSample(
            std::fabs(static_cast<double>(frame[c])));
        if (e > best) best = e, loudest_ = c;
    }
    return static_cast<float>(best * settings_.gain);
}

void CookEnvelope::process(const float* const* inputs, float* out, int n) noexcept {
    float frame[kMaxChannels];
    for (int i = 0; i < n; ++i) {
        for (int c = 0; c < numChannels_; ++c) frame[c] = inputs[c][i];
        out[i] = processFrame(frame);
    }
}

GrfSignal grfFromFootstep(const AudioBuffer& recording, double peakNewtons,
                          const CookEnvelopeSettings& settings) {
    if (!(peakNewtons > 0) || !std::isfinite(peakNewtons))
        throw std::invalid_argument(fmt::format(
            "grfFromFootstep: peak force {} N must be positive and finite", peakNewtons));
    if (recording.channels < 1 || recording.channels > CookEnvelope::kMaxChannels)
        throw FileError(fmt::format("footstep recording has {} channels; expected 1 to {}",
                                    recording.channels, CookEnvelope::kMaxChannels));
    CookEnvelope env;
    env.prepare({recording.sampleRateHz, 512}, recording.channels);
    env.setSettings(settings);
    const std::size_t n = recording.frames();
    GrfSignal grf;
    grf.sampleRateHz = recording.sampleRateHz;
    grf.names = {"grf"};
    grf.channels.assign(1, std::vector<float>(n));
    auto& y = grf.channels[0];
    double peak = 0;
    for (std::size_t i = 0; i < n; ++i) {
        y[i] =
            env.processFrame(&recording.samples[i * static_cast<std::size_t>(recording.channels)]);
        peak = std::max(peak, static_cast<double>(y[i]));
    }
    if (!(peak > 0))
        throw FileError("footstep recording is silent: its envelope never rises above 0, so it "
                        "cannot be scaled to a peak force");
    const double k = peakNewtons / peak;
    for (float& v : y) v = static_cast<float>(v * k);
    return grf;
}

GrfSignal grfFromFootstepFile(const std::string& path, double peakNewtons, double targetRateHz,
                              const CookEnvelopeSettings& settings) {
    const AudioBuffer audio = readAudioFile(path, targetRateHz);
    try {
        return grfFromFootstep(audio, peakNewtons, settings);
    } catch (const FileError& e) {
        throw FileError(fmt::format("{}: {}", path, e.what()));
    }
}

} // namespace underfoot::engine
