// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Step detection from the FSR shoes (Turchet et al. 2010, "Audio-haptic
/// physically based simulation of walking on different grounds", §V): the first time-derivative
/// of each heel/toe pressure is watched and, when it rises above a calibrated threshold
/// (positive changes only: foot strike, not lift-off), a step event fires for that sensor.
/// Further thresholds on the signal guard against false steps while standing:
///  - the pressure must be above `contactLevel` when the derivative crosses (noise at rest),
///  - after a step the sensor is disarmed: no retrigger while the pressure stays high (weight
///    shifts while standing); it re-arms only after the pressure has stayed below
///    `releaseLevel` for `releaseHoldMs` (the foot was lifted),
///  - and no two steps of one sensor within `refractoryMs`.
/// At start every sensor is disarmed until it is seen released, so a participant already standing
/// on the shoes does not trigger.
///
/// The derivative is the difference over `derivativeSpanMs` (4 ms = 4 frames at 1 kHz) in raw
/// ADC units per second, which averages the ADC's +-1-2 LSB noise. process() runs on the serial
/// reader thread (or offline over a recording); it is noexcept and does not allocate.
#include "engine/io/sensors/ShoeFrame.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace underfoot::engine {

/// Thresholds of one pressure sensor, in raw ADC units (0..1023) and units per second.
struct StepSensorThresholds {
    double restLevel = 20;                  ///< pressure with the foot lifted (calibration)
    double peakLevel = 800;                 ///< pressure under a step (calibration)
    double onsetDerivativePerS = 4000;      ///< fire when the derivative rises above this
    double contactLevel = 80;               ///< ... and the pressure is at least this
    double releaseLevel = 200;              ///< re-arm after the pressure fell below this
    double referenceDerivativePerS = 20000; ///< derivative of a typical strike: strength 1
};

/// All thresholds of one participant (saved per participant by StepCalibration).
struct StepThresholds {
    std::string participant;   ///< pseudonymous code, may be empty
    double frameRateHz = 1000; ///< the shoes' sample rate
    double derivativeSpanMs = 4;
    double refractoryMs = 120;
    double releaseHoldMs = 20;
    std::array<StepSensorThresholds, kShoeSensorCount> sensors{}; ///< lh, lt, rh, rt

    /// Throws std::invalid_argument naming the first bad value (non-finite, non-positive,
    /// release <= contact, ...).
    void validate() const;
};

/// A detected foot strike on one sensor.
struct StepEvent {
    double timeS = 0;             ///< host time of the frame that fired (sensor clock)
    std::uint32_t deviceMs = 0;   ///< the frame's device clock
    std::uint64_t frameIndex = 0; ///< the frame's index in the stream
    Foot foot = Foot::Left;
    FootPart part = FootPart::Heel;
    float strength = 0;         ///< derivative / referenceDerivativePerS, clamped to [0, 1]
    float derivativePerS = 0;   ///< derivative at the crossing, ADC units per second
    std::uint16_t pressure = 0; ///< raw pressure at the crossing
};

/// Per-sensor derivative-threshold onset detector with standing-still guards.
class StepDetector {
  public:
    /// At most one event per sensor per frame.
    using Events = std::array<StepEvent, kShoeSensorCount>;

    /// Throws std::invalid_argument when the thresholds are invalid.
    explicit StepDetector(const StepThresholds& thresholds);

    /// Processes one frame (frames must be consecutive at frameRateHz); writes the events of this
    /// frame to `out` and returns their number (0..4).
    std::size_t process(const ShoeFrame& frame, Events& out) noexcept;
    /// Forgets the history (all sensors disarmed).
    void reset() noexcept;
    const StepThresholds& thresholds() const noexcept { return thresholds_; }
    /// Whether sensor i is armed (released since its last step).
    bool armed(std::size_t i) const noexcept { return state_[i].armed; }
    /// The last derivative of sensor i (units per second), for the GUI's live view.
    double derivativePerS(std::size_t i) const noexcept { return state_[i].derivative; }

  private:
    static constexpr std::size_t kMaxSpan = 64;
    struct SensorState {
        std::array<std::uint16_t, kMaxSpan> history{};
        std::size_t filled = 0;
        bool armed = false;
        std::uint32_t framesBelowRelease = 0;
        std::uint64_t framesSinceStep = ~std::uint64_t{0};
        double derivative = 0;
    };
    StepThresholds thresholds_;
    std::size_t span_ = 4;
    std::uint32_t releaseHoldFrames_ = 20;
    std::uint64_t refractoryFrames_ = 120;
    std::size_t head_ = 0;
    std::array<SensorState, kShoeSensorCount> state_{};
};

} // namespace underfoot::engine
