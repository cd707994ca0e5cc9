// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Run view's stimulus player, out of RunView.cpp (issue #17: RunView.cpp keeps the view,
/// its own small classes what stands alone). Included by RunView.cpp only.
#include "app/gui/RunView.h"
#include "app/gui/WalkerPlayer.h"
#include "experiment/Clips.h"
#include "experiment/Session.h"

#ifdef UNDERFOOT_HAVE_WIRING
#include "app/wiring/Adapters.h"
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#endif

#include <QDir>
#include <QFileInfo>
#include <QString>

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

/// The session's player: the live engine (app/wiring's LivePlayer, which also records the GRF
/// next to the study for replay) while the Setup view's audio output runs, and always the
/// walker meters of the Run view. Listening tests present their pre-rendered clips instead
/// (experiment::ClipPlayer; heard through the live engine when it runs).
class ConsolePlayer final : public exp::StimulusPlayer {
  public:
    /// `clipDir` non-empty: a listening test (throws StoreError when the clips are not ready).
    /// `injected` non-null: stimuli are presented through it instead of the live engine.
    /// `engine` non-null: stimuli play through it; the `sensors` connected in the Setup view
    /// then drive FSR stimuli (the shoes' steps, detected with `participant`'s thresholds, choose
    /// the GRFs) and water stimuli (the gyroscopes). Throws when the thresholds file is broken
    /// or the shoes cannot be reopened.
    ConsolePlayer(WalkerPlayer& meters, engine::LiveEngine* engine, const QString& studyPath,
                  const exp::Protocol& protocol, const QString& clipDir,
                  exp::StimulusPlayer* injected, const LiveSensors& sensors,
                  const std::string& participant)
        : meters_(meters), injected_(injected) {
        if (!clipDir.isEmpty()) {
            exp::ClipPlayer::PlayFunction play;
            std::function<void()> stop;
#ifdef UNDERFOOT_HAVE_WIRING
            if (engine) {
                clipAudio_ = std::make_unique<wiring::ClipAudio>(*engine);
                play = [this](const std::string& path) { clipAudio_->play(path); };
                stop = [this] { clipAudio_->stop(); };
            }
#endif
            clips_ = std::make_unique<exp::ClipPlayer>(protocol, clipDir.toStdString(), play, stop);
            return;
        }
        if (injected_) return;
#ifdef UNDERFOOT_HAVE_WIRING
        if (engine) {
            wiring::LivePlayerOptions o;
            const QDir dir = QFileInfo(studyPath).dir();
            o.studyFolder = dir.path().toStdString();
            o.recordingFolder = dir.filePath("recordings").toStdString();
            QDir().mkpath(QString::fromStdString(o.recordingFolder));
            if (sensors.shoes) attachShoes(*engine, sensors, participant, o);
            o.scene.gyroReceiver = sensors.gyros;
            gyros_ = sensors.gyros;
            live_ = std::make_unique<wiring::LivePlayer>(*engine, o);
        }
#else
        (void)engine;
        (void)studyPath;
        (void)sensors;
        (void)participant;
#endif
    }
    ConsolePlayer(const ConsolePlayer&) = delete;
    ConsolePlayer& operator=(const ConsolePlayer&) = delete;
    /// Hands the shoes back to the Setup view: the step detector is detached (the port is
    /// reopened without it; a failure shows in the Setup view's status line).
    ~ConsolePlayer() override {
#ifdef UNDERFOOT_HAVE_WIRING
        // The shoes' reader thread pushes steps into the player's queues: stop it before the
        // player goes (the terminal session freed the queue under a running reader; ASan).
        if (shoes_) {
            shoes_->stop();
            shoes_->setFrameCallback({});
        }
        live_.reset();
        if (!shoes_) return;
        try {
            shoes_->start();
        } catch (const std::exception&) {
        }
#endif
    }
    exp::StimulusStart start(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) override {
        if (clips_) return clips_->start(stimulus, plannedSeed);
        exp::StimulusStart started;
        started.renderSeed = plannedSeed;
        if (injected_) started = injected_->start(stimulus, plannedSeed);
#ifdef UNDERFOOT_HAVE_WIRING
        // Silent baseline laps: the live player reserves the recording now and submits the
        // scene only when the sound comes on (LivePlayer::setMuted), so the recording reference
        // stored with the trial is the one replay needs.
        if (live_) started = live_->start(stimulus, plannedSeed);
#endif
        meters_.start(stimulus, started.renderSeed);
        return started;
    }
    void stop() override {
        if (clips_) {
            clips_->stop();
            return;
        }
        if (injected_) injected_->stop();
#ifdef UNDERFOOT_HAVE_WIRING
        if (live_) live_->stop();
#endif
        meters_.stop();
    }
    /// The fault of the injected player, else of the live player's sensors (shoes, gyroscopes).
    std::optional<std::string> sensorFault() const override {
        if (injected_) return injected_->sensorFault();
#ifdef UNDERFOOT_HAVE_WIRING
        if (live_) return live_->sensorFault();
#endif
        return std::nullopt;
    }
    /// The sensors this session's trials may use, for the session record.
    std::string sensorConfig() const {
        std::string text;
#ifdef UNDERFOOT_HAVE_WIRING
        if (shoes_) text = "FSR shoes on " + shoes_->config().path;
        if (live_ && gyros_)
            text += (text.empty() ? "" : ", ") +
                    ("OSC gyroscopes on UDP " + std::to_string(gyros_->port()));
#endif
        return text.empty() ? std::string("none") : text;
    }
    /// Whether stimuli are heard (live engine) or only shown (meters).
    bool live() const {
#ifdef UNDERFOOT_HAVE_WIRING
        return live_ != nullptr || clipAudio_ != nullptr;
#else
        return false;
#endif
    }

    void setMuted(bool muted) override {
        muted_ = muted;
#ifdef UNDERFOOT_HAVE_WIRING
        if (live_) {
            try {
                live_->setMuted(muted);
                soundError_.clear();
            } catch (const std::exception& e) {
                soundError_ = e.what(); // the lap is stored; the view shows why nothing is heard
            }
        }
#endif
    }
    /// Why the sound of the feedback laps did not start ("" when it did or was not asked).
    const std::string& soundError() const {
        return soundError_;
    }
    /// Whether the session asked for silence (baseline laps).
    bool muted() const {
        return muted_;
    }
    /// The clip presented last ("" before the first or outside listening tests).
    std::string lastClip() const {
        return clips_ ? clips_->lastPath() : std::string();
    }
#ifdef UNDERFOOT_HAVE_WIRING
    /// The live player's figures of the last stopped trial (nullptr without the live engine).
    const wiring::LiveTrialStats* lastTrialStats() const {
        return live_ ? &live_->lastTrialStats() : nullptr;
    }
#endif

  private:
    WalkerPlayer& meters_;
    exp::StimulusPlayer* injected_ = nullptr;
    std::unique_ptr<exp::ClipPlayer> clips_;
    bool muted_ = false;
    std::string soundError_;
#ifdef UNDERFOOT_HAVE_WIRING
    /// What `underfoot session --live` builds (app/cli/cmd_session.cpp): a StepGrfPlayer with
    /// the default bank at the engine's rate, a StepInput with the participant's thresholds
    /// attached to the shoes (reopened, since the callback is set while stopped), the player as
    /// the scene's FSR source, and the shoes and steps for the sensor log.
    void attachShoes(engine::LiveEngine& engine, const LiveSensors& sensors,
                     const std::string& participant, wiring::LivePlayerOptions& o) {
        namespace eng = underfoot::engine;
        const QString path =
            QDir(sensors.thresholdsDir).filePath(QString::fromStdString(participant) + ".toml");
        const eng::StepThresholds thresholds = QFileInfo::exists(path)
                                                   ? eng::loadStepThresholds(path.toStdString())
                                                   : eng::StepThresholds{};
        auto player = std::make_shared<eng::StepGrfPlayer>(
            eng::StepGrfPlayer::loadDefaultBank(engine.settings().sampleRateHz),
            eng::StepGrfPlayerConfig{});
        auto steps = std::make_shared<eng::StepInput>(thresholds);
        sensors.shoes->stop();
        steps->attach(*sensors.shoes, player.get());
        try {
            sensors.shoes->start();
        } catch (...) {
            sensors.shoes->setFrameCallback({}); // `steps` dies with this exception
            throw;
        }
        shoes_ = sensors.shoes; // from here the destructor detaches the steps again
        steps_ = steps;
        stepPlayer_ = player;
        o.scene.fsrSource = std::make_shared<wiring::StepGrfSource>(player);
        o.shoes = sensors.shoes;
        o.shoeSteps = steps;
    }
    std::shared_ptr<engine::SerialSource> shoes_;
    std::shared_ptr<engine::StepInput> steps_;
    std::shared_ptr<engine::StepGrfPlayer> stepPlayer_;
    std::shared_ptr<engine::OscGyroReceiver> gyros_;
    std::unique_ptr<wiring::LivePlayer> live_;
    std::unique_ptr<wiring::ClipAudio> clipAudio_;
#endif
};

} // namespace underfoot::gui
