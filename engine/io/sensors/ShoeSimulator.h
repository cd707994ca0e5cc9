// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A scripted walker on the FSR shoes: the raw 10-bit pressures of heel and toe sensors for a
/// script of standing and walking phases, with ADC noise, postural sway and quick weight shifts
/// while standing. Used by `underfoot sensors simulate` (emulates the shoes on a serial port or
/// pseudo-terminal) and by the live tests, which know from the script when every foot strike
/// began and check the detector against it.
///
/// Shape of one contact: a raised-cosine rise from the rest level to `peak` over riseMs, a
/// plateau (x (1 + swayDepth sin(2 pi swayHz t))), a raised-cosine fall over fallMs.
#include "engine/dsp/Random.h"
#include "engine/io/sensors/ShoeFrame.h"

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace underfoot::engine {

/// One sensor loaded from onMs to offMs (offMs = +inf: still loaded at the end).
struct ShoeContact {
    std::size_t sensor = 0;
    double onMs = 0; ///< < 0: already loaded when the script starts (no strike)
    double offMs = std::numeric_limits<double>::infinity();
    double peak = 600;
};

/// A quick weight shift while a sensor is loaded (must not count as a step).
struct ShoeBump {
    std::size_t sensor = 0;
    double atMs = 0;
    double amount = 150; ///< raw units added, rising over 20 ms and decaying with tau 300 ms
};

/// The walker's parameters.
struct ShoeWalkOptions {
    double stepIntervalMs = 550; ///< strike to strike of alternate feet (109 steps/min)
    double heelStanceMs = 350;
    double toeDelayMs = 70; ///< toe strike after heel strike
    double toeStanceMs = 530;
    double swingMs = 450; ///< a standing foot lifts this long before its first strike
    double heelPeak = 700;
    double toePeak = 600;
    double standHeel = 450; ///< plateau while standing on both feet
    double standToe = 350;
    double restLevel = 15;
    int noiseLsb = 2; ///< uniform integer noise +-noiseLsb
    double riseMs = 25;
    double fallMs = 40;
    double swayDepth = 0.10;
    double swayHz = 0.4;
    double peakJitter = 0.1; ///< each contact's peak x (1 +- peakJitter), seeded
};

/// A script: contacts, weight shifts, and its length.
class ShoeScript {
  public:
    explicit ShoeScript(ShoeWalkOptions options = {}, std::uint64_t seed = 1);

    /// Both feet loaded for `ms` (the last step of each foot is held; at the start they are
    /// loaded from before the script).
    void stand(double ms);
    /// `steps` alternating steps starting with `first`.
    void walk(int steps, Foot first = Foot::Left);
    /// A weight shift on a loaded sensor, `afterMs` after the current end of the script.
    void bump(std::size_t sensor, double afterMs, double amount = 150);
    /// Both feet lifted (ends all contacts now) and `ms` of no contact.
    void lift(double ms);

    double durationMs() const noexcept { return endMs_; }
    const std::vector<ShoeContact>& contacts() const noexcept { return contacts_; }
    /// Strikes that the detector must find (contacts that start inside the script).
    std::vector<ShoeContact> strikes() const;

    /// The raw pressures at frame `frame` (1 kHz: frame n is n ms); noise from `random`.
    std::array<std::uint16_t, kShoeSensorCount> sample(std::size_t frame, Random& random) const;

  private:
    ShoeWalkOptions o_;
    Random jitter_;
    std::vector<ShoeContact> contacts_;
    std::vector<ShoeBump> bumps_;
    double endMs_ = 0;
    std::array<bool, 2> standing_{true, true};
    std::array<std::size_t, kShoeSensorCount> open_{}; ///< index+1 of a sensor's open contact
};

/// The default script of the tests and of `sensors simulate`: 1 s standing, 8 steps, 2 s standing
/// with two weight shifts, 6 steps, 1 s standing.
ShoeScript defaultWalkScript(std::uint64_t seed = 1, const ShoeWalkOptions& options = {});

} // namespace underfoot::engine
