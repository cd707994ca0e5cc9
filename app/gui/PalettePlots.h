// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The sound palette's comparison pictures: a step's spectrogram (log frequency in Hz, time in
/// s, colours in dB re the step's own peak over a fixed 60 dB range, so that a render and a
/// recording of any level share one colour scale) and the band-energy bars of both sides.
#include <QString>
#include <QStringList>
#include <QWidget>

#include <vector>

namespace underfoot::gui {

/// Magnitude spectrogram of one step (frames x bins, dB), computed off the UI thread.
struct StepSpectrogram {
    std::vector<std::vector<float>> db; ///< frames x (fftSize / 2 + 1) bins
    double rateHz = 48000;
    int fftSize = 512, hop = 128;
    double seconds = 0;   ///< length of the step
    double maxHz = 16000; ///< upper edge shown (the analysis band)
    float peakDb = 0;     ///< highest bin of all frames
    bool empty() const { return db.empty(); }
};

/// Spectrogram of a mono step at `rateHz` (512-point frames, hop 128), up to `maxHz`.
StepSpectrogram stepSpectrogram(const std::vector<float>& step, double rateHz, double maxHz);

class SpectrogramPlot : public QWidget {
    Q_OBJECT
  public:
    static constexpr double kRangeDb = 60; ///< colours span the top 60 dB of each step

    explicit SpectrogramPlot(QWidget* parent = nullptr);
    void setSpectrogram(const StepSpectrogram& s, const QString& title);
    void clear(const QString& placeholder);
    /// Both plots of a comparison use the same time span (the longer step).
    void setTimeSpan(double seconds);
    const StepSpectrogram& spectrogram() const { return data_; }
    QString title() const { return title_; }
    QSize sizeHint() const override { return {320, 200}; }
    QSize minimumSizeHint() const override { return {220, 150}; }

  protected:
    void paintEvent(QPaintEvent*) override;

  private:
    StepSpectrogram data_;
    QString title_;
    double span_ = 0;
};

class BandBars : public QWidget {
    Q_OBJECT
  public:
    explicit BandBars(QWidget* parent = nullptr);
    /// Band levels re the whole band (dB) of the recorded and the synthetic steps (medians).
    void setBands(const QStringList& labels, const std::vector<double>& recorded,
                  const std::vector<double>& synthetic);
    void clear();
    QSize sizeHint() const override { return {300, 200}; }
    QSize minimumSizeHint() const override { return {220, 150}; }

  protected:
    void paintEvent(QPaintEvent*) override;

  private:
    QStringList labels_;
    std::vector<double> recorded_, synthetic_;
};

} // namespace underfoot::gui
