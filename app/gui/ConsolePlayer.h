// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Run view's stimulus player. It drives the live engine the Setup view runs (its audio
/// output) instead of opening a device of its own, so it assembles its rig from that engine and
/// the sensors connected there; the terminal's `session --live` opens its own device through
/// wiring::SessionRig. Both use the same pieces: wiring::LivePlayer (the stimulus scene, its
/// GRF recording next to the study for replay, the sensor log), wiring::ClipAudio with
/// experiment::ClipPlayer for listening tests, a StepGrfPlayer behind the FSR shoes' steps.
/// The walker meters of the Run view follow every stimulus.
#include "app/gui/RunView.h"
#include "experiment/Session.h"

#include <QString>

#include <memory>
#include <optional>
#include <string>

namespace underfoot::experiment {
class ClipPlayer;
}
namespace underfoot::engine {
class StepInput;
class StepGrfPlayer;
} // namespace underfoot::engine
namespace underfoot::wiring {
class LivePlayer;
class ClipAudio;
struct LivePlayerOptions;
struct LiveTrialStats;
} // namespace underfoot::wiring

namespace underfoot::gui {

class WalkerPlayer;

class ConsolePlayer final : public experiment::StimulusPlayer {
  public:
    /// `clipDir` non-empty: a listening test (throws StoreError when the clips are not ready).
    /// `injected` non-null: stimuli are presented through it instead of the live engine.
    /// `engine` non-null: stimuli play through it; the `sensors` connected in the Setup view
    /// then drive FSR stimuli (the shoes' steps, detected with `participant`'s thresholds, choose
    /// the GRFs) and water stimuli (the gyroscopes). Throws when the thresholds file is broken
    /// or the shoes cannot be reopened.
    ConsolePlayer(WalkerPlayer& meters, engine::LiveEngine* engine, const QString& studyPath,
                  const experiment::Protocol& protocol, const QString& clipDir,
                  experiment::StimulusPlayer* injected, const LiveSensors& sensors,
                  const std::string& participant);
    ConsolePlayer(const ConsolePlayer&) = delete;
    ConsolePlayer& operator=(const ConsolePlayer&) = delete;
    /// Hands the shoes back to the Setup view: the step detector is detached (the port is
    /// reopened without it; a failure shows in the Setup view's status line).
    ~ConsolePlayer() override;

    experiment::StimulusStart start(const experiment::Stimulus& stimulus,
                                    std::uint64_t plannedSeed) override;
    void stop() override;
    /// The fault of the injected player, else of the live player's sensors (shoes, gyroscopes).
    std::optional<std::string> sensorFault() const override;
    void setMuted(bool muted) override;

    /// The sensors this session's trials may use, for the session record.
    std::string sensorConfig() const;
    /// Whether stimuli are heard (live engine) or only shown (meters).
    bool live() const;
    /// Why the sound of the feedback laps did not start ("" when it did or was not asked).
    const std::string& soundError() const { return soundError_; }
    /// The live player's figures of the last stopped trial (nullptr without the live engine).
    const wiring::LiveTrialStats* lastTrialStats() const;

  private:
    void attachShoes(engine::LiveEngine& engine, const LiveSensors& sensors,
                     const std::string& participant, wiring::LivePlayerOptions& options);

    WalkerPlayer& meters_;
    experiment::StimulusPlayer* injected_ = nullptr;
    std::unique_ptr<experiment::ClipPlayer> clips_;
    std::string soundError_;
    std::shared_ptr<engine::SerialSource> shoes_;
    std::shared_ptr<engine::StepInput> steps_;
    std::shared_ptr<engine::StepGrfPlayer> stepPlayer_;
    std::shared_ptr<engine::OscGyroReceiver> gyros_;
    std::unique_ptr<wiring::LivePlayer> live_;
    std::unique_ptr<wiring::ClipAudio> clipAudio_;
};

} // namespace underfoot::gui
