// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The FSR-shoe control path of a live scene, assembled: the serial reader thread runs the step
/// detector on every frame and hands each step to the StepGrfPlayer (which the audio thread
/// runs) and to a lock-free queue the main thread drains for the log and the GUI.
///
///     SerialSource source(config);
///     StepGrfPlayer player(StepGrfPlayer::loadDefaultBank(48000), playerConfig);
///     StepInput steps(loadStepThresholds("p07.toml"));
///     steps.attach(source, &player);   // before source.start()
///     source.start();
///     // audio thread: player.process(grf, n);   main thread: steps.popEvent(e),
///     source.popFrame(f)
#include "engine/control/StepDetector.h"

#include <boost/lockfree/spsc_queue.hpp>

#include <atomic>
#include <cstdint>

namespace underfoot::engine {

class SerialSource;
class StepGrfPlayer;

/// Step detection on the serial reader thread, fanned out to a player and a main-thread queue.
class StepInput {
  public:
    /// Throws std::invalid_argument when the thresholds are invalid.
    explicit StepInput(const StepThresholds& thresholds, std::size_t eventCapacity = 1024);

    /// Installs the frame callback on `source` (call before source.start()); steps also go to
    /// `player` when given. `source` and `player` must outlive the reading.
    void attach(SerialSource& source, StepGrfPlayer* player = nullptr);
    /// Runs one frame through the detector (what the callback does; also for offline replays).
    void onFrame(const ShoeFrame& frame) noexcept;

    /// Main thread: the next detected step. False when none is waiting.
    bool popEvent(StepEvent& event) noexcept;
    /// Steps detected so far.
    std::uint64_t steps() const noexcept { return steps_.load(std::memory_order_relaxed); }
    /// Steps the main-thread queue had no room for (it was not drained).
    std::uint64_t eventsDropped() const noexcept {
        return dropped_.load(std::memory_order_relaxed);
    }
    const StepDetector& detector() const noexcept { return detector_; }

  private:
    StepDetector detector_;
    StepGrfPlayer* player_ = nullptr;
    boost::lockfree::spsc_queue<StepEvent> events_;
    std::atomic<std::uint64_t> steps_{0}, dropped_{0};
};

} // namespace underfoot::engine
