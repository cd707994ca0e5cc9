// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The experiment's StimulusPlayer wired to the engine.
///
///  - LivePlayer: each start() builds a LiveScene from the stimulus (surface, soundscape,
///    reverb, modalities, input) off the audio thread, records its GRF channels to a WAV file
///    next to the study (the path StimulusStart::grfRecording returns, relative to the study's
///    folder, so `underfoot replay` re-renders the trial), and submits it to a running
///    LiveEngine with the engine's crossfade; stop() fades it out, waits for the audio thread to
///    hand it back and closes the recording.
///  - OfflinePlayer: renders a stimulus to memory (the GUI palette's preview, headless runs)
///    through the one offline renderer (StimulusRender.h). Sensor stimuli are previewed with
///    the default walker.
#include "app/wiring/WadingSource.h"
#include "engine/control/StepInput.h"
#include "engine/io/AudioFile.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Session.h"

#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <thread>

namespace underfoot::wiring {

/// What the stimulus description does not say.
struct StimulusSceneOptions {
    /// GRF sources for sensor inputs (null: such stimuli are refused with a clear error).
    std::shared_ptr<engine::GrfSource> fsrSource, gyroSource;
    /// The gyroscopes of water stimuli (`surface = "water"` with the gyro sensor as input; null:
    /// such stimuli are refused with a clear error). Water stimuli with a walker input use the
    /// virtual gait at their `wading.cadence`.
    std::shared_ptr<engine::OscGyroReceiver> gyroReceiver;
    /// Actuator pairs driven when the stimulus has haptics.
    std::array<engine::HapticPairs, 2> hapticPairs{engine::HapticPairs::Both,
                                                   engine::HapticPairs::Both};
    double hapticGainDb = 0.0;
    /// Newtons per unit of |x| of the microphones' envelope.
    double microphoneNewtonsPerFullScale = 1000.0;
};

/// The engine's walker parameters from a stimulus's `walker = {...}` table. Throws
/// std::invalid_argument naming the key and what was expected.
engine::WalkerParameters walkerFromStimulus(const experiment::Parameters& walker);

/// The scene description of a stimulus (the soundscape is loaded here). Throws
/// std::invalid_argument / DefinitionError / PresetError with a clear message.
engine::LiveSceneDescription describeStimulus(const experiment::Stimulus& stimulus,
                                              std::uint64_t seed,
                                              const StimulusSceneOptions& options = {});

struct LivePlayerOptions {
    /// Folder receiving the GRF recordings ("" = no recording: replay then needs a walker).
    std::string recordingFolder;
    /// Recording paths are returned relative to this folder when they lie inside it (the
    /// study file's folder, which `underfoot replay` resolves them against).
    std::string studyFolder;
    StimulusSceneOptions scene;
    /// The FSR shoes behind `scene.fsrSource` (a StepGrfSource): the serial port and the step
    /// detector attached to it. With them, every FSR trial writes its sensor log (shoe frames,
    /// step events, the GRFs the player chose; SensorLogWriter) next to its GRF recording as
    /// `<recording>.sensors.csv`, referenced by StimulusStart::sensorLog, and the port's faults
    /// are reported by sensorFault(). This player is then the only consumer of their queues.
    std::shared_ptr<engine::SerialSource> shoes;
    std::shared_ptr<engine::StepInput> shoeSteps;
};

/// What the engine measured while one stimulus played (from start() to stop()).
struct LiveTrialStats {
    std::uint64_t frames = 0;           ///< audio frames the device ran
    std::uint64_t xruns = 0;            ///< device over/underflows
    double averageLoadPercent = 0;      ///< callback time / audio time
    double maxLoadPercent = 0;          ///< worst callback
    double maxBlockSeconds = 0;         ///< worst callback time
    std::uint64_t droppedGrfFrames = 0; ///< GRF frames lost by the recording ring (0 = complete)
};

/// Plays stimuli live through a LiveEngine that the caller opened and started.
class LivePlayer final : public experiment::StimulusPlayer {
  public:
    LivePlayer(engine::LiveEngine& engine, LivePlayerOptions options);
    ~LivePlayer() override;
    /// Throws std::runtime_error (building the scene, creating the recording, a full command
    /// queue) with the reason; nothing plays then.
    experiment::StimulusStart start(const experiment::Stimulus& stimulus,
                                    std::uint64_t plannedSeed) override;
    void stop() override;
    /// Silent baseline laps ([laps]): while muted, start() reserves the recording's name (and
    /// returns it) but submits no scene; unmuting starts the scene then, so that its recording
    /// holds exactly what was heard and `underfoot replay` reproduces it. Unmuting throws as
    /// start() does when the scene cannot be built.
    void setMuted(bool muted) override;

    bool playing() const noexcept { return playing_; }
    /// The running (or last) scene's one-line summary.
    const std::string& sceneSummary() const noexcept { return summary_; }
    /// The absolute path of the running (or last) GRF recording ("" when none). For a water
    /// stimulus: its gait recording (CSV, written at stop(); `underfoot wade --gait` re-renders
    /// it), which is also what StimulusStart::grfRecording refers to.
    const std::string& recordingPath() const noexcept { return recordingPath_; }
    /// Frames of the last recording lost to a full ring (0 = complete), after stop().
    std::uint64_t lastDroppedFrames() const noexcept { return lastDropped_; }
    /// The last stopped trial's figures. They are also written next to its GRF recording as
    /// `<recording>.meters.toml` (frames, xruns, loads, dropped frames, scene summary).
    const LiveTrialStats& lastTrialStats() const noexcept { return stats_; }
    /// The last stopped trial's figures with the audio settings' rate and block size, for the
    /// session to store with the trial (nullopt before the first stop()).
    std::optional<experiment::TrialAudioStats> stoppedTrialStats() const override;
    /// Why the sensor of the running (or last stopped) trial cannot be recorded now ("FSR shoes
    /// silent: no frame for 402 ms ...", "gyroscopes disconnected: ..."; the shoes for FSR
    /// stimuli, the OSC receiver for gyro stimuli), or nullopt (fine, or no sensor). Any thread.
    std::optional<std::string> sensorFault() const override;
    /// The absolute path of the running (or last) trial's sensor log ("" when none).
    const std::string& sensorLogPath() const noexcept { return sensorLogPath_; }
    /// Rows written to the last sensor log (after stop()).
    std::size_t lastSensorLogRows() const noexcept { return sensorLogRows_; }

  private:
    enum class TrialSensor { None, Shoes, Gyro };
    struct Deferred {
        experiment::Stimulus stimulus;
        std::uint64_t seed = 0;
        std::string path;
    };
    experiment::StimulusStart begin(const experiment::Stimulus& stimulus, std::uint64_t plannedSeed,
                                    const std::string& path);
    std::string reservePath(const experiment::Stimulus& stimulus, std::uint64_t plannedSeed);
    std::string reference(const std::string& path) const;
    void startSensorLog(const std::string& path);
    void stopSensorLog();

    engine::LiveEngine& engine_;
    LivePlayerOptions options_;
    std::shared_ptr<engine::AudioRecorder> recorder_;
    std::string summary_, recordingPath_;
    std::uint64_t lastDropped_ = 0;
    engine::LiveMeters startMeters_;
    double startLoadSeconds_ = 0;
    LiveTrialStats stats_;
    int counter_ = 0;
    bool playing_ = false;
    bool stopped_ = false; ///< a trial was stopped (stats_ is valid)
    bool wading_ = false;  ///< the running trial is a water scene (gait recorded at stop)
    bool muted_ = false;   ///< silent baseline laps: scenes wait for setMuted(false)
    std::optional<Deferred> deferred_;
    std::atomic<TrialSensor> sensor_{TrialSensor::None}; ///< what the running trial depends on
    std::string sensorLogPath_, sensorLogError_;
    std::size_t sensorLogRows_ = 0;
    std::thread sensorLogThread_;
    std::atomic<bool> sensorLogRunning_{false};
};

/// A player that renders each started stimulus to memory (lastRender()).
class OfflinePlayer final : public experiment::StimulusPlayer {
  public:
    explicit OfflinePlayer(double seconds = 10.0, double sampleRateHz = 48000.0)
        : seconds_(seconds), rate_(sampleRateHz) {}
    experiment::StimulusStart start(const experiment::Stimulus& stimulus,
                                    std::uint64_t plannedSeed) override;
    void stop() override {}
    const engine::AudioBuffer& lastRender() const noexcept { return last_; }

  private:
    double seconds_, rate_;
    engine::AudioBuffer last_;
};

} // namespace underfoot::wiring
