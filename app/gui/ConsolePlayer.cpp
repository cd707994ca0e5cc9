// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/ConsolePlayer.h"
#include "app/gui/WalkerPlayer.h"

#include "app/wiring/Adapters.h"
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#include "experiment/Clips.h"

#include <QDir>
#include <QFileInfo>

#include <functional>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

ConsolePlayer::ConsolePlayer(WalkerPlayer& meters, engine::LiveEngine* engine,
                             const QString& studyPath, const exp::Protocol& protocol,
                             const QString& clipDir, exp::StimulusPlayer* injected,
                             const LiveSensors& sensors, const std::string& participant)
    : meters_(meters), injected_(injected) {
    if (!clipDir.isEmpty()) {
        exp::ClipPlayer::PlayFunction play;
        std::function<void()> stop;
        if (engine) {
            clipAudio_ = std::make_unique<wiring::ClipAudio>(*engine);
            play = [this](const std::string& path) { clipAudio_->play(path); };
            stop = [this] { clipAudio_->stop(); };
        }
        clips_ = std::make_unique<exp::ClipPlayer>(protocol, clipDir.toStdString(), play, stop);
        return;
    }
    if (injected_ || !engine) return;
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

ConsolePlayer::~ConsolePlayer() {
    // The shoes' reader thread pushes steps into the player's queues: stop it before the player
    // goes (the terminal session once freed the queue under a running reader; ASan).
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
}

exp::StimulusStart ConsolePlayer::start(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) {
    if (clips_) return clips_->start(stimulus, plannedSeed);
    exp::StimulusStart started;
    started.renderSeed = plannedSeed;
    if (injected_) started = injected_->start(stimulus, plannedSeed);
    // Silent baseline laps: the live player reserves the recording now and submits the scene
    // only when the sound comes on (LivePlayer::setMuted), so the recording reference stored
    // with the trial is the one replay needs.
    if (live_) started = live_->start(stimulus, plannedSeed);
    meters_.start(stimulus, started.renderSeed);
    return started;
}

void ConsolePlayer::stop() {
    if (clips_) {
        clips_->stop();
        return;
    }
    if (injected_) injected_->stop();
    if (live_) live_->stop();
    meters_.stop();
}

std::optional<std::string> ConsolePlayer::sensorFault() const {
    if (injected_) return injected_->sensorFault();
    if (live_) return live_->sensorFault();
    return std::nullopt;
}

void ConsolePlayer::setMuted(bool muted) {
    if (!live_) return;
    try {
        live_->setMuted(muted);
        soundError_.clear();
    } catch (const std::exception& e) {
        soundError_ = e.what(); // the lap is stored; the view shows why nothing is heard
    }
}

std::string ConsolePlayer::sensorConfig() const {
    std::string text;
    if (shoes_) text = "FSR shoes on " + shoes_->config().path;
    if (live_ && gyros_)
        text += (text.empty() ? "" : ", ") +
                ("OSC gyroscopes on UDP " + std::to_string(gyros_->port()));
    return text.empty() ? std::string("none") : text;
}

bool ConsolePlayer::live() const {
    return live_ != nullptr || clipAudio_ != nullptr;
}

const wiring::LiveTrialStats* ConsolePlayer::lastTrialStats() const {
    return live_ ? &live_->lastTrialStats() : nullptr;
}

/// What wiring::SessionRig::openLive builds around a serial port it opens itself, here around
/// the Setup view's shoes: a StepGrfPlayer with the default bank at the engine's rate, a
/// StepInput with the participant's thresholds attached to the shoes (reopened, since the
/// callback is set while stopped), the player as the scene's FSR source, and the shoes and steps
/// for the sensor log.
void ConsolePlayer::attachShoes(engine::LiveEngine& engine, const LiveSensors& sensors,
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

} // namespace underfoot::gui
