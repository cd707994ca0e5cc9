// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The wading scene: gait frames in, stereo water out (the wading study,
/// docs/explanation/studies.md).
///
///   GaitFrame (100 Hz) -> WadingControl (v1 | v2) -> per-layer, per-side gains, EQ gain, rate
///     -> ControlRamp (linear over one frame period, from the sample where the frame arrives)
///   layers, one voice per limb side (left / right, independent seeds):
///     flowing  = band-passed noise with a slow seeded "gurgle" modulation + a dense population of
///                small bubbles (van den Doel) -> peaking EQ at 260 Hz and 9250 Hz (0..+9 dB, C1)
///     bubbling = van den Doel bubble stream at a steady rate (v2, the paper's pre-rendered steady
///                state) or at c x v1 rate (v1: "mapped to the bubble generation rate")
///     splash   = Poisson splash events: each a burst of larger bubbles and a decaying high-passed
///                noise burst ("continuous light splashes")
///   a layer may instead loop a lab recording (preset key `recording`), resampled on load;
///   voices panned -pan / +pan (constant power), summed, x output gain.
/// process() is noexcept, allocation-free and flushes denormals; NaN/Inf gait readings are
/// rejected at the input (the limb keeps its previous reading).
#include "engine/control/GyroFrame.h"
#include "engine/dsp/Biquad.h"
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"
#include "engine/models/Bubbles.h"
#include "engine/surfaces/Preset.h"
#include "engine/wading/WadingControl.h"

#include <array>
#include <string>
#include <vector>

namespace underfoot::engine {

/// Flowing-water layer.
struct FlowingParameters {
    double levelDb = -20;    ///< voice level at fader 0 dB
    double noiseLowHz = 150; ///< band-pass edges of the noise
    double noiseHighHz = 4000;
    double noiseDb = 0;        ///< noise part
    double gurgleHz = 3;       ///< rate of the slow level modulation
    double gurgleDepthDb = 6;  ///< its depth (peak-to-peak of the random walk, dB)
    double bubbleRateHz = 300; ///< small bubbles per second
    double radiusMinMm = 0.6, radiusMaxMm = 4, radiusExponent = -2;
    double bubbleDb = 0; ///< bubble part
    std::string recording;
};

/// Bubbling layer.
struct BubblingParameters {
    double levelDb = -20;
    double rateHz = 60;
    double radiusMinMm = 1, radiusMaxMm = 8, radiusExponent = -1.5;
    double xi = 0.1;
    std::string recording;
};

/// Splash layer.
struct SplashParameters {
    double levelDb = -20;
    double rateHz = 8;            ///< splash events per second
    double bubblesPerSplash = 12; ///< mean bubbles per event
    double radiusMinMm = 1.5, radiusMaxMm = 10;
    double noiseHz = 1500;      ///< high-pass of the noise burst
    double noiseHighHz = 16000; ///< low-pass of the noise burst
    double noiseDecayMs = 60;
    double noiseDb = 0;
    double bubbleDb = 0;
    std::string recording;
};

/// A depth preset (engine/data/wading/*.toml).
struct WadingPreset {
    std::string id, name, description, file;
    double outputGainDb = 0;
    WadingMapping mapping;
    FlowingParameters flowing;
    BubblingParameters bubbling;
    SplashParameters splash;
    std::vector<ParamInfo> params; ///< every parameter read, with unit and range
};

/// Folder of the shipped depth presets ($UNDERFOOT_WADING_DIR, else as base::dataDirectory
/// finds it).
std::string wadingPresetDirectory();
/// Loads "shallow", "deep" (from the folder) or a path to a .toml file. Throws PresetError
/// naming file:line:column and what was expected.
WadingPreset loadWadingPreset(const std::string& nameOrPath);
/// Parses preset text (`file` is used in messages and to resolve recording paths).
WadingPreset parseWadingPreset(const std::string& text, const std::string& file);

/// A gait frame and the sample of the block at which it takes effect.
struct TimedGaitFrame {
    int offset = 0;
    GaitFrame frame;
};

class WadingScene {
  public:
    /// Control/EQ update granularity: chunks on a fixed grid of this many samples from reset.
    static constexpr int kChunkSamples = 32;
    /// Sets preset, algorithm and filter (allocates; throws on bad settings).
    void configure(const WadingPreset& preset, WadingAlgorithm algorithm, GyroFilter filter);
    /// Allocates voices and scratch buffers, loads recordings (throws FileError).
    void prepare(const ProcessSpec& spec);
    /// Clears all state; every voice is reseeded from `seed`.
    void reset(std::uint64_t seed) noexcept;
    /// Live input: the frame takes effect at the first sample of the next process() call.
    void pushFrame(const GaitFrame& frame) noexcept;
    /// Renders n samples (n <= maxBlockSize) into left/right (overwritten). `frames` (sorted by
    /// offset, offsets in [0, n)) take effect at their offsets. No allocation, no locks.
    void process(const TimedGaitFrame* frames, int frameCount, float* left, float* right,
                 int n) noexcept;

    const WadingControl& control() const noexcept { return control_; }
    const WadingPreset& preset() const noexcept { return preset_; }
    /// Gait readings rejected at the input (NaN/Inf/absurd).
    std::uint64_t rejectedReadings() const noexcept { return control_.rejectedReadings(); }
    /// Samples processed since reset.
    std::int64_t samplesProcessed() const noexcept { return sample_; }

  private:
    struct Loop {
        std::vector<float> samples;
        std::size_t pos = 0;
        float next() noexcept {
            const float v = samples[pos];
            if (++pos == samples.size()) pos = 0;
            return v;
        }
    };
    struct Voice {
        // flowing
        Biquad flowHp, flowLp;
        BubbleStream flowBubbles;
        double gurgle = 0, gurgleTarget = 0;
        int gurgleCountdown = 0;
        // bubbling
        BubbleStream bubbles;
        // splash
        BubbleStream splashBubbles;
        Biquad splashHp, splashLp;
        double splashEnv = 0;
        double splashWait = 0;
        Random random;
        // The flow noise of the current chunk, drawn at its grid point (before the splash's
        // draws of the chunk, as when chunks were rendered whole), so the random sequence does
        // not depend on how host blocks cut the chunk.
        std::array<double, kChunkSamples> flowNoise{};
        Loop recording[kWadingLayerCount];
        Biquad eqLow, eqHigh;
        ControlRamp gain[kWadingLayerCount];
    };
    void applyFrame(const GaitFrame& frame) noexcept;
    void chunkControls() noexcept; // at a chunk grid point: EQ coefficients, gurgle
    void renderChunk(float* left, float* right, int n, int phase) noexcept;
    void loadRecording(int layer, const std::string& path);

    WadingPreset preset_;
    WadingControl control_;
    WadingAlgorithm algorithm_ = WadingAlgorithm::V2;
    GyroFilter filter_ = GyroFilter::Butterworth5Hz;
    double sampleRateHz_ = 48000;
    int maxBlock_ = 512;
    std::array<Voice, 2> voices_;
    ControlRamp eqDb_, rateScale_;
    double currentEqDb_ = -1;
    std::vector<float> scratchA_, scratchB_, scratchC_, rate_, ones_, zeros_;
    double flowNoiseGain_ = 0, flowBubbleGain_ = 0, bubbleLevel_ = 0, splashNoiseGain_ = 0,
           splashBubbleGain_ = 0, splashDecayG_ = 0, gurgleG_ = 0;
    double layerLevel_[kWadingLayerCount] = {1, 1, 1};
    double panGain_[2][2] = {{1, 0}, {0, 1}}; ///< [voice][channel]
    double outputGain_ = 1;
    bool pending_ = false;
    GaitFrame pendingFrame_{};
    std::int64_t sample_ = 0;
};

} // namespace underfoot::engine
