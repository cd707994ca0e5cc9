// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The processing graph of one footstep stimulus: one surface voice per foot (or per GRF
/// channel), panned, summed, and — only when the stimulus asks for it — a zero-latency
/// convolution reverb. The offline renderer and the live audio callback run this same object,
/// block by block, so a render is what a participant hears.
///
/// build() and prepare() allocate (off the audio thread); process() does not allocate, lock,
/// log or throw.
#include "engine/reverb/Convolver.h"
#include "engine/surfaces/Surface.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::engine {

enum class ReverbMode {
    AsPreset, ///< use the preset's [reverb] when it has one
    Off,      ///< dry, whatever the preset says
};

struct SceneOptions {
    int voices = 2;         ///< one surface instance per foot / GRF channel
    double panSpread = 0.3; ///< voice i of N is panned in [-spread, +spread]
    ReverbMode reverb = ReverbMode::AsPreset;
    /// An impulse response (name or file) to use instead of the preset's; empty: the preset's.
    std::string impulseResponse;
    double impulseWetDb = -6.0; ///< wet level when `impulseResponse` is given
    AccuracyOptions accuracy;
};

/// Per-node cost of the last process() calls (for the "only what it needs" proof).
struct SceneCost {
    double voiceSeconds = 0, reverbSeconds = 0;
    long long blocks = 0;
    bool hasReverb = false;
};

class FootstepScene {
  public:
    /// Loads the surface (id or .toml path) and, when needed, its impulse response. Throws
    /// PresetError / std::runtime_error with a clear message.
    void build(const std::string& surface, const SceneOptions& options = {});
    void prepare(const ProcessSpec& spec);
    /// Restarts deterministically: the voices from `seed`, the reverb's history cleared (a reset
    /// scene gives the samples of a freshly built one).
    void reset(std::uint64_t seed) noexcept;
    /// grf[v] is the GRF (N) of voice v (v < voices()); writes stereo output (overwrites).
    void process(const float* const* grf, float* outL, float* outR, int n) noexcept;

    int voices() const noexcept { return static_cast<int>(voices_.size()); }
    bool hasReverb() const noexcept { return reverb_ != nullptr; }
    /// Taps of the reverb's IR at the processing rate (0: no reverb or not prepared).
    std::size_t reverbLength() const noexcept { return reverb_ ? reverb_->impulseLength() : 0; }
    const Surface& surface(int v = 0) const { return *voices_.at(static_cast<std::size_t>(v)); }
    /// Measured cost per node, when `measure` is on (off by default: no clock reads).
    void setMeasureCost(bool on) noexcept { measure_ = on; }
    const SceneCost& cost() const noexcept { return cost_; }
    /// Whether denormals were flushed to zero during the last process() (checked each block).
    bool flushedDenormals() const noexcept { return flushingDenormals_; }

  private:
    std::vector<std::unique_ptr<Surface>> voices_;
    std::vector<double> panL_, panR_;
    std::unique_ptr<Convolver> reverb_;
    AudioBuffer impulse_;
    double wet_ = 0, dry_ = 1;
    std::vector<float> mono_, voiceOut_, wetL_, wetR_;
    bool measure_ = false;
    bool flushingDenormals_ = false;
    SceneCost cost_;
};

} // namespace underfoot::engine
