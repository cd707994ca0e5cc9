// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Plays a random heel or toe GRF from a bank at each detected step (Turchet et al. 2010: five heel
/// and five toe GRFs, picked at random per step, 25 combinations): the control source of a live
/// scene driven by the FSR shoes.
///
/// Threads: the sensor thread (or any single producer) calls pushStep(); the audio thread calls
/// process(), which drains the step queue at the start of the block, picks a bank entry with the
/// player's seeded generator (engine/dsp/Random.h), starts a voice scaled by the step's strength
/// and mixes all sounding voices into the output. process() is noexcept, lock-free and does not
/// allocate (tests/live/sensors prove it with the AllocationTrap). Every playback (event, chosen
/// bank index, gain, start sample) is pushed to a second SPSC queue that the main thread drains
/// with popPlayback() for the trial's log, so a replay knows which GRFs were played.
///
/// Channel layout (GrfChannelLayout): PerFoot gives one GRF per foot (0 = left, 1 = right; heel
/// and toe of a foot add up, as the bank's heel + toe = the stance force) — the layout of
/// FootstepScene, one surface voice per foot. PerFootPart gives lh, lt, rh, rt for separate
/// heel/toe haptic actuators.
#include "engine/control/GrfBank.h"
#include "engine/control/StepDetector.h"
#include "engine/dsp/Random.h"

#include <boost/lockfree/spsc_queue.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace underfoot::engine {

/// How the output channels are laid out.
enum class GrfChannelLayout : std::uint8_t {
    PerFoot,     ///< 2 channels: left, right (heel + toe summed)
    PerFootPart, ///< 4 channels: left heel, left toe, right heel, right toe
};

/// Settings of a StepGrfPlayer.
struct StepGrfPlayerConfig {
    double sampleRateHz = 48000; ///< must equal the bank's rate
    GrfChannelLayout layout = GrfChannelLayout::PerFoot;
    std::uint64_t seed = 1;              ///< GRF choice (store it with the trial)
    std::size_t stepCapacity = 256;      ///< queued steps between two blocks
    std::size_t playbackCapacity = 1024; ///< playback records awaiting the main thread
    std::size_t maxVoices = 16;          ///< simultaneous GRFs; the oldest is stolen beyond this
    float minGain = 0.5f;                ///< gain of a step of strength 0 (strength 1 -> gain 1)
};

/// One GRF started by the player (for the trial log).
struct StepPlayback {
    StepEvent step;
    std::uint32_t bankIndex = 0; ///< 0-based index into bank.heel or bank.toe
    float gain = 1;
    std::uint64_t startSample = 0; ///< player sample at which it started (block start)
};

/// Step-triggered GRF playback from a heel/toe bank.
class StepGrfPlayer {
  public:
    /// Throws std::invalid_argument when the bank is empty, mono-less, or at another rate.
    StepGrfPlayer(GrfBank bank, const StepGrfPlayerConfig& config);

    /// Loads heel_1..heel_N.wav and toe_1..toe_N.wav from `directory` (N = as many as exist,
    /// at least 1 of each), resampled to `sampleRateHz`. Throws FileError naming the file.
    static GrfBank loadBank(const std::string& directory, double sampleRateHz);
    /// The bank shipped in engine/data/grf (5 heel + 5 toe).
    static GrfBank loadDefaultBank(double sampleRateHz);

    /// Producer side (one thread): queues a step. False (and counted) when the queue is full.
    bool pushStep(const StepEvent& step) noexcept;

    /// Audio thread: writes `n` samples of each of channels() outputs (newtons; overwrites).
    void process(float* const* grf, std::size_t n) noexcept;
    std::size_t channels() const noexcept;
    /// The construction settings (config().seed is the first seed; see seed()).
    const StepGrfPlayerConfig& config() const noexcept { return config_; }
    /// The seed in use (the last reset()'s, or config().seed).
    std::uint64_t seed() const noexcept { return seed_.load(std::memory_order_relaxed); }

    /// Consumer side (main thread): the next playback record. False when none is waiting.
    bool popPlayback(StepPlayback& playback) noexcept;

    /// Steps refused because the step queue was full.
    std::uint64_t stepsDropped() const noexcept { return stepsDropped_.load(); }
    /// Voices cut short because maxVoices were sounding.
    std::uint64_t voicesStolen() const noexcept { return voicesStolen_.load(); }
    /// Playback records lost because the main thread did not drain them.
    std::uint64_t playbacksDropped() const noexcept { return playbacksDropped_.load(); }
    /// Voices sounding after the last block.
    std::size_t activeVoices() const noexcept { return activeVoices_.load(); }

    /// Silences all voices, drops queued steps, restarts the sample counter and reseeds. Call it
    /// from the thread that calls process() (e.g. at a trial start inside the callback) or while
    /// process() is not running; noexcept and allocation-free. Playback records already queued
    /// for the main thread are left to it.
    void reset(std::uint64_t seed) noexcept;

  private:
    struct Voice {
        const float* data = nullptr;
        std::size_t length = 0;
        std::size_t position = 0;
        std::size_t channel = 0;
        float gain = 0;
        std::uint64_t startSample = 0;
        bool active = false;
    };
    void start(const StepEvent& step) noexcept;

    StepGrfPlayerConfig config_;
    std::vector<std::vector<float>> heel_, toe_;
    std::vector<Voice> voices_;
    Random random_;
    std::uint64_t sample_ = 0;
    boost::lockfree::spsc_queue<StepEvent> steps_;
    boost::lockfree::spsc_queue<StepPlayback> playbacks_;
    std::atomic<std::uint64_t> stepsDropped_{0}, voicesStolen_{0}, playbacksDropped_{0};
    std::atomic<std::size_t> activeVoices_{0};
    std::atomic<std::uint64_t> seed_{0};
};

} // namespace underfoot::engine
