// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The soundscape renderer: plays the layers of one definition as a stereo background.
///
/// Lifecycle (ProcessSpec.h): the constructor builds only the declared layers and reads every
/// recording (a missing, unreadable, empty or silent file is a DefinitionError naming the
/// layer's file:line:column and the recording); `prepare()` resamples recordings to the output
/// rate, allocates voices and scratch, and calibrates levels; `reset(seed)` restarts
/// deterministically; `process()` runs on the audio thread without allocating, locking,
/// logging or throwing.
///
/// Levels: each layer is measured in `prepare()` with a fixed calibration seed, so the balance
/// does not depend on the playback seed (beds: a 20 s render; procedural events: 32 calibration
/// events; recordings: their samples). `level_db` sets the balance of the layers' *reference*
/// powers: a bed's long-term power, an event's power while it sounds (its energy over its
/// duration, times the mean per-event gain), so "gulls at -6 dB" means a gull call is 6 dB
/// below a bed at 0 dB whatever the call rate. One common factor then scales all layers so
/// that their long-term powers (events: energy x rate) add up to `target_level_dbfs` (mean
/// channel power of the mix, i.e. its Leq).
#include "engine/dsp/ProcessSpec.h"
#include "soundscapes/Definition.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace underfoot::soundscapes {

/// Counters of one layer since the last reset (read them on the thread that calls process()).
struct LayerStats {
    std::uint64_t eventsStarted = 0;  ///< event onsets that got a voice
    std::uint64_t eventsDropped = 0;  ///< onsets dropped because every voice was busy
    std::uint64_t framesComputed = 0; ///< frames the layer's sources actually rendered
};

class SoundscapeRenderer {
  public:
    /// Builds the layers and reads the recordings. Throws DefinitionError.
    explicit SoundscapeRenderer(SoundscapeDefinition definition);
    ~SoundscapeRenderer();
    SoundscapeRenderer(const SoundscapeRenderer&) = delete;
    SoundscapeRenderer& operator=(const SoundscapeRenderer&) = delete;

    /// Allocates, resamples recordings and calibrates levels (off the audio thread). Throws
    /// DefinitionError if a recording cannot be resampled.
    void prepare(const engine::ProcessSpec& spec);
    /// Restarts every layer deterministically from `seed`.
    void reset(std::uint64_t seed) noexcept;
    /// Writes n frames (any n: long blocks are split internally) to left and right.
    void process(float* left, float* right, int n) noexcept;

    const SoundscapeDefinition& definition() const noexcept { return definition_; }
    /// Number of layers built (the enabled layers of the definition, nothing else).
    std::size_t layerCount() const noexcept;
    /// Counters of layer i since the last reset.
    const LayerStats& layerStats(std::size_t i) const noexcept;
    /// Calibrated linear gain applied to layer i (after prepare()).
    double layerGain(std::size_t i) const noexcept;
    /// Measured unity-gain power of layer i (mean channel power, after prepare()).
    double layerUnityPower(std::size_t i) const noexcept;
    /// The soundscape's level relative to the footsteps' reference (for the scene mixer).
    double footstepReferenceGainDb() const noexcept { return definition_.footstepReferenceGainDb; }

  private:
    struct Layer;
    void processChunk(float* left, float* right, int n) noexcept;
    void startEvent(Layer& layer) noexcept;
    void renderVoices(Layer& layer, float* left, float* right, int from, int to) noexcept;
    struct Calibration {
        double longTermPower = 0.0;  ///< mean channel power over time at unity gain
        double referencePower = 0.0; ///< the power `level_db` refers to
    };
    Calibration calibrate(Layer& layer);

    SoundscapeDefinition definition_;
    engine::ProcessSpec spec_{};
    std::vector<std::unique_ptr<Layer>> layers_;
    std::vector<float> scratchL_, scratchR_, scratchMono_;
    bool prepared_ = false;
};

} // namespace underfoot::soundscapes
