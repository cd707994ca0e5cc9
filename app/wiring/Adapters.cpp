// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/Adapters.h"

#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace underfoot::wiring {

namespace {

class SoundscapeAmbience final : public engine::AmbienceSource {
  public:
    explicit SoundscapeAmbience(soundscapes::SoundscapeDefinition definition, std::string name)
        : renderer_(std::move(definition)), name_(std::move(name)) {}
    void prepare(const engine::ProcessSpec& spec) override { renderer_.prepare(spec); }
    void reset(std::uint64_t seed) noexcept override { renderer_.reset(seed); }
    void process(float* left, float* right, int n) noexcept override {
        renderer_.process(left, right, n);
    }
    std::string name() const override { return name_; }

  private:
    soundscapes::SoundscapeRenderer renderer_;
    std::string name_;
};

} // namespace

std::unique_ptr<engine::AmbienceSource> makeSoundscapeAmbience(const std::string& idOrPath) {
    return std::make_unique<SoundscapeAmbience>(soundscapes::loadSoundscape(idOrPath), idOrPath);
}

StepGrfSource::StepGrfSource(std::shared_ptr<engine::StepGrfPlayer> player)
    : player_(std::move(player)) {
    if (!player_) throw std::invalid_argument("StepGrfSource: no step player");
}

int StepGrfSource::channelCount() const noexcept {
    return static_cast<int>(player_->channels());
}

void StepGrfSource::prepare(const engine::ProcessSpec& spec) {
    if (std::fabs(player_->config().sampleRateHz - spec.sampleRateHz) > 1e-6)
        throw std::invalid_argument(fmt::format(
            "the step player runs at {} Hz, the audio device at {} Hz; build the player (and "
            "load its bank) at the device rate",
            player_->config().sampleRateHz, spec.sampleRateHz));
}

void StepGrfSource::reset(std::uint64_t seed) noexcept {
    try {
        player_->reset(seed);
    } catch (...) {
        // StepGrfPlayer::reset only clears and reseeds; nothing to report.
    }
}

void StepGrfSource::process(float* const* grf, int n) noexcept {
    player_->process(grf, static_cast<std::size_t>(n));
}

} // namespace underfoot::wiring
