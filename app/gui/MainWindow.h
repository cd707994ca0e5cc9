// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The console's main window: one tab per view (Study, Run, Results, Sound palette, Setup),
/// reachable with Ctrl+1..5 and Alt+underlined letter.
#include <QMainWindow>
#include <QString>

class QTabWidget;
class QLabel;

namespace underfoot::gui {

class StudyContext;
class StudyView;
class RunView;
class ResultsView;
class PaletteView;
class SetupView;
class AudioOutput;

class MainWindow : public QMainWindow {
    Q_OBJECT
  public:
    struct Options {
        /// Study to open; empty: the last study opened, else the demo study.
        QString studyPath;
        /// User data folder (demo study, saved presets); empty: the platform's default.
        QString dataDir;
        /// Create the demo study when no study is given (off in tests that bring their own).
        bool createDemo = true;
        /// Start the live audio output when a session starts (so trials are heard); off in
        /// tests and screenshots.
        bool startAudio = true;
    };
    explicit MainWindow(const Options& options, QWidget* parent = nullptr);
    ~MainWindow() override;

    StudyContext& context() { return *context_; }
    StudyView* studyView() const { return study_; }
    RunView* runView() const { return run_; }
    ResultsView* resultsView() const { return results_; }
    PaletteView* paletteView() const { return palette_; }
    SetupView* setupView() const { return setup_; }
    QTabWidget* tabs() const { return tabs_; }
    /// Shows the view at `index` (0 Study, 1 Run, 2 Results, 3 Sound palette, 4 Setup).
    void showView(int index);
    /// The data folder in use.
    const QString& dataDir() const { return dataDir_; }

    /// Renders each main view (and the Run view's trial page on a scratch copy of the study)
    /// into `dir` as PNG; returns the number of views that could not be saved.
    int saveScreenshots(const QString& dir);

  protected:
    void closeEvent(QCloseEvent* event) override;

  private:
    void updateTitle();
    StudyContext* context_ = nullptr;
    QTabWidget* tabs_ = nullptr;
    StudyView* study_ = nullptr;
    RunView* run_ = nullptr;
    ResultsView* results_ = nullptr;
    PaletteView* palette_ = nullptr;
    SetupView* setup_ = nullptr;
    AudioOutput* audio_ = nullptr;
    QLabel* studyLabel_ = nullptr;
    QString dataDir_;
};

} // namespace underfoot::gui
