// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Adapters from the parts the engine does not know (soundscapes/, the FSR step player) to the
/// LiveScene's node interfaces.
#include "engine/control/StepGrfPlayer.h"
#include "engine/scene/LiveScene.h"

#include <memory>
#include <string>

namespace underfoot::wiring {

/// A shipped soundscape (id) or a definition file as the scene's ambience: the same renderer,
/// seed and unity gain as `underfoot replay` mixes in. Throws soundscapes::DefinitionError.
std::unique_ptr<engine::AmbienceSource> makeSoundscapeAmbience(const std::string& idOrPath);

/// The FSR shoes' step player as the scene's external GRF source (its channels() channels:
/// PerFoot = left, right; PerFootPart = lh, lt, rh, rt). The player is shared with the sensor
/// thread that pushes steps; reset() reseeds it (off the audio thread, as the scene is built).
class StepGrfSource final : public engine::GrfSource {
  public:
    explicit StepGrfSource(std::shared_ptr<engine::StepGrfPlayer> player);
    int channelCount() const noexcept override;
    void prepare(const engine::ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    void process(float* const* grf, int n) noexcept override;
    engine::StepGrfPlayer& player() noexcept { return *player_; }

  private:
    std::shared_ptr<engine::StepGrfPlayer> player_;
};

} // namespace underfoot::wiring
