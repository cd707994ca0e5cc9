// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Setup view: audio API, device, sample rate, block size and channel map (headphones,
/// haptic actuators per shoe), saved as the engine's audio settings TOML; start/stop the live
/// engine with its meters (peak per output, xruns, callback load); the FSR shoes' serial
/// connection with its live status; and the step calibration of a participant: a recording
/// (from the shoes, or from the engine's scripted shoe simulator when none are connected) is
/// calibrated by engine::calibrateSteps, plotted (pressures, their derivative against each
/// sensor's onset threshold), checked with the StepDetector and saved as the participant's
/// thresholds TOML.
#include "engine/control/StepCalibration.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"

#include <QWidget>

#include <memory>
#include <vector>

class QComboBox;
class QSpinBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;
class QTimer;
class QProgressBar;
class QChartView;
class QChart;
class QLineEdit;

namespace underfoot::gui {

class AudioOutput;

class SetupView : public QWidget {
    Q_OBJECT
  public:
    SetupView(AudioOutput& audio, const QString& dataDir, QWidget* parent = nullptr);

    /// Applies the form to the audio output; returns "" or the problem.
    QString applyForm();
    /// Calibrates from the scripted shoe simulator's default walk; false (message shown) when
    /// the calibration fails.
    bool calibrateSimulated();
    /// Starts (or stops) recording for `seconds` from the connected shoes, else from the serial
    /// port in the form (opened for the recording only). Refused while a session uses the shoes.
    void toggleSerialRecording();
    /// Connects (or disconnects) the FSR shoes on the serial port in the form: they stay open
    /// for the Run view's sessions (FSR stimuli). Returns "" or why not (also shown).
    QString toggleShoes();
    /// The connected shoes (null when not connected). A session that holds them is the only
    /// reader of their frames; this view then shows their status only.
    std::shared_ptr<engine::SerialSource> connectedShoes() const { return shoes_; }
    /// Whether a session holds the connected shoes.
    bool shoesInSession() const { return shoes_ && shoes_.use_count() > 1; }
    /// The listening OSC gyroscope receiver (null when not listening).
    std::shared_ptr<engine::OscGyroReceiver> gyroReceiver() const { return gyro_; }
    /// The folder of the participants' saved thresholds (`<code>.toml`).
    QString thresholdsDir() const;
    /// The shoes' status line.
    QString sensorStatusText() const;
    /// Steps the detector found with the proposed thresholds in the calibration recording.
    int detectedSteps() const { return detectedSteps_; }
    /// Strikes the recording is known to contain (simulation), or -1.
    int expectedSteps() const { return expectedSteps_; }
    /// Saves the proposed thresholds for the participant code in the form; returns the path.
    QString saveThresholds();
    QString calibrationText() const;
    /// Plays (or, when one plays, stops) the test tone on the output chosen in the form:
    /// headphones 1 kHz, actuators 200 Hz, both -20 dBFS. Returns "" or why not.
    QString toggleTestTone();
    /// The test tone button (its text says why it is disabled when no device runs).
    QPushButton* testToneButton() const { return toneButton_; }
    bool testTonePlaying() const { return tonePlaying_; }
    /// Starts (or stops) listening for the OSC gyroscopes on the port in the form (0: any free
    /// port). Returns "" or why not.
    QString toggleGyroListening();
    /// The bound UDP port while listening, else 0.
    int gyroPort() const;
    /// The gyroscope status line (state, rate, counters per limb).
    QString gyroStatusText() const;

  private:
    void fillDevices();
    void loadForm();
    void updateMeters();
    void setMessage(const QString& text, bool error);

    AudioOutput& audio_;
    QComboBox* api_;
    QComboBox* device_;
    QComboBox* rate_;
    QComboBox* block_;
    QSpinBox* headL_;
    QSpinBox* headR_;
    QSpinBox* haptic_[4];
    QPushButton* startStop_;
    QLabel* meterText_;
    QProgressBar* outputMeters_[8];
    QLabel* message_;
    QTimer* meterTimer_;
    QComboBox* toneOutput_;
    QPushButton* toneButton_;
    bool tonePlaying_ = false;
    void refreshToneButton();
    void pollGyro();
    QSpinBox* gyroPortBox_;
    QPushButton* gyroListen_;
    QLabel* gyroStatus_;
    QTimer* gyroTimer_;
    std::shared_ptr<engine::OscGyroReceiver> gyro_;
    void calibrate(const std::vector<engine::ShoeFrame>& frames, int expectedSteps);
    void pollSerial();

    QString dataDir_;
    QComboBox* port_;
    QSpinBox* seconds_;
    QLineEdit* participant_;
    QPushButton* record_;
    QLabel* sensorStatus_;
    QLabel* calibration_;
    QChart* pressureChart_;
    QChart* derivativeChart_;
    QTimer* sensorTimer_;
    QPushButton* connectShoes_;
    std::shared_ptr<engine::SerialSource> shoes_;
    bool recordingActive_ = false;
    bool disconnectAfterRecording_ = false;
    QString connectShoesNow();
    void disconnectShoes();
    std::vector<engine::ShoeFrame> recording_;
    double recordUntilS_ = 0;
    std::unique_ptr<engine::StepCalibrationResult> result_;
    int detectedSteps_ = 0;
    int expectedSteps_ = -1;
};

} // namespace underfoot::gui
