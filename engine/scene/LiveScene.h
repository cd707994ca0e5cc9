// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The live scene: the processing graph of one stimulus, built off the audio thread from a
/// description and run by the LiveEngine's callback (or by tests / benchmarks block by block).
///
/// It contains only the nodes the stimulus needs:
///   control   -> the GRF per voice: virtual walker, microphones (Cook's envelope on the loudest
///                of N inputs), a GRF recording replayed sample-accurately, or an external source
///                (e.g. the FSR shoes' step player) through GrfSource;
///   voices    -> one surface instance per GRF channel (sleeping voices cost what the surface's
///                sleep costs);
///   reverb    -> only when the stimulus or the surface preset asks for it (zero-latency
///                Convolver), and only when the headphones are in use;
///   ambience  -> only with a soundscape (an AmbienceSource the app adapts), only for headphones;
///   haptics   -> only when the modality includes haptics: per shoe, that foot's dry voice sum
///                band-limited to 50-500 Hz (Butterworth, 4th order per edge: 24 dB/octave) to heel
///                / toe.
/// The headphone mix is computed exactly as FootstepScene computes it (same seeds, pan, gains,
/// order of operations), so a render of the recorded GRF with the same seed is the same samples.
///
/// create() allocates and may throw; process() never allocates, locks, logs or throws.
#include "engine/control/CookEnvelope.h"
#include "engine/control/GrfFile.h"
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Biquad.h"
#include "engine/dsp/ProcessSpec.h"
#include "engine/io/AudioDevice.h"
#include "engine/io/AudioRecorder.h"
#include "engine/scene/WadingNode.h"
#include "engine/surfaces/Layer.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace underfoot::engine {

class Surface;
class Convolver;

/// A stereo background (soundscape) the scene mixes into the headphones at unity gain. The app
/// adapts soundscapes::SoundscapeRenderer to it (the engine does not depend on soundscapes/).
class AmbienceSource {
  public:
    virtual ~AmbienceSource() = default;
    /// Off the audio thread: allocate for blocks up to spec.maxBlockSize.
    virtual void prepare(const ProcessSpec& spec) = 0;
    /// Restarts deterministically (the scene passes its render seed).
    virtual void reset(std::uint64_t seed) noexcept = 0;
    /// Writes (overwrites) n frames. No allocation, locks or throws.
    virtual void process(float* left, float* right, int n) noexcept = 0;
    /// For reports ("forest").
    virtual std::string name() const = 0;
};

/// A GRF produced outside the scene (FSR step player, network, ...), pulled per block on the
/// audio thread. Channel c drives voice c; the first half of the channels belong to the left
/// shoe, the second half to the right one (1 channel: both shoes).
class GrfSource {
  public:
    virtual ~GrfSource() = default;
    /// Number of GRF channels (1..16); fixed for the source's lifetime.
    virtual int channelCount() const noexcept = 0;
    /// Off the audio thread.
    virtual void prepare(const ProcessSpec& spec) = 0;
    virtual void reset(std::uint64_t seed) noexcept = 0;
    /// Writes n samples of GRF (newtons) into grf[c] for every channel. No allocation, no locks.
    virtual void process(float* const* grf, int n) noexcept = 0;
};

/// What drives the scene.
enum class ControlKind { Walker, Microphones, GrfReplay, External };
/// Which senses the stimulus is rendered to.
enum class OutputModality { Audio, Haptic, AudioHaptic };
/// Which actuator pairs of a shoe vibrate.
enum class HapticPairs { None, Heel, Toe, Both };

const char* toString(ControlKind kind) noexcept;
const char* toString(OutputModality modality) noexcept;
const char* toString(HapticPairs pairs) noexcept;
/// Parses "audio", "haptic", "both"/"audio-haptic"; throws std::invalid_argument.
OutputModality parseOutputModality(const std::string& text);

/// Everything a scene is built from.
struct LiveSceneDescription {
    std::string surface = "wood"; ///< surface id or preset path
    /// Impulse response name/path overriding the preset's ("" = the preset's [reverb], if any).
    std::string impulseResponse;
    double impulseWetDb = -6.0;            ///< wet level with `impulseResponse` (as FootstepScene)
    bool dryEvenIfPresetHasReverb = false; ///< ignore the preset's [reverb]
    double panSpread = 0.3;
    AccuracyOptions accuracy;
    /// The soundscape (taken by the scene; null = none).
    std::unique_ptr<AmbienceSource> ambience;

    OutputModality modality = OutputModality::Audio;
    std::array<HapticPairs, 2> hapticPairs{HapticPairs::Both, HapticPairs::Both}; ///< left, right
    double hapticGainDb = 0.0;
    double hapticLowHz = 50.0, hapticHighHz = 500.0;

    ControlKind control = ControlKind::Walker;
    WalkerParameters walker;                              ///< ControlKind::Walker
    CookEnvelopeSettings microphones{1.0, 100.0, 1000.0}; ///< 1000 N per unit of |x| by default
    GrfSignal grf;                       ///< ControlKind::GrfReplay (resampled to the scene rate)
    std::shared_ptr<GrfSource> external; ///< ControlKind::External
    /// Walking through water (surface "water"): the wading node (a WadingScene fed by its gait
    /// source) replaces the GRF control and the surface voices; `surface`, `control` and
    /// `grfRecorder` are then not used (the node records its gait frames itself). Its stereo
    /// output goes to the headphones (and the reverb, when one is named); with haptics, the
    /// left / right output drives the left / right shoe through the 50-500 Hz band.
    std::unique_ptr<WadingNode> wading;

    std::uint64_t seed = 1; ///< render seed (voices, walker, ambience)
    /// Recording of the GRF channels from the scene's first sample (made by makeGrfRecorder,
    /// as many channels as the control has: walker 2, microphones 1, replay/external theirs).
    std::shared_ptr<AudioRecorder> grfRecorder;
    /// Recording of the scene's headphone output after its fade gain (what it added to the
    /// device's headphone channels); optional.
    std::shared_ptr<AudioRecorder> outputRecorder;
};

/// Full scale of GRF recordings (engine/control/GrfFile.h: a sample of 1.0 is 1000 N).
inline constexpr double kGrfFileFullScaleNewtons = 1000.0;

/// A recorder for a scene's GRF channels (`LiveSceneDescription::grfRecorder`): a float WAV
/// that loadGrfFile / `underfoot replay` read back. Throws FileError.
std::shared_ptr<AudioRecorder> makeGrfRecorder(const std::string& path, int channels,
                                               double sampleRateHz);

/// The nodes of a scene, for cost reports.
enum class SceneNode { Control, Voices, Reverb, Ambience, Haptics, Mix, Count };
const char* toString(SceneNode node) noexcept;

/// Measured cost of one node since the scene started (when measuring is on).
struct SceneNodeCost {
    SceneNode node = SceneNode::Control;
    bool present = false; ///< the node exists in this scene
    double seconds = 0;   ///< thread time spent in it (steady clock)
    long long blocks = 0; ///< blocks in which it ran
};

class LiveScene {
  public:
    /// Builds and prepares every node for `spec` and `channels` (off the audio thread). Throws
    /// PresetError / FileError / std::invalid_argument with a message naming what is wrong.
    static std::unique_ptr<LiveScene> create(LiveSceneDescription description,
                                             const ProcessSpec& spec, const ChannelMap& channels);
    ~LiveScene();
    LiveScene(const LiveScene&) = delete;
    LiveScene& operator=(const LiveScene&) = delete;

    /// Runs n frames (n <= spec.maxBlockSize): reads the device inputs it needs, ADDS its output
    /// (times its fade gain) to the mapped device outputs, pushes recordings. `inputs` has
    /// `numInputs` planar channels, `outputs` `numOutputs`. No allocation, locks or throws.
    void process(const float* const* inputs, int numInputs, float* const* outputs, int numOutputs,
                 int n) noexcept;

    /// Fade: the scene's output gain ramps linearly over `frames` samples. A new scene starts at
    /// gain 0 and fades in: sample k (from the scene's first sample) has gain
    /// fadeGain(k, frames) = min(1, k / frames) (1 everywhere when frames = 0).
    static float fadeGain(std::int64_t k, int frames) noexcept;
    /// Audio thread (engine): sets the fade-in length before the first process().
    void setFadeIn(int frames) noexcept;
    /// Audio thread (engine): starts fading out from the current gain over `frames` samples.
    void startFadeOut(int frames) noexcept;
    /// True once a fade-out has reached 0 (the engine then retires the scene).
    bool fadedOut() const noexcept;

    /// The GRF the voices hear for a computed `newtons`: the value a GRF recording stores
    /// (`stored` = newtons / kGrfFileFullScaleNewtons as float) read back as loadGrfFile reads
    /// it, so that replaying the recording drives the voices with identical numbers.
    static float quantizeGrf(float newtons, float& stored) noexcept;

    /// Samples processed since the scene started.
    std::int64_t framesProcessed() const noexcept { return frames_; }
    /// Loudest GRF sample of the last block (newtons), for the meters.
    float lastGrfPeakNewtons() const noexcept { return grfPeak_; }
    /// Number of voices (GRF channels).
    int voiceCount() const noexcept { return static_cast<int>(voices_.size()); }
    std::uint64_t seed() const noexcept { return seed_; }
    const std::string& surfaceId() const noexcept { return surfaceId_; }
    ControlKind control() const noexcept { return control_; }
    /// The wading node of a water scene (null otherwise), e.g. to save its gait recording after
    /// the scene was retired.
    const WadingNode* wading() const noexcept { return wading_.get(); }
    OutputModality modality() const noexcept { return modality_; }
    bool hasNode(SceneNode node) const noexcept;
    /// A one-line description: "wood, walker, 2 voices, reverb hall (1.9 s), haptics L:both
    /// R:both".
    std::string summary() const;

    /// Clock reads per node (off by default); set before the scene runs.
    void setMeasureCost(bool on) noexcept { measure_ = on; }
    /// Costs of every node kind (absent nodes: present = false, zero cost).
    std::vector<SceneNodeCost> nodeCosts() const;

  private:
    LiveScene() = default;
    void runControl(const float* const* inputs, int numInputs, int n) noexcept;

    std::string surfaceId_;
    std::uint64_t seed_ = 1;
    ControlKind control_ = ControlKind::Walker;
    OutputModality modality_ = OutputModality::Audio;
    ProcessSpec spec_{};
    ChannelMap channels_;

    // control
    std::unique_ptr<VirtualWalker> walker_;
    std::unique_ptr<CookEnvelope> cook_;
    std::vector<int> micChannels_;
    GrfSignal replay_;
    std::shared_ptr<GrfSource> external_;
    std::unique_ptr<WadingNode> wading_;
    std::vector<std::vector<float>> grf_, grfScaled_;
    std::vector<float*> grfPtr_, grfScaledPtr_;
    std::vector<const float*> micPtr_;
    std::vector<float> zeros_;

    // voices + headphone mix (FootstepScene's arithmetic)
    std::vector<std::unique_ptr<Surface>> voices_;
    std::vector<double> panL_, panR_;
    double wet_ = 0, dry_ = 1;
    std::unique_ptr<Convolver> reverb_;
    std::string reverbName_;
    std::vector<float> voiceOut_, mono_, wetL_, wetR_, mixL_, mixR_;
    bool headphones_ = true;

    // ambience
    std::unique_ptr<AmbienceSource> ambience_;
    std::vector<float> ambL_, ambR_;

    // haptics: per shoe, the dry sum of its voices, band-limited
    bool haptics_ = false;
    std::array<Butterworth, 2> hapticFilter_;
    std::array<std::vector<float>, 2> shoe_;
    std::array<HapticPairs, 2> hapticPairs_{};
    std::vector<int> voiceShoe_; ///< 0 left, 1 right, 2 both
    float hapticGain_ = 1.0f;

    // recordings
    std::shared_ptr<AudioRecorder> grfRecorder_, outputRecorder_;
    std::vector<float> recL_, recR_;

    // fade
    std::vector<float> gain_;
    float fadeStart_ = 0.0f;
    int fadeInFrames_ = 0, fadeLength_ = 0, fadePos_ = 0;
    bool fadingOut_ = false;

    std::int64_t frames_ = 0;
    float grfPeak_ = 0.0f;
    bool measure_ = false;
    std::array<SceneNodeCost, static_cast<int>(SceneNode::Count)> cost_{};
};

} // namespace underfoot::engine
