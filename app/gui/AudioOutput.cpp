// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/AudioOutput.h"

#include "engine/scene/TestTone.h"

#include "engine/scene/LiveScene.h"

#include <QFile>

namespace underfoot::gui {

namespace eng = underfoot::engine;

AudioOutput::AudioOutput(QString settingsPath, QObject* parent)
    : QObject(parent), path_(std::move(settingsPath)) {
    if (QFile::exists(path_)) {
        try {
            settings_ = eng::loadAudioSettings(path_.toStdString());
        } catch (const std::exception& e) {
            loadError_ = tr("%1\nThe default audio settings are used until the file is fixed or "
                            "saved again from the Setup view.")
                             .arg(QString::fromStdString(e.what()));
        }
    }
}

AudioOutput::~AudioOutput() {
    stop();
}

QString AudioOutput::setSettings(const eng::AudioSettings& settings) {
    try {
        settings.validate();
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    const bool wasRunning = running();
    stop();
    settings_ = settings;
    return wasRunning ? start() : QString();
}

QString AudioOutput::save() const {
    try {
        eng::saveAudioSettings(path_.toStdString(), settings_);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return {};
}

QString AudioOutput::start() {
    if (running()) return {};
    auto engine = std::make_unique<eng::LiveEngine>();
    try {
        engine->open(settings_);
        engine->start();
    } catch (const std::exception& e) {
        return tr("%1\nCheck the audio API and device in the Setup view (Ctrl+5), or start "
                  "the sound server (e.g. JACK), then try again.")
            .arg(QString::fromStdString(e.what()));
    }
    engine_ = std::move(engine);
    emit runningChanged(true);
    return {};
}

void AudioOutput::stop() {
    if (!engine_) return;
    engine_->close();
    engine_.reset();
    emit runningChanged(false);
}

bool AudioOutput::running() const {
    return engine_ && engine_->isRunning();
}

QString AudioOutput::playWalker(const QString& presetPath, const eng::WalkerParameters& walker) {
    if (const QString error = start(); !error.isEmpty()) return error;
    try {
        eng::LiveSceneDescription d;
        d.surface = presetPath.toStdString();
        d.control = eng::ControlKind::Walker;
        d.walker = walker;
        d.seed = 1;
        auto scene = eng::LiveScene::create(std::move(d), engine_->processSpec(),
                                            engine_->settings().channels);
        if (!engine_->submit(std::move(scene)))
            return tr("The audio engine is busy; try again in a moment.");
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return {};
}

QString AudioOutput::playTestTone(int outputChannel, double frequencyHz, double levelDbfs) {
    if (!running())
        return tr("No audio device runs: start the audio output first (Setup view, Start audio).");
    if (outputChannel < 0 || outputChannel >= engine_->outputChannels())
        return tr("Output %1 is not open on this device (%2 outputs open); map it in the channel "
                  "settings and restart the audio.")
            .arg(outputChannel + 1)
            .arg(engine_->outputChannels());
    try {
        auto scene =
            eng::makeTestToneScene(outputChannel, {frequencyHz, levelDbfs}, engine_->processSpec());
        if (!engine_->submit(std::move(scene)))
            return tr("The audio engine is busy; try again in a moment.");
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return {};
}

void AudioOutput::silence() {
    if (engine_) engine_->submit(nullptr);
}

eng::LiveMeters AudioOutput::meters() const {
    return engine_ ? engine_->meters() : eng::LiveMeters{};
}

QString AudioOutput::description() const {
    if (!engine_) return tr("not running");
    return tr("%1 / %2, %3 Hz, %4 frames")
        .arg(QString::fromStdString(engine_->openedApi()),
             QString::fromStdString(engine_->openedDevice()))
        .arg(engine_->settings().sampleRateHz)
        .arg(engine_->settings().blockSize);
}

} // namespace underfoot::gui
