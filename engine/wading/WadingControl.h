// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The control chain of the wading simulation (gait sonification paper 004, §3.3 and §6), run
/// once per gait frame (100 Hz, as the paper's software did per OSC packet), built from the
/// blocks of engine/control/GyroBlocks.h.
///
/// v1 (Algo V1, §3): per thigh Butterworth low-pass (5 Hz | 0.8 Hz + make-up gain | asymmetric:
///   left 5 Hz, right 0.8 Hz), normalisation 0..100 deg/s -> 0..1, left + right summed -> one
///   control c in 0..1, mapped linearly to the overall gain (c x v1 gain) and to the bubble rate
///   (c x v1 bubble rate).
/// v2 (Algo V2, §6): thighs and shanks filtered and normalised identically;
///   C1 = (weighted thigh sum -> envelope 0 / 890 ms)^1.93 -> flowing level -33..0 dB and the
///        gain of EQ bands at 260 Hz and 9250 Hz, 0..+9 dB;
///   C2 = (shank sum -> envelope 0 / 2230 ms)^2.56 -> bubbling level -38..-5 dB;
///   C3 = (shank sum delayed 150 ms -> envelope 0 / 890 ms)^1 -> splash level -40..+5 dB.
/// Stereo (§5: "the sounds corresponding to the left and right limb were panned 50 % left and
/// right"): every layer has a left-limb and a right-limb voice; the paper's summed control sets
/// the layer's total level, and the share of each limb (the same follower on that limb's own
/// normalised signal, divided by the sum of both) splits it in power: gain_side = g sqrt(share).
/// Rest (our choice, the paper's faders rested "at the threshold of silence"): each gain is faded
/// linearly to silence as its control falls below `restFade`, so a still walker is silent.
#include "engine/control/GyroBlocks.h"
#include "engine/control/GyroFrame.h"

#include <array>
#include <cstdint>
#include <string>

namespace underfoot::engine {

enum class WadingAlgorithm { V1, V2 };
enum class GyroFilter { Butterworth5Hz, Butterworth0_8Hz, Asymmetric };

/// Make-up gain after the 0.8 Hz filter (the paper's unstated "gain factor to compensate for the
/// resulting amplitude decrease"): the ratio of the peak of the 5 Hz-filtered thigh swing to the
/// 0.8 Hz-filtered one for the virtual gait at 63 steps/min (1.673 measured, see
/// tests/wading/engine/test_wading_control.cpp and docs/explanation/wading.md).
inline constexpr double kSlowFilterMakeUpGain = 1.67;

/// Parameters of the mapping (defaults: the paper's values).
struct WadingMapping {
    double normaliseRangeDps = 100; ///< forward rotation mapped to 1
    double thighWeight = 1.0;       ///< weights of the "weighted thigh sum" (C1)
    double shankWeight = 1.0;       ///< weights of the shank sums (C2, C3)
    double attackMs = 0;            ///< all followers
    double c1ReleaseMs = 890, c2ReleaseMs = 2230, c3ReleaseMs = 890;
    double c1Exponent = 1.93, c2Exponent = 2.56, c3Exponent = 1.0;
    double splashDelayMs = 150;
    double flowingMinDb = -33, flowingMaxDb = 0;
    double eqMaxDb = 9, eqLowHz = 260, eqHighHz = 9250, eqQ = 1.0;
    double bubblingMinDb = -38, bubblingMaxDb = -5;
    double splashMinDb = -40, splashMaxDb = 5;
    double restFade = 0.02;
    double v1GainDb = 0;         ///< v1 gain at c = 1
    double v1BubbleRateHz = 400; ///< v1 bubble rate at c = 1
    double pan = 0.5;            ///< left/right limb voices at -pan / +pan
};

/// Layers of the wading sound.
enum class WadingLayer : std::uint8_t { Flowing = 0, Bubbling = 1, Splash = 2 };
inline constexpr std::size_t kWadingLayerCount = 3;

/// What one frame of the chain produces.
struct WadingControls {
    double c1 = 0, c2 = 0, c3 = 0; ///< v2 control signals (0..1)
    double v1 = 0;                 ///< v1 control (0..1)
    /// Per layer, per side (0 left, 1 right): linear gain of that voice.
    std::array<std::array<double, 2>, kWadingLayerCount> gain{};
    double eqDb = 0;            ///< gain of the 260 Hz and 9250 Hz bands (v2)
    double bubbleRateScale = 1; ///< bubbling rate factor (v1: c; v2: 1, steady state)
    /// Normalised, filtered inputs of this frame (diagnostics, tests): indexed by Limb.
    std::array<double, kLimbCount> normalised{};
};

class WadingControl {
  public:
    /// Sets the algorithm, filter and mapping (allocates: not for the audio thread).
    void configure(WadingAlgorithm algorithm, GyroFilter filter, const WadingMapping& mapping,
                   double frameRateHz = 100.0);
    void reset() noexcept;
    /// Runs one frame. Non-finite or absurd (|w| > 5000 deg/s) readings are rejected: the limb
    /// keeps its previous reading (counted in rejectedReadings()).
    const WadingControls& push(const GaitFrame& frame) noexcept;
    const WadingControls& controls() const noexcept { return out_; }
    std::uint64_t rejectedReadings() const noexcept { return rejected_; }
    WadingAlgorithm algorithm() const noexcept { return algorithm_; }
    const WadingMapping& mapping() const noexcept { return mapping_; }
    /// The low-pass of one limb (for group-delay reports).
    const GyroLowpass& lowpass(Limb limb) const noexcept {
        return lowpass_[static_cast<std::size_t>(limb)];
    }

  private:
    double restGain(double db, double control) const noexcept;
    WadingAlgorithm algorithm_ = WadingAlgorithm::V2;
    WadingMapping mapping_;
    std::array<GyroLowpass, kLimbCount> lowpass_;
    std::array<double, kLimbCount> last_{};
    // v2 followers: per layer the summed control and each side's share follower.
    std::array<GyroEnvelope, kWadingLayerCount> sumEnv_;
    std::array<std::array<GyroEnvelope, 2>, kWadingLayerCount> sideEnv_;
    ControlDelay splashDelay_;
    std::array<ControlDelay, 2> splashSideDelay_;
    WadingControls out_;
    std::uint64_t rejected_ = 0;
};

/// Parses "butterworth_5hz" / "butterworth_0_8hz" / "asymmetric" (nullopt-like: throws
/// std::invalid_argument listing the accepted names).
GyroFilter parseGyroFilter(const std::string& name);
std::string gyroFilterName(GyroFilter filter);
WadingAlgorithm parseWadingAlgorithm(const std::string& name);

} // namespace underfoot::engine
