// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A test tone on one device output channel, run by the LiveEngine like any scene: the
/// experimenter checks each headphone side and each actuator before a participant arrives.
///
/// The tone is a sine that starts at phase 0, with its level in dBFS as peak amplitude
/// (-20 dBFS: peak 0.1, RMS 0.0707). It plays through the scene's ambience path (no surface
/// sound: the scene's GRF is silent) into a channel map whose only output is the chosen channel,
/// so nothing else of the device is touched. The engine's crossfade applies at start and stop.
#include "engine/scene/LiveScene.h"

#include <memory>

namespace underfoot::engine {

/// The sine source (left output; right silent). process() never allocates, locks or throws.
class TestTone final : public AmbienceSource {
  public:
    /// Throws std::invalid_argument for a frequency <= 0 or not finite, or a level above
    /// 0 dBFS or not finite.
    TestTone(double frequencyHz, double levelDbfs);
    /// Throws std::invalid_argument when the frequency is not below half of spec's rate.
    void prepare(const ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    void process(float* left, float* right, int n) noexcept override;
    std::string name() const override;

    double frequencyHz() const noexcept { return frequencyHz_; }
    /// Peak amplitude (10^(dBFS/20)).
    double amplitude() const noexcept { return amplitude_; }

  private:
    double frequencyHz_, levelDbfs_, amplitude_;
    double phase_ = 0.0, increment_ = 0.0;
};

/// The test-tone settings usual for the lab's outputs.
struct TestToneSettings {
    double frequencyHz = 1000.0;
    double levelDbfs = -20.0;
};
/// Headphones: 1 kHz at -20 dBFS.
inline constexpr TestToneSettings kHeadphoneTestTone{1000.0, -20.0};
/// Actuators: 200 Hz (inside their 50-500 Hz band) at -20 dBFS.
inline constexpr TestToneSettings kHapticTestTone{200.0, -20.0};

/// A scene that plays `tone` on device output `outputChannel` (0-based) only. Throws
/// std::invalid_argument for a negative channel or a bad tone (see TestTone).
std::unique_ptr<LiveScene> makeTestToneScene(int outputChannel, const TestToneSettings& tone,
                                             const ProcessSpec& spec);

} // namespace underfoot::engine
