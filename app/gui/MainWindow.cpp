// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/MainWindow.h"

#include "app/gui/AudioOutput.h"
#include "app/gui/DemoStudy.h"
#include "app/gui/PaletteView.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/ResultsView.h"
#include "app/gui/RunView.h"
#include "app/gui/SetupView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/StudyView.h"

#include <QApplication>
#include <QCloseEvent>
#include <QDir>
#include <QFile>
#include <QLabel>
#include <QMessageBox>
#include <QSettings>
#include <QShortcut>
#include <QStatusBar>
#include <QTabWidget>
#include <QTemporaryDir>

namespace underfoot::gui {

MainWindow::MainWindow(const Options& options, QWidget* parent) : QMainWindow(parent) {
    dataDir_ = userDataDir(options.dataDir);
    context_ = new StudyContext(this);
    tabs_ = new QTabWidget(this);
    tabs_->setDocumentMode(true);
    study_ = new StudyView(*context_, this);
    run_ = new RunView(*context_, this);
    results_ = new ResultsView(*context_, this);
    audio_ = new AudioOutput(QDir(dataDir_).filePath("audio.toml"), this);
    palette_ = new PaletteView(dataDir_, this);
    palette_->setAudioOutput(audio_);
    run_->setAudioOutput(audio_, options.startAudio);
    results_->setAudioOutput(audio_);
    setup_ = new SetupView(*audio_, dataDir_, this);
    run_->setSensorProvider([this] {
        return LiveSensors{setup_->connectedShoes(), setup_->gyroReceiver(),
                           setup_->thresholdsDir()};
    });
    tabs_->addTab(study_, tr("&Study"));
    tabs_->addTab(run_, tr("&Run"));
    tabs_->addTab(results_, tr("R&esults"));
    tabs_->addTab(palette_, tr("Sound &palette"));
    tabs_->addTab(setup_, tr("Se&tup"));
    const char* tips[] = {"Create or open a study; participants, groups, progress, exclusions "
                          "(Ctrl+1)",
                          "Register a participant and run the trials (Ctrl+2)",
                          "Confusion matrix, summary, between-group tests, replay, export "
                          "(Ctrl+3)",
                          "Surfaces and their physical parameters; CPU cost; save presets "
                          "(Ctrl+4)",
                          "Audio output, sensors and step-threshold calibration (Ctrl+5)"};
    for (int i = 0; i < tabs_->count(); ++i) {
        tabs_->setTabToolTip(i, tr(tips[i]));
        auto* sc =
            new QShortcut(QKeySequence(Qt::CTRL | static_cast<Qt::Key>(Qt::Key_1 + i)), this);
        connect(sc, &QShortcut::activated, this, [this, i] { showView(i); });
    }
    setCentralWidget(tabs_);
    studyLabel_ = new QLabel(this);
    studyLabel_->setAccessibleName(tr("Open study"));
    statusBar()->addPermanentWidget(studyLabel_, 1);
    connect(context_, &StudyContext::studyChanged, this, &MainWindow::updateTitle);
    connect(study_, &StudyView::runRequested, this, [this] { showView(1); });
    connect(context_, &StudyContext::sessionActiveChanged, this, [this](bool active) {
        // While a participant is being run the study cannot be switched under the session.
        study_->setStudySwitchingEnabled(!active);
    });
    setMinimumSize(1024, 700);
    resize(1280, 800);

    QString path = options.studyPath;
    if (path.isEmpty()) {
        const QString last = QSettings().value("lastStudy").toString();
        if (!last.isEmpty() && QFile::exists(last)) path = last;
    }
    if (path.isEmpty() && options.createDemo) {
        const QString error = ensureDemoStudy(dataDir_);
        if (error.isEmpty())
            path = demoStudyPath(dataDir_);
        else
            statusBar()->showMessage(error);
    }
    if (!path.isEmpty()) {
        const QString error = context_->openStudy(path);
        if (!error.isEmpty()) statusBar()->showMessage(error);
    }
    updateTitle();
    // Reopening a study with an interrupted session offers to resume it.
    if (context_->hasStudy() && run_->hasResumable()) showView(1);
}

MainWindow::~MainWindow() {
    // The views use the study context: end the session and delete them while it exists.
    run_->closeSession();
    delete tabs_;
}

void MainWindow::showView(int index) {
    tabs_->setCurrentIndex(index);
    if (QWidget* w = tabs_->currentWidget()) w->setFocus();
}

void MainWindow::updateTitle() {
    if (context_->hasStudy()) {
        const auto info = context_->store().info();
        setWindowTitle(tr("Underfoot — %1 (%2)")
                           .arg(QString::fromStdString(context_->store().protocol().title),
                                QDir::toNativeSeparators(context_->path())));
        studyLabel_->setText(
            tr("Study %1 · protocol %2 v%3 · %4")
                .arg(QString::fromStdString(info.code), QString::fromStdString(info.protocolId))
                .arg(info.protocolVersion)
                .arg(QDir::toNativeSeparators(context_->path())));
        QSettings().setValue("lastStudy", context_->path());
    } else {
        setWindowTitle(tr("Underfoot — no study open"));
        studyLabel_->setText(tr("No study open: create or open one in the Study view (Ctrl+1)."));
    }
}

void MainWindow::closeEvent(QCloseEvent* event) {
    // Every answer is already committed; closing only ends the session as interrupted so that
    // reopening offers to resume it.
    run_->closeSession();
    run_->closeParticipantWindow();
    event->accept();
}

int MainWindow::saveScreenshots(const QString& dir) {
    QDir().mkpath(dir);
    int failures = 0;
    const auto shoot = [&](const QString& name) {
        QApplication::processEvents();
        QApplication::processEvents();
        if (!grab().save(QDir(dir).filePath(name))) ++failures;
    };
    showView(0);
    shoot("01_study.png");
    showView(1);
    shoot("02_run_register.png");
    // A trial in progress, on a scratch copy of the open study (the real one stays untouched).
    QTemporaryDir scratch;
    const QString original = context_->path();
    if (context_->hasStudy() && scratch.isValid()) {
        const QString copy = scratch.filePath("screenshot_study.db");
        if (QFile::copy(context_->path(), copy) && context_->openStudy(copy).isEmpty() &&
            run_->startDemoTrialForScreenshot()) {
            shoot("03_run_trial.png");
            // The participant's screen of the same trial (only what the participant may see).
            if (auto* pw = run_->openParticipantWindow()) {
                pw->resize(1280, 800);
                QApplication::processEvents();
                QApplication::processEvents();
                if (!pw->grab().save(QDir(dir).filePath("09_participant_window.png"))) ++failures;
                run_->closeParticipantWindow();
            }
            run_->closeSession();
        } else {
            ++failures;
        }
        context_->openStudy(original);
    }
    // A listening test and a lap protocol (shipped wading protocols) on scratch studies.
    if (scratch.isValid()) {
        const QString dirOfProtocols = QString::fromStdString(experiment::shippedProtocolDir());
        const std::pair<const char*, int> cases[] = {{"wading_listening", 0},
                                                     {"wading_interactive", 4}};
        for (const auto& [id, laps] : cases) {
            experiment::StudySettings settings;
            settings.code = "SCREENSHOT";
            const QString file = scratch.filePath(QString("%1.db").arg(id));
            const bool created =
                context_->createStudy(file, dirOfProtocols + "/" + id + ".toml", settings)
                    .isEmpty();
            showView(1);
            if (created && run_->startProtocolTrialForScreenshot(laps)) {
                shoot(laps ? "08_run_laps.png" : "07_run_listening.png");
                run_->closeSession();
            } else {
                ++failures;
            }
        }
        if (!original.isEmpty()) context_->openStudy(original);
    }
    showView(2);
    results_->showFigure(0);
    shoot("04_results.png");
    results_->showFigure(1);
    shoot("10_results_ratings.png");
    results_->showFigure(0);
    showView(3);
    shoot("05_sound_palette.png");
    showView(4);
    shoot("06_setup.png");
    return failures;
}

} // namespace underfoot::gui
