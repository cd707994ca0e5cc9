// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The live engine: owns the audio stream (RtAudio, duplex, planar float) and runs the current
/// LiveScene in its callback.
///
/// Threads (docs/explanation/live-audio.md):
///  - main thread: open / start / stop, builds scenes (LiveScene::create) and submit()s them,
///    reads meters(), releases retired scenes (collectRetired(), also done by submit and stop);
///  - audio thread: the callback. It takes commands from an SPSC queue (scene swaps, fade-outs,
///    latency probes), runs the scenes, crossfades a swap over AudioSettings::crossfadeMs,
///    hands the old scene back through a second SPSC queue, and publishes meters through
///    atomics. It never allocates, locks, logs, throws or frees a scene.
/// Without a device (openOffline) the same callback body runs from processBlock(): tests and
/// benchmarks drive it block by block.
#include "engine/io/AudioDevice.h"
#include "engine/render/SafetyLimiter.h"
#include "engine/scene/LiveScene.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace underfoot::engine {

/// A snapshot of the published meters (any thread).
struct LiveMeters {
    static constexpr int kMaxChannels = 16;
    int outputChannels = 0;
    /// Peak |x| and RMS of the last block, per device output channel.
    std::array<float, kMaxChannels> outputPeak{}, outputRms{};
    /// Peak |x| of the last block per device input channel.
    std::array<float, kMaxChannels> inputPeak{};
    int inputChannels = 0;
    float grfPeakNewtons = 0;          ///< loudest GRF sample of the current scene's last block
    std::uint64_t xruns = 0;           ///< device over/underflows reported to the callback
    std::uint64_t blocks = 0;          ///< callbacks run
    std::uint64_t frames = 0;          ///< frames processed
    double lastBlockSeconds = 0;       ///< time spent in the last callback
    double maxBlockSeconds = 0;        ///< worst callback since start / resetPeaks()
    double loadPercent = 0;            ///< last callback time / block period x 100
    double maxLoadPercent = 0;         ///< worst of it
    double averageLoadPercent = 0;     ///< total callback time / total audio time x 100
    std::uint64_t scenesSwapped = 0;   ///< scenes that became current
    std::uint64_t scenesRetired = 0;   ///< scenes handed back to the main thread
    std::uint64_t droppedCommands = 0; ///< submit() calls refused because the queue was full
    /// Last latency-probe result: frames from the probe impulse leaving an output to it arriving
    /// at an input; -1 = none measured (or still waiting).
    long long probeLatencyFrames = -1;
    /// Output safety limiter (engine/render/SafetyLimiter.h, -0.3 dBFS ceiling per output
    /// channel): output samples it reduced since the engine was opened, and its deepest
    /// reduction. 0 means it never acted (the output passed bit for bit).
    std::uint64_t limitedSamples = 0;
    double limiterMaxReductionDb = 0;
};

/// Hooks run by the callback on the audio thread at its start and end (tests arm an
/// allocation trap with them); plain function pointers, set before start().
struct CallbackHooks {
    void (*enter)() = nullptr;
    void (*leave)() = nullptr;
};

class LiveEngine {
  public:
    LiveEngine();
    /// Stops and closes the stream and releases every scene.
    ~LiveEngine();
    LiveEngine(const LiveEngine&) = delete;
    LiveEngine& operator=(const LiveEngine&) = delete;

    /// Validates the settings and opens the device (stream not running yet). Throws
    /// AudioSettingsError naming the device / API and listing what exists when a device is
    /// unknown, and when RtAudio refuses the stream (with its message).
    void open(const AudioSettings& settings);
    /// No device: the callback body runs from processBlock() with these settings.
    void openOffline(const AudioSettings& settings);
    /// Starts the stream (device mode). Throws AudioSettingsError when RtAudio fails.
    void start();
    /// Stops the stream (drains nothing: the current scene keeps its place) and releases
    /// retired scenes.
    void stop();
    /// Stops and closes; scenes are released.
    void close();
    bool isOpen() const noexcept;
    bool isRunning() const noexcept;

    /// The settings in use (after open; the rate and block size the device accepted).
    const AudioSettings& settings() const noexcept { return settings_; }
    /// Rate and largest block, for LiveScene::create.
    ProcessSpec processSpec() const noexcept;
    /// Device channels opened.
    int outputChannels() const noexcept { return numOutputs_; }
    int inputChannels() const noexcept { return numInputs_; }
    /// The API and device actually opened ("jack", "system").
    const std::string& openedApi() const noexcept { return openedApi_; }
    const std::string& openedDevice() const noexcept { return openedDevice_; }
    /// Latency the device reports (RtAudio getStreamLatency), frames; 0 when unknown.
    long deviceLatencyFrames() const;

    /// Swaps `scene` in with the crossfade (nullptr: fade the current scene out to silence).
    /// The scene must have been created with processSpec() and settings().channels. Returns
    /// false (and keeps nothing) when the command queue is full. Releases retired scenes.
    bool submit(std::unique_ptr<LiveScene> scene);
    /// Releases scenes the audio thread handed back; returns how many.
    int collectRetired();
    /// Takes the scenes the audio thread handed back (e.g. to read their nodeCosts()).
    std::vector<std::unique_ptr<LiveScene>> takeRetired();
    /// Whether the audio thread has taken every submitted command and retired every faded
    /// scene (so that a recorder fed by a retired scene can be finished).
    bool idle() const noexcept;
    /// Waits (sleeping) until idle() or the timeout; returns idle(). Retired scenes stay
    /// queued for collectRetired() / takeRetired().
    bool waitIdle(double timeoutSeconds);

    /// Emits one impulse on `outputChannel` and watches `inputChannel` for it (threshold 0.5);
    /// the result appears in meters().probeLatencyFrames. Returns false when the queue is full.
    bool probeLatency(int outputChannel, int inputChannel);

    /// Snapshot of the meters.
    LiveMeters meters() const noexcept;
    /// Resets the worst-case figures (max block time / load).
    void resetPeaks() noexcept;

    void setCallbackHooks(const CallbackHooks& hooks) noexcept { hooks_ = hooks; }

    /// The callback body (device callback or offline): planar inputs/outputs with
    /// inputChannels() / outputChannels() channels, n <= block size. `xrun` marks a device
    /// over/underflow reported for this block.
    void processBlock(const float* const* inputs, float* const* outputs, int n,
                      bool xrun = false) noexcept;

  private:
    struct Device;
    struct Command;
    struct Queues;
    void openCommon(const AudioSettings& settings);
    void releaseAll();

    AudioSettings settings_;
    std::unique_ptr<Device> device_;
    std::unique_ptr<Queues> queues_;
    int numOutputs_ = 0, numInputs_ = 0;
    std::string openedApi_, openedDevice_;
    bool offline_ = false;
    CallbackHooks hooks_{};

    // audio-thread state
    friend struct DeviceCallback;
    void retire(LiveScene* scene) noexcept;
    LiveScene* current_ = nullptr;
    LiveScene* fading_ = nullptr;
    std::array<LiveScene*, 8> pending_{}; ///< faded out, but the return queue was full
    std::atomic<std::uint64_t> leaked_{0};
    int crossfadeFrames_ = 0;
    std::uint64_t framesTotal_ = 0;
    std::array<const float*, 64> callbackIn_{};
    std::array<float*, 64> callbackOut_{};
    std::vector<float> silence_;
    std::array<SafetyLimiter, 64> limiters_{}; ///< one per output channel, before the meters
    struct Probe {
        int out = -1, in = -1;
        long long emittedAt = -1;
        bool active = false;
    } probe_;

    // published (atomics)
    struct Published;
    std::unique_ptr<Published> pub_;
    std::atomic<std::uint64_t> submitted_{0}, taken_{0};
};

} // namespace underfoot::engine
