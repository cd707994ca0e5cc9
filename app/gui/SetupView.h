// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Setup view: audio API, device, sample rate, block size and channel map (headphones,
/// haptic actuators per shoe), saved as the engine's audio settings TOML; start/stop the live
/// engine with its meters (peak per output, xruns, callback load); and the step-calibration
/// plot: the ground reaction force under each foot and its time derivative against the onset
/// threshold, from the virtual walker while no shoes are connected.
#include <QWidget>

class QComboBox;
class QSpinBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;
class QTimer;
class QProgressBar;
class QChartView;
class QChart;

namespace underfoot::gui {

class AudioOutput;

class SetupView : public QWidget {
    Q_OBJECT
  public:
    SetupView(AudioOutput& audio, QWidget* parent = nullptr);

    /// Applies the form to the audio output; returns "" or the problem.
    QString applyForm();
    /// Redraws the calibration plot (walker parameters and threshold from the form).
    void updateCalibrationPlot();
    /// Steps detected in the plotted window (derivative above threshold, positive changes only).
    int detectedSteps() const { return detectedSteps_; }

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
    QDoubleSpinBox* massKg_;
    QDoubleSpinBox* cadence_;
    QDoubleSpinBox* threshold_;
    QLabel* stepsLabel_;
    QChart* grfChart_;
    QChart* derivativeChart_;
    int detectedSteps_ = 0;
};

} // namespace underfoot::gui
