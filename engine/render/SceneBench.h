// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// One way of timing the footstep scenes, used by `underfoot bench --only surfaces|scenes` and by
/// tests/bench/bench_reverb, so that the two report the same figures.
///
/// Method: the same deterministic input runs `repeats` times, the scene reset to the same seed
/// before each repeat (voices AND reverb: every block does the same work in every repeat), in
/// 64-frame blocks at 48 kHz.
///  - ns/sample and x real time come from the fastest repeat's WHOLE-RUN thread CPU time: what a
///    real-time thread pays over a walk, cache refills after preemption included.
///  - median, p99 and worst 64-frame block come from the per-block MINIMUM over the repeats
///    (steady clock around each block): a shared machine only ever slows a block down, so the
///    minimum is the block's own cost. Their mean ("per-block minima") is reported too: it is a
///    lower bound of the cost (it keeps, for every block, its luckiest repeat) and must not be
///    read as the real-time factor (that was the 2x between the two harnesses).
#include "engine/control/GrfFile.h"
#include "engine/render/FootstepScene.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace underfoot::engine {

class AmbienceSource;

inline constexpr int kBenchRateHz = 48000;
inline constexpr int kBenchBlock = 64;
/// The real-time budget of one 64-frame block at 48 kHz, in microseconds.
inline constexpr double kBenchBlockBudgetUs = 1e6 * kBenchBlock / kBenchRateHz;

struct BlockCostStats {
    std::size_t blocks = 0;       ///< blocks per repeat
    int repeats = 0;              ///< runs of the same input
    double nsPerSample = 0;       ///< fastest whole run, thread (or process) CPU time
    double realTimeFactor = 0;    ///< audio seconds per CPU second of that run
    double minimaNsPerSample = 0; ///< mean of the per-block minima (a lower bound)
    double medianUs = 0, p99Us = 0, worstUs = 0; ///< per-block minima (steady clock)
    double worstOverMedian() const noexcept { return medianUs > 0 ? worstUs / medianUs : 0; }
    /// Worst block as a share of the 1333 us budget of a 64-frame block.
    double budgetShare() const noexcept { return worstUs / kBenchBlockBudgetUs; }
};

enum class BenchClock {
    Thread, ///< the calling thread's CPU time (everything runs on it)
    Process ///< the process's CPU time (work done in other threads, e.g. zita-convolver's)
};

/// Runs `block(b)` for b = 0 .. blocks - 1, `repeats` times, calling `reset()` before each
/// repeat (reset must make block b do the same work in every repeat). `samplesPerBlock` audio
/// samples at `sampleRateHz` per block.
BlockCostStats timeBlocks(std::size_t blocks, int repeats, int samplesPerBlock, double sampleRateHz,
                          const std::function<void()>& reset,
                          const std::function<void(std::size_t)>& block,
                          BenchClock clock = BenchClock::Thread);

/// A footstep scene to time: surface voices driven by the virtual walker, the reverb as the
/// preset (or `impulseResponse`) says, optionally a background (added at unity gain, as the
/// live engine's headphone mix does).
struct SceneBenchSpec {
    std::string surface;
    int voices = 1; ///< 1: one voice (walker's left foot); 2: both feet
    ReverbMode reverb = ReverbMode::AsPreset;
    std::string impulseResponse;        ///< instead of the preset's IR (empty: the preset's)
    AmbienceSource* ambience = nullptr; ///< prepared and reset by measureScene; not owned
    double seconds = 10.0;              ///< walker seconds (the last stances are completed)
    int repeats = 5;
    std::uint64_t seed = 1;
};

struct SceneBenchResult {
    BlockCostStats stats;
    bool hasReverb = false;
    std::size_t irLength = 0; ///< taps of the reverb's IR at 48 kHz (0: none)
    double checksum = 0; ///< sum of |output| of the last repeat (the work is not optimised away)
};

/// Builds the scene of `spec` at 48 kHz / 64 frames and times it (see the file comment).
/// Throws as FootstepScene::build does (unknown surface, missing IR).
SceneBenchResult measureScene(const SceneBenchSpec& spec);

/// The scene of `spec` with its walker input, built and prepared at 48 kHz / 64 frames: the work
/// measureScene times, one 64-frame block at a time. `underfoot bench --only scene-instructions`
/// runs it block by block under callgrind to count each block's instructions.
class SceneBlocks {
  public:
    /// Throws as FootstepScene::build does, std::invalid_argument for voices outside 1..2.
    /// Prepares `spec.ambience` (not owned; must outlive this object).
    explicit SceneBlocks(const SceneBenchSpec& spec);
    SceneBlocks(const SceneBlocks&) = delete;
    SceneBlocks& operator=(const SceneBlocks&) = delete;

    /// 64-frame blocks of the walker's input.
    std::size_t blocks() const noexcept { return blocks_; }
    /// The scene (voices and reverb) and the ambience to `spec.seed`; the checksum to 0.
    void reset();
    /// Block b (b < blocks()): the scene, then the ambience added at unity gain (the live
    /// headphone mix), then the checksum.
    void process(std::size_t b) noexcept;
    /// Sum over the blocks since the last reset of |first left| + |last right| output sample.
    double checksum() const noexcept { return checksum_; }
    bool hasReverb() const noexcept { return scene_.hasReverb(); }
    std::size_t reverbLength() const noexcept { return scene_.reverbLength(); }

  private:
    SceneBenchSpec spec_;
    FootstepScene scene_;
    GrfSignal grf_;
    std::size_t blocks_ = 0;
    std::vector<float> l_, r_, al_, ar_;
    double checksum_ = 0;
};

} // namespace underfoot::engine
