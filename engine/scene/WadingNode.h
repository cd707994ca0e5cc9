// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The live scene's wading node (the wading study; docs/explanation/wading.md "Live"): a
/// WadingScene fed by a gait source on the audio thread. It replaces the GRF control and the
/// surface voices when a stimulus walks through water (surface "water").
///
/// Gait sources (all pulled once per audio block, allocation-free):
///  - LiveGyroGaitSource: GyroSamples popped from an OscGyroReceiver's SPSC queue, folded into
///    100 Hz GaitFrames by a GaitFrameAssembler; a frame takes effect at the first sample of the
///    block in which the audio thread sees it (the paper's live path: no added buffering); when
///    no frame has come for kGyroSilenceSeconds (sensor unplugged, sender stopped) the source
///    reads as standing still (all-zero frames every 10 ms) so that the water calms down instead
///    of holding the last swing;
///  - VirtualGaitSource: the virtual gait for a cadence, precomputed off the audio thread
///    (looped when a trial outlasts it), delivered at the sample where each 100 Hz frame is due.
/// Every frame the node hands to the scene is also appended to a preallocated gait recording
/// (capacity fixed before the trial; frames beyond it are counted, not recorded) that the main
/// thread writes with writeGaitCsv() after the trial, so that `underfoot wade --gait` re-renders
/// it. Each frame is also recorded with the sample (counted from the node's reset) at which it
/// took effect; writeArrivals() saves those as a gait arrivals file from which
/// renderWadingArrivals() reproduces the node's output exactly (`underfoot replay`).
#include "engine/dsp/ProcessSpec.h"
#include "engine/io/AudioFile.h"
#include "engine/render/SafetyLimiter.h"
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "engine/wading/WadingScene.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace underfoot::engine {

class OscGyroReceiver;

/// Where the wading node's gait frames come from.
class GaitSource {
  public:
    virtual ~GaitSource() = default;
    /// Off the audio thread.
    virtual void prepare(const ProcessSpec& spec) = 0;
    virtual void reset(std::uint64_t seed) noexcept = 0;
    /// Audio thread: writes the frames due in the next n samples (offsets in [0, n), sorted) to
    /// `frames` (at most `capacity`); returns how many. No allocation, locks or throws.
    virtual int pull(int n, TimedGaitFrame* frames, int capacity) noexcept = 0;
    /// For summaries ("osc gyroscopes", "virtual gait 63 steps/min").
    virtual std::string name() const = 0;
};

/// Gyroscope silence after which the live source reads as standing still (10 frame periods).
inline constexpr double kGyroSilenceSeconds = 0.1;

/// Live gyroscopes: pops the receiver's queue on the audio thread (the single consumer).
class LiveGyroGaitSource final : public GaitSource {
  public:
    /// The receiver must outlive the source and have no other consumer of popSample().
    explicit LiveGyroGaitSource(std::shared_ptr<OscGyroReceiver> receiver);
    void prepare(const ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    int pull(int n, TimedGaitFrame* frames, int capacity) noexcept override;
    std::string name() const override { return "osc gyroscopes"; }
    /// Samples popped and samples the assembler refused (NaN/Inf/absurd), since reset.
    std::uint64_t samplesPopped() const noexcept { return popped_.load(); }
    std::uint64_t samplesRejected() const noexcept { return rejected_.load(); }
    /// Standing frames made up because the gyroscopes were silent, since reset.
    std::uint64_t silentFrames() const noexcept { return silent_.load(); }

  private:
    std::shared_ptr<OscGyroReceiver> receiver_;
    GaitFrameAssembler assembler_;
    double rateHz_ = 48000;
    std::int64_t sinceFrame_ = 0; ///< samples since the last frame (real or made up)
    bool silentMode_ = false;
    std::uint64_t rejectedBefore_ = 0; ///< rejections counted by earlier assembler runs
    std::atomic<std::uint64_t> popped_{0}, rejected_{0}, silent_{0};
};

/// The virtual gait (engine/wading/Gait.h) at the stimulus's cadence.
class VirtualGaitSource final : public GaitSource {
  public:
    /// `loopSeconds` of gait are computed in prepare() and looped.
    explicit VirtualGaitSource(VirtualGaitParameters parameters, double loopSeconds = 600.0);
    void prepare(const ProcessSpec& spec) override;
    void reset(std::uint64_t seed) noexcept override;
    int pull(int n, TimedGaitFrame* frames, int capacity) noexcept override;
    std::string name() const override;

  private:
    VirtualGaitParameters parameters_;
    double loopSeconds_;
    double rateHz_ = 48000;
    std::uint64_t seed_ = 1;
    std::vector<GaitFrame> gait_;
    std::int64_t sample_ = 0;    ///< samples since reset
    std::int64_t nextFrame_ = 0; ///< index of the next frame (not wrapped)
};

/// A gait frame as the live node applied it: the sample, counted from the node's reset, at which
/// it took effect (block start + offset in the block).
struct GaitArrival {
    std::int64_t sample = 0;
    GaitFrame frame;
};

/// Everything the node was fed during a run: its frames where they took effect, and how many
/// samples it rendered.
struct GaitArrivals {
    std::vector<GaitArrival> frames; ///< sorted by sample
    std::int64_t samples = 0;        ///< samples the node processed since its reset
};

/// Writes a gait arrivals file (CSV: '#' comments, a `# samples = N` line, then the header
/// sample,time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,right_shank_dps; numbers in
/// shortest round-trip form, so reading back gives the same doubles). Throws GaitFileError.
void writeGaitArrivals(const std::string& path, const GaitArrivals& arrivals);
/// Reads it back. Throws GaitFileError naming file:line and what was expected (missing
/// `samples` line, wrong header, a non-number, NaN/Inf, samples out of order or beyond the run,
/// more than 10^8 frames).
GaitArrivals readGaitArrivals(const std::string& path);
GaitArrivals parseGaitArrivals(const std::string& text, const std::string& file);

/// Recorded arrivals as a gait source: each frame at its recorded sample (replay).
class RecordedGaitSource final : public GaitSource {
  public:
    explicit RecordedGaitSource(std::vector<GaitArrival> frames);
    void prepare(const ProcessSpec&) override {}
    void reset(std::uint64_t seed) noexcept override;
    int pull(int n, TimedGaitFrame* frames, int capacity) noexcept override;
    std::string name() const override { return "recorded gait arrivals"; }

  private:
    std::vector<GaitArrival> frames_;
    std::size_t next_ = 0;
    std::int64_t sample_ = 0;
};

/// Re-renders a live wading node's run: the same node (options, seed) fed the recorded frames at
/// their samples, in blocks of `blockSize` (the live block size) for `arrivals.samples` samples,
/// then the offline output stage (StereoSafetyLimiter, as renderWading). Identical to what the
/// live node rendered when blockSize is the live one. A run with more than 30 s without a
/// frame (from its start, between frames, or after the last) is refused, so the memory asked
/// for is bounded by the frames the file holds. Throws WadingOptionError / PresetError.
AudioBuffer renderWadingArrivals(const WadingOptions& options, const GaitArrivals& arrivals,
                                 int blockSize, LimiterReport* limiter = nullptr);

/// The node: a configured WadingScene + its gait source + the gait recording.
class WadingNode {
  public:
    /// Loads the depth preset and configures the scene (throws WadingOptionError / PresetError).
    /// `recordCapacityFrames` frames of gait are preallocated for the recording (0: none).
    WadingNode(const WadingOptions& options, std::unique_ptr<GaitSource> source,
               std::size_t recordCapacityFrames = 360000);
    /// Off the audio thread (allocates; throws FileError for preset recordings).
    void prepare(const ProcessSpec& spec);
    void reset(std::uint64_t seed) noexcept;
    /// Audio thread: pulls the block's gait frames, records them, renders n stereo samples
    /// (overwritten). No allocation, locks or throws.
    void process(float* left, float* right, int n) noexcept;

    const WadingOptions& options() const noexcept { return options_; }
    const GaitSource& source() const noexcept { return *source_; }
    const WadingScene& scene() const noexcept { return scene_; }
    /// Audio thread publishes: frames recorded and frames that did not fit.
    std::size_t recordedFrames() const noexcept { return recorded_.load(); }
    std::uint64_t unrecordedFrames() const noexcept { return overflow_.load(); }
    /// Frames handed to the scene since reset.
    std::uint64_t framesApplied() const noexcept { return applied_.load(); }
    /// Main thread, after the node stopped running: the recorded frames.
    std::vector<GaitFrame> recording() const;
    /// Main thread, after the node stopped running: writes the recording as a gait CSV (the
    /// times are made relative to the first frame). Throws GaitFileError / FileError.
    void writeRecording(const std::string& path) const;
    /// Main thread, after the node stopped running: the recorded frames with the samples at
    /// which they took effect, and the samples processed.
    GaitArrivals arrivals() const;
    /// Writes arrivals() as a gait arrivals file (writeGaitArrivals).
    void writeArrivals(const std::string& path) const;
    /// Samples processed since reset (audio thread publishes).
    std::int64_t samplesProcessed() const noexcept { return samples_.load(); }
    /// "deep, v2, butterworth_5hz, osc gyroscopes".
    std::string summary() const;

  private:
    static constexpr int kMaxFramesPerBlock = 64;
    WadingOptions options_;
    std::unique_ptr<GaitSource> source_;
    WadingScene scene_;
    std::vector<TimedGaitFrame> frames_;
    std::vector<GaitFrame> record_;
    std::vector<std::int64_t> recordSample_; ///< where each recorded frame took effect
    std::atomic<std::size_t> recorded_{0};
    std::atomic<std::int64_t> samples_{0};
    std::atomic<std::uint64_t> overflow_{0}, applied_{0};
};

} // namespace underfoot::engine
