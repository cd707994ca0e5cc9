// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The console's live audio output: the engine's LiveEngine opened with the user's audio
/// settings (saved as TOML in the data folder), playing one scene at a time (palette
/// auditions), with its meters (peaks per output, xruns, callback load) for the views.
#include "engine/control/VirtualWalker.h"
#include "engine/io/AudioDevice.h"
#include "engine/scene/LiveEngine.h"

#include <QObject>
#include <QString>

#include <memory>

namespace underfoot::gui {

class AudioOutput : public QObject {
    Q_OBJECT
  public:
    /// Loads `settingsPath` when it exists (a broken file is reported by loadError()).
    explicit AudioOutput(QString settingsPath, QObject* parent = nullptr);
    ~AudioOutput() override;

    const engine::AudioSettings& settings() const { return settings_; }
    /// Replaces the settings (validated); restarts the stream when it was running.
    QString setSettings(const engine::AudioSettings& settings);
    /// Writes the settings file; returns "" or what went wrong.
    QString save() const;
    const QString& settingsPath() const { return path_; }
    const QString& loadError() const { return loadError_; }

    /// Opens the device and starts the stream; returns "" or what went wrong and what to do.
    QString start();
    void stop();
    bool running() const;
    /// Plays a surface preset walked on by the virtual walker (starts the stream if needed).
    QString playWalker(const QString& presetPath, const engine::WalkerParameters& walker);
    /// Plays a test tone on device output `outputChannel` (0-based) alone, replacing the current
    /// scene. Does not start the stream: returns why not when no device runs, or the problem.
    QString playTestTone(int outputChannel, double frequencyHz, double levelDbfs);
    /// Fades the current scene out.
    void silence();
    /// The meters (zeros when not running).
    engine::LiveMeters meters() const;
    /// The running engine (nullptr when not running).
    engine::LiveEngine* engine() const { return running() ? engine_.get() : nullptr; }
    /// "jack / system, 48000 Hz, 64 frames" or "not running".
    QString description() const;

  signals:
    void runningChanged(bool running);

  private:
    QString path_;
    QString loadError_;
    engine::AudioSettings settings_;
    std::unique_ptr<engine::LiveEngine> engine_;
};

} // namespace underfoot::gui
