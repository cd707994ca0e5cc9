// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Results view: the confusion matrix of the stored answers as a heat map (updated after
/// every committed answer), the per-stimulus summary, the between-group tests, replay of any
/// trial to a WAV file, and export of every table (CSV, ratings, codebook, report in tidy CSV,
/// Markdown, HTML, LaTeX) on a worker thread with a progress bar.
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/tables/Tables.h"
#include "experiment/Store.h"

#include <QFutureWatcher>
#include <QWidget>

class QComboBox;
class QLabel;
class QTableWidget;
class QSpinBox;
class QProgressBar;
class QPushButton;
class QTabWidget;

namespace underfoot::gui {

class StudyContext;
class HeatMap;
class RatingsPlot;
class AudioOutput;

/// The analysis of a study's answered trials, simulated participants included, set up by
/// wiring::analyzeStudy as `underfoot analyze --study --include-simulated` sets it up.
analysis::AnalysisReport analyzeStudy(const experiment::StudyStore& store);

/// A rating study (no surface question) analysed by wiring::analyzeRatings as `underfoot
/// analyze --study --include-simulated` does, with the mixed models of every scale; empty
/// without ratings.
analysis::RatingStudyAnalysis analyzeRatingStudy(const experiment::StudyStore& store);

/// Writes every export of the study at `studyPath` into `folder`; `progress(done, total)` is
/// called after each file. Returns an empty string or what went wrong.
QString exportStudy(const QString& studyPath, const QString& folder,
                    const std::function<void(int, int)>& progress);

class ResultsView : public QWidget {
    Q_OBJECT
  public:
    explicit ResultsView(StudyContext& context, QWidget* parent = nullptr);

    /// Recomputes the tables from the store (called after every change).
    void refresh();
    /// Starts the export into `folder` on a worker thread; emits exportFinished.
    void startExport(const QString& folder);
    /// Starts rendering the selected trial to `wavPath` on a worker thread; emits
    /// replayFinished.
    void startReplay(const QString& participant, int trialIndex, const QString& wavPath);
    bool busy() const;
    /// Plays a stored trial through the live engine (what the participant heard, from its
    /// render seed and GRF recording or walker); returns "" or what went wrong.
    QString playLive(const QString& participant, int trialIndex);
    void setAudioOutput(AudioOutput* output) { audio_ = output; }

    HeatMap* heatMap() const { return heatMap_; }
    RatingsPlot* ratingsPlot() const { return ratings_; }
    /// The scale shown in the ratings plot.
    QComboBox* scaleBox() const { return scale_; }
    /// Saves the heat map / the ratings plot as .svg or .png; "" or what went wrong.
    QString saveHeatMap(const QString& path) const;
    QString saveRatingsPlot(const QString& path) const;
    /// Shows figure `index` (0 confusion matrix, 1 ratings per condition).
    void showFigure(int index);
    QTableWidget* summaryTable() const { return summary_; }
    QTableWidget* testsTable() const { return tests_; }
    /// The mixed models (glmer; lmer and clmm for ratings) and the nonparametric tests beside
    /// them, one row each, and the sentence on which to cite.
    QTableWidget* modelsTable() const { return models_; }
    QString modelAdvice() const;
    QComboBox* groupBox() const { return group_; }
    const analysis::AnalysisReport& report() const { return report_; }
    QString statusText() const;

  signals:
    void exportFinished(const QString& error);
    void replayFinished(const QString& error);

  private:
    void showMatrix();
    void fillModels();
    void showRatings();
    void chooseFigureFile();
    void chooseExport();
    void chooseReplay();
    void fillReplayParticipants();
    void setBusy(bool busy, const QString& what);

    StudyContext& context_;
    analysis::AnalysisReport report_;
    QComboBox* group_;
    QLabel* status_;
    HeatMap* heatMap_;
    RatingsPlot* ratings_;
    QComboBox* scale_;
    QTabWidget* figures_;
    QTableWidget* summary_;
    QTableWidget* tests_;
    QTableWidget* models_;
    QLabel* modelAdvice_;
    QComboBox* replayParticipant_;
    QSpinBox* replayTrial_;
    QPushButton* exportButton_;
    QPushButton* replayButton_;
    QProgressBar* progress_;
    QLabel* workLabel_;
    QFutureWatcher<QString>* exportWatcher_;
    QFutureWatcher<QString>* replayWatcher_;
    AudioOutput* audio_ = nullptr;
};

} // namespace underfoot::gui
