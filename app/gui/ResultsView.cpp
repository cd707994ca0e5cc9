// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/ResultsView.h"
#include "app/gui/QtText.h"

#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/Export.h"
#include "app/gui/AudioOutput.h"
#include "app/gui/Figures.h"
#include "app/gui/HeatMap.h"
#include "app/gui/RatingsPlot.h"
#include "app/gui/Replay.h"
#include "app/gui/StudyContext.h"
#include "app/wiring/StudyAnalysis.h"
#include "engine/control/GrfFile.h"
#include "experiment/Export.h"
#ifdef UNDERFOOT_HAVE_WIRING
#include "app/wiring/Players.h"
#endif

#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QMetaObject>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QShortcut>
#include <QSpinBox>
#include <QSplitter>
#include <QTabWidget>
#include <QTableWidget>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrent>

#include <cmath>
#include <fstream>

namespace underfoot::gui {

namespace exp = underfoot::experiment;
namespace an = underfoot::analysis;

namespace {
QString num(double v, int decimals = 1) {
    return std::isfinite(v) ? QString::number(v, 'f', decimals) : QString("—");
}
/// A group's label from the protocol ("footsteps alone"), the id when it has none.
QString groupLabelOf(const exp::Protocol& p, const std::string& id) {
    const exp::Group* g = p.group(id);
    return QString::fromStdString(g && !g->label.empty() ? g->label : id);
}
QString pval(double p) {
    if (!std::isfinite(p)) return "—";
    return p < 0.0001 ? QString("< 0.0001") : QString::number(p, 'g', 3);
}
} // namespace

namespace {
/// The console shows every participant, the simulated ones too (the Study view marks them, the
/// report's banner counts them); otherwise the study is analysed as `underfoot analyze
/// --study --include-simulated` does.
wiring::StudyAnalysisOverrides consoleOverrides() {
    wiring::StudyAnalysisOverrides o;
    o.includeSimulated = true;
    return o;
}
} // namespace

an::AnalysisReport analyzeStudy(const exp::StudyStore& store) {
    return wiring::analyzeStudy(store, consoleOverrides());
}

an::RatingStudyAnalysis analyzeRatingStudy(const exp::StudyStore& store) {
    const auto ratings = wiring::studyRatings(store, consoleOverrides());
    if (ratings.data.ratings.empty()) return {};
    return wiring::analyzeRatings(ratings, consoleOverrides());
}

QString exportStudy(const QString& studyPath, const QString& folder,
                    const std::function<void(int, int)>& progress) {
    try {
        if (!QDir().mkpath(folder))
            return QObject::tr("%1: cannot create the folder; choose a writable one.").arg(folder);
        const auto store = exp::StudyStore::openForReading(studyPath.toStdString());
        const QDir dir(folder);
        const int total = 7;
        int done = 0;
        const auto write = [&](const QString& name, const auto& fn) {
            const std::string path = dir.filePath(name).toStdString();
            std::ofstream out(path, std::ios::binary);
            if (!out) throw std::runtime_error(path + ": cannot open for writing");
            fn(out);
            if (!out.flush()) throw std::runtime_error(path + ": write failed (disk full?)");
            if (progress) progress(++done, total);
        };
        write("trials.csv", [&](std::ostream& o) { exp::writeTrialsCsv(store, o); });
        write("ratings.csv", [&](std::ostream& o) { exp::writeRatingsCsv(store, o); });
        write("codebook.md", [&](std::ostream& o) { exp::writeCodebook(store, o); });
        const auto report = analyzeStudy(store);
        const std::pair<const char*, an::ReportFormat> formats[] = {
            {"report.csv", an::ReportFormat::Csv},
            {"report.md", an::ReportFormat::Markdown},
            {"report.html", an::ReportFormat::Html},
            {"report.tex", an::ReportFormat::Latex}};
        for (const auto& [name, format] : formats)
            write(name, [&](std::ostream& o) { o << an::renderReport(report, format); });
    } catch (const std::exception& e) {
        return QObject::tr("%1\nThe export stopped; files written so far are complete.")
            .arg(QString::fromStdString(e.what()));
    }
    return {};
}

ResultsView::ResultsView(StudyContext& context, QWidget* parent)
    : QWidget(parent), context_(context) {
    group_ = new QComboBox(this);
    group_->setAccessibleName(tr("Group of the confusion matrix"));
    auto* groupLabel = new QLabel(tr("&Group:"), this);
    groupLabel->setBuddy(group_);
    status_ = new QLabel(this);
    status_->setAccessibleName(tr("Answers analysed"));
    exportButton_ = new QPushButton(tr("E&xport all…  (Ctrl+S)"), this);
    exportButton_->setAccessibleName(tr("Export every table"));
    exportButton_->setToolTip(tr("trials.csv, ratings.csv, codebook.md and the report as tidy "
                                 "CSV, Markdown, HTML (heat maps) and LaTeX"));
    progress_ = new QProgressBar(this);
    progress_->setAccessibleName(tr("Progress of the export or replay"));
    progress_->hide();
    workLabel_ = new QLabel(this);
    workLabel_->setWordWrap(true);
    workLabel_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    auto* top = new QHBoxLayout;
    top->addWidget(groupLabel);
    top->addWidget(group_);
    top->addWidget(status_, 1);
    top->addWidget(progress_);
    top->addWidget(exportButton_);

    heatMap_ = new HeatMap(this);
    ratings_ = new RatingsPlot(this);
    scale_ = new QComboBox(this);
    scale_->setAccessibleName(tr("Scale of the ratings plot"));
    auto* saveFigureButton = new QPushButton(tr("Save &figure… (SVG, PNG)"), this);
    saveFigureButton->setAccessibleName(tr("Save the figure shown"));
    saveFigureButton->setToolTip(
        tr("The figure on screen as SVG (vector) or PNG at %1 dpi").arg(kPrintDpi));
    auto* ratingsPage = new QWidget(this);
    auto* rp = new QVBoxLayout(ratingsPage);
    rp->setContentsMargins(0, 0, 0, 0);
    auto* scaleRow = new QHBoxLayout;
    auto* scaleLabel = new QLabel(tr("Sc&ale:"), ratingsPage);
    scaleLabel->setBuddy(scale_);
    scaleRow->addWidget(scaleLabel);
    scaleRow->addWidget(scale_, 1);
    rp->addLayout(scaleRow);
    rp->addWidget(ratings_, 1);
    figures_ = new QTabWidget(this);
    figures_->addTab(heatMap_, tr("Confusion matrix"));
    figures_->addTab(ratingsPage, tr("Ratings per condition"));
    figures_->setCornerWidget(saveFigureButton);
    connect(saveFigureButton, &QPushButton::clicked, this, &ResultsView::chooseFigureFile);
    connect(scale_, &QComboBox::currentIndexChanged, this, &ResultsView::showRatings);

    summary_ = new QTableWidget(0, 9, this);
    summary_->setHorizontalHeaderLabels({tr("Group"), tr("Surface"), tr("Soundscape"), tr("n"),
                                         tr("% correct"), tr("% wrong"), tr("% don't know"),
                                         tr("Realism (correct)"), tr("Quality (all but DK)")});
    summary_->setAccessibleName(tr("Summary per stimulus"));
    tests_ = new QTableWidget(0, 11, this);
    tests_->setHorizontalHeaderLabels({tr("Measure"), tr("Surface"), tr("Groups"), tr("Value A"),
                                       tr("Value B"), tr("Result"), tr("Test"), tr("Statistic"),
                                       tr("df"), tr("p"), tr("p (Holm)")});
    tests_->setAccessibleName(tr("Between-group tests"));
    models_ = new QTableWidget(0, 10, this);
    models_->setHorizontalHeaderLabels(
        {tr("Measure / scale"), tr("Surface"), tr("Compared"), tr("Model"), tr("Estimate (SE)"),
         tr("p (Wald)"), tr("p (LRT)"), tr("Classic p"), tr("Mann-Whitney p"), tr("Warnings")});
    models_->setAccessibleName(tr("Mixed models and which test to cite"));
    modelAdvice_ = new QLabel(this);
    modelAdvice_->setWordWrap(true);
    modelAdvice_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    modelAdvice_->setAccessibleName(tr("Which test to cite"));
    auto* modelsPage = new QWidget(this);
    auto* ml = new QVBoxLayout(modelsPage);
    ml->addWidget(modelAdvice_);
    ml->addWidget(models_, 1);
    for (auto* t : {summary_, tests_, models_}) {
        t->setEditTriggers(QAbstractItemView::NoEditTriggers);
        t->verticalHeader()->setVisible(false);
        t->horizontalHeader()->setStretchLastSection(true);
        t->setAlternatingRowColors(true);
    }

    auto* replay = new QWidget(this);
    auto* rl = new QHBoxLayout(replay);
    replayParticipant_ = new QComboBox(replay);
    replayParticipant_->setAccessibleName(tr("Participant to replay"));
    replayTrial_ = new QSpinBox(replay);
    replayTrial_->setRange(1, 9999);
    replayTrial_->setAccessibleName(tr("Trial number to replay"));
    replayButton_ = new QPushButton(tr("Render the trial to WAV…  (Ctrl+Shift+R)"), replay);
    replayButton_->setAccessibleName(tr("Replay the trial"));
    auto* pl = new QLabel(tr("P&articipant:"), replay);
    pl->setBuddy(replayParticipant_);
    auto* tl = new QLabel(tr("T&rial:"), replay);
    tl->setBuddy(replayTrial_);
    rl->addWidget(pl);
    rl->addWidget(replayParticipant_);
    rl->addWidget(tl);
    rl->addWidget(replayTrial_);
    rl->addWidget(replayButton_);
    auto* live = new QPushButton(tr("Play through the live engine  (Ctrl+Shift+P)"), replay);
    live->setAccessibleName(tr("Play the trial through the live engine"));
    rl->addWidget(live);
    rl->addStretch();
    const auto playSelected = [this] {
        if (replayParticipant_->currentText().isEmpty()) {
            workLabel_->setText(tr("Choose a participant and a trial in the Replay tab first."));
            return;
        }
        const QString e = playLive(replayParticipant_->currentText(), replayTrial_->value() - 1);
        if (!e.isEmpty()) workLabel_->setText(e);
    };
    connect(live, &QPushButton::clicked, this, playSelected);
    auto* scLive = new QShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_P), this);
    scLive->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scLive, &QShortcut::activated, this, playSelected);

    auto* lower = new QTabWidget(this);
    lower->addTab(summary_, tr("Summary"));
    lower->addTab(tests_, tr("Between-group tests"));
    lower->addTab(modelsPage, tr("Models (which to cite)"));
    lower->addTab(replay, tr("Replay"));

    auto* split = new QSplitter(Qt::Vertical, this);
    split->addWidget(figures_);
    split->addWidget(lower);
    split->setStretchFactor(0, 3);
    split->setStretchFactor(1, 2);

    auto* layout = new QVBoxLayout(this);
    layout->addLayout(top);
    layout->addWidget(split, 1);
    layout->addWidget(workLabel_);

    exportWatcher_ = new QFutureWatcher<QString>(this);
    replayWatcher_ = new QFutureWatcher<QString>(this);
    connect(exportWatcher_, &QFutureWatcher<QString>::finished, this, [this] {
        const QString error = exportWatcher_->result();
        setBusy(false, error.isEmpty() ? tr("Export finished.") : error);
        emit exportFinished(error);
    });
    connect(replayWatcher_, &QFutureWatcher<QString>::finished, this, [this] {
        const QString text = replayWatcher_->result();
        const bool ok = text.startsWith("ok:");
        setBusy(false, ok ? text.mid(3) : text);
        emit replayFinished(ok ? QString() : text);
    });
    connect(group_, &QComboBox::currentIndexChanged, this, &ResultsView::showMatrix);
    connect(exportButton_, &QPushButton::clicked, this, &ResultsView::chooseExport);
    connect(replayButton_, &QPushButton::clicked, this, &ResultsView::chooseReplay);
    auto* scExport = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_S), this);
    scExport->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scExport, &QShortcut::activated, this, &ResultsView::chooseExport);
    auto* scReplay = new QShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_R), this);
    scReplay->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scReplay, &QShortcut::activated, this, &ResultsView::chooseReplay);
    connect(&context_, &StudyContext::dataChanged, this, &ResultsView::refresh);
    refresh();
}

QString ResultsView::modelAdvice() const {
    return modelAdvice_->text();
}

QString ResultsView::statusText() const {
    return status_->text();
}

bool ResultsView::busy() const {
    return exportWatcher_->isRunning() || replayWatcher_->isRunning();
}

void ResultsView::refresh() {
    report_ = {};
    summary_->setRowCount(0);
    tests_->setRowCount(0);
    models_->setRowCount(0);
    modelAdvice_->clear();
    const QString previous = group_->currentText();
    group_->blockSignals(true);
    group_->clear();
    if (!context_.hasStudy()) {
        group_->blockSignals(false);
        status_->setText(tr("No study open."));
        heatMap_->setMatrix({});
        fillReplayParticipants();
        return;
    }
    try {
        report_ = analyzeStudy(context_.store());
    } catch (const std::exception& e) {
        group_->blockSignals(false);
        status_->setText(tr("The analysis failed: %1").arg(q(e.what())));
        heatMap_->setMatrix({});
        return;
    }
    for (const auto& c : report_.confusions)
        group_->addItem(groupLabelOf(context_.store().protocol(), c.group), q(c.group));
    const int again = group_->findText(previous);
    group_->setCurrentIndex(again >= 0 ? again : 0);
    group_->blockSignals(false);
    double n = 0;
    for (const auto& s : report_.summary) n += s.n;
    status_->setText(
        (n == 1 ? tr("1 answered trial analysed") : tr("%1 answered trials analysed").arg(n)) +
        tr(" (practice and excluded trials left out)"));
    const auto groupLabel = [this](const std::string& id) {
        return groupLabelOf(context_.store().protocol(), id);
    };
    summary_->setRowCount(static_cast<int>(report_.summary.size()));
    for (std::size_t i = 0; i < report_.summary.size(); ++i) {
        const auto& s = report_.summary[i];
        const QStringList cells = {
            groupLabel(s.group),
            surfaceLabel(s.stimulus.surfaceId),
            s.stimulus.soundscapeId.empty() ? QString() : soundscapeLabel(s.stimulus.soundscapeId),
            QString::number(s.n),
            num(s.correct.percent),
            num(s.wrong.percent),
            num(s.dontKnow.percent),
            num(s.realism.mean, 2),
            num(s.quality.mean, 2)};
        for (int c = 0; c < cells.size(); ++c)
            summary_->setItem(static_cast<int>(i), c, new QTableWidgetItem(cells[c]));
    }
    summary_->resizeColumnsToContents();
    tests_->setRowCount(static_cast<int>(report_.comparisons.size()));
    for (std::size_t i = 0; i < report_.comparisons.size(); ++i) {
        const auto& c = report_.comparisons[i];
        QString df;
        for (double d : c.test.df) df += (df.isEmpty() ? "" : ", ") + num(d, 2);
        const QStringList cells = {q(an::measureName(c.measure)),
                                   c.surfaceId.empty() ? tr("(all)") : surfaceLabel(c.surfaceId),
                                   groupLabel(c.groupA) + " vs " + groupLabel(c.groupB),
                                   num(c.valueA, 2),
                                   num(c.valueB, 2),
                                   testInWords(c.test),
                                   c.test.ok() ? q(c.test.method) : q(c.test.error),
                                   num(c.test.statistic, 3),
                                   df,
                                   pval(c.test.p),
                                   pval(c.pHolm)};
        for (int col = 0; col < cells.size(); ++col)
            tests_->setItem(static_cast<int>(i), col, new QTableWidgetItem(cells[col]));
    }
    tests_->resizeColumnsToContents();
    fillModels();
    showMatrix();
    const QString previousScale = scale_->currentData().toString();
    scale_->blockSignals(true);
    scale_->clear();
    for (const auto& sc : context_.store().protocol().questions.scales)
        scale_->addItem(q(sc.prompt), q(sc.id));
    const int scaleAgain = scale_->findData(previousScale);
    scale_->setCurrentIndex(scaleAgain >= 0 ? scaleAgain : 0);
    scale_->blockSignals(false);
    showRatings();
    fillReplayParticipants();
}

void ResultsView::fillModels() {
    const auto warningsText = [](const std::vector<std::string>& warnings) {
        QStringList w;
        for (const auto& x : warnings) w << q(x.substr(0, x.find('\n')));
        return w.join("; ");
    };
    const auto addRow = [this](const QStringList& cells) {
        const int r = models_->rowCount();
        models_->insertRow(r);
        for (int c = 0; c < cells.size(); ++c)
            models_->setItem(r, c, new QTableWidgetItem(cells[c]));
    };
    const auto groupLabel = [this](const std::string& id) {
        return groupLabelOf(context_.store().protocol(), id);
    };
    for (const auto& m : report_.mixedModels)
        addRow({q(an::measureName(m.measure)),
                m.surfaceId.empty() ? tr("(all)") : surfaceLabel(m.surfaceId),
                groupLabel(m.groupA) + " vs " + groupLabel(m.groupB), q(m.model),
                m.error.empty() ? num(m.estimate, 3) + " (" + num(m.se, 3) + ")" : q(m.error),
                pval(m.p), pval(m.lrtP), pval(m.classicP), pval(m.nonparametricP),
                warningsText(m.warnings)});
    QStringList advice;
    if (!report_.mixedModelAdvice.empty()) advice << q(report_.mixedModelAdvice);
    if (!context_.store().protocol().questions.asksSurface()) {
        an::RatingStudyAnalysis ratings;
        try {
            ratings = analyzeRatingStudy(context_.store());
        } catch (const std::exception& e) {
            advice << q(e.what());
        }
        for (const auto& s : ratings.scales) {
            if (!s.models.fitted) continue;
            const QString scale = q(s.scale.id);
            addRow({scale, tr("(all)"), tr("stimuli"),
                    s.omnibus.conditions.size() >= 3 ? tr("Friedman (cell means)")
                                                     : tr("Wilcoxon signed-rank (cell means)"),
                    "", "", pval(s.omnibus.result.p), "", "", q(s.omnibus.result.error)});
            const auto model = [&](const QString& name, const an::MixedModelResult& r) {
                addRow({scale, tr("(all)"), tr("stimuli"), name, r.ok() ? QString() : q(r.error),
                        "", pval(r.lrt.p), "", "", warningsText(r.warnings)});
            };
            model(tr("lmer (REML; LRT by ML)"), s.models.lmm);
            if (s.models.clmmSkipped.empty())
                model(tr("clmm (Laplace, logit)"), s.models.clmm);
            else
                addRow({scale, tr("(all)"), tr("stimuli"), tr("clmm"), "", "", "", "", "",
                        q(s.models.clmmSkipped)});
            advice << scale + ": " + q(s.models.advice);
        }
    }
    modelAdvice_->setText(advice.join("\n"));
    models_->resizeColumnsToContents();
}

void ResultsView::showMatrix() {
    const int i = group_->currentIndex();
    if (i < 0 || i >= static_cast<int>(report_.confusions.size())) {
        heatMap_->setMatrix({});
        return;
    }
    heatMap_->setMatrix(report_.confusions[static_cast<std::size_t>(i)]);
}

void ResultsView::showRatings() {
    if (!context_.hasStudy() || scale_->currentIndex() < 0) {
        ratings_->setSeries({});
        return;
    }
    try {
        ratings_->setSeries(
            ratingSeries(context_.store(), scale_->currentData().toString().toStdString()));
    } catch (const std::exception& e) {
        ratings_->setSeries({});
        workLabel_->setText(q(e.what()));
    }
}

void ResultsView::showFigure(int index) {
    figures_->setCurrentIndex(index);
}

QString ResultsView::saveHeatMap(const QString& path) const {
    return heatMap_->save(path);
}

QString ResultsView::saveRatingsPlot(const QString& path) const {
    return ratings_->save(path);
}

void ResultsView::chooseFigureFile() {
    if (!context_.hasStudy()) return;
    const bool matrix = figures_->currentIndex() == 0;
    const QString suggested =
        QFileInfo(context_.path())
            .dir()
            .filePath(matrix ? QString("confusion_%1.svg").arg(group_->currentText())
                             : QString("ratings_%1.svg").arg(scale_->currentData().toString()));
    const QString file = QFileDialog::getSaveFileName(
        this, tr("Save figure"), suggested, tr("SVG (*.svg);;PNG, %1 dpi (*.png)").arg(kPrintDpi));
    if (file.isEmpty()) return;
    const QString error = matrix ? saveHeatMap(file) : saveRatingsPlot(file);
    workLabel_->setText(
        error.isEmpty() ? tr("Figure written to %1.").arg(QDir::toNativeSeparators(file)) : error);
}

void ResultsView::fillReplayParticipants() {
    const QString previous = replayParticipant_->currentText();
    replayParticipant_->clear();
    if (!context_.hasStudy()) return;
    for (const auto& p : context_.store().participants()) replayParticipant_->addItem(q(p.code));
    const int again = replayParticipant_->findText(previous);
    if (again >= 0) replayParticipant_->setCurrentIndex(again);
}

void ResultsView::setBusy(bool busy, const QString& what) {
    exportButton_->setEnabled(!busy);
    replayButton_->setEnabled(!busy);
    progress_->setVisible(busy);
    workLabel_->setText(what);
}

void ResultsView::startExport(const QString& folder) {
    if (!context_.hasStudy() || busy()) return;
    setBusy(true, tr("Exporting to %1…").arg(QDir::toNativeSeparators(folder)));
    progress_->setRange(0, 7);
    progress_->setValue(0);
    QPointer<QProgressBar> bar = progress_;
    const QString study = context_.path();
    exportWatcher_->setFuture(QtConcurrent::run([study, folder, bar] {
        return exportStudy(study, folder, [bar](int done, int total) {
            QMetaObject::invokeMethod(
                bar,
                [bar, done, total] {
                    if (!bar) return;
                    bar->setRange(0, total);
                    bar->setValue(done);
                },
                Qt::QueuedConnection);
        });
    }));
}

void ResultsView::chooseExport() {
    if (!context_.hasStudy()) return;
    const QString folder = QFileDialog::getExistingDirectory(
        this, tr("Export into folder"), QFileInfo(context_.path()).dir().path());
    if (!folder.isEmpty()) startExport(folder);
}

void ResultsView::startReplay(const QString& participant, int trialIndex, const QString& wavPath) {
    if (!context_.hasStudy() || busy()) return;
    setBusy(true, tr("Rendering trial %1 of %2…").arg(trialIndex + 1).arg(participant));
    progress_->setRange(0, 0); // busy indicator: the render reports no steps
    const QString study = context_.path();
    replayWatcher_->setFuture(QtConcurrent::run([study, participant, trialIndex, wavPath] {
        const ReplayResult r = renderTrial(study, participant, trialIndex, wavPath);
        if (!r.error.isEmpty()) return r.error;
        return QString("ok:") + QObject::tr("%1 — %2 s written to %3")
                                    .arg(r.description)
                                    .arg(r.seconds, 0, 'f', 1)
                                    .arg(QDir::toNativeSeparators(wavPath));
    }));
}

QString ResultsView::playLive(const QString& participant, int trialIndex) {
#ifdef UNDERFOOT_HAVE_WIRING
    if (!context_.hasStudy()) return tr("No study open.");
    if (!audio_) return tr("No audio output.");
    try {
        const auto info = context_.store().trialForReplay(participant.toStdString(), trialIndex);
        auto d = wiring::describeStimulus(info.stimulus, info.renderSeed);
        if (info.grfRecording) {
            QString path = QString::fromStdString(*info.grfRecording);
            if (QFileInfo(path).isRelative())
                path = QFileInfo(context_.path()).dir().filePath(path);
            d.control = engine::ControlKind::GrfReplay;
            engine::GrfLoadOptions options;
            options.targetRateHz = audio_->settings().sampleRateHz;
            d.grf = engine::loadGrfFile(path.toStdString(), options);
        } else if (info.stimulus.input.kind != experiment::InputKind::Walker) {
            return tr("Trial %1 of %2 was driven by a live sensor and no GRF recording is "
                      "stored for it: it cannot be replayed exactly.")
                .arg(trialIndex + 1)
                .arg(participant);
        }
        if (const QString e = audio_->start(); !e.isEmpty()) return e;
        auto scene = engine::LiveScene::create(std::move(d), audio_->engine()->processSpec(),
                                               audio_->engine()->settings().channels);
        if (!audio_->engine()->submit(std::move(scene)))
            return tr("The audio engine is busy; try again in a moment.");
    } catch (const std::exception& e) {
        return q(e.what());
    }
    workLabel_->setText(tr("Playing trial %1 of %2 through %3; stop it in the Setup view.")
                            .arg(trialIndex + 1)
                            .arg(participant, audio_->description()));
    return {};
#else
    (void)participant;
    (void)trialIndex;
    return tr("This build has no live audio wiring; render the trial to WAV instead.");
#endif
}

void ResultsView::chooseReplay() {
    if (!context_.hasStudy() || replayParticipant_->currentText().isEmpty()) {
        workLabel_->setText(tr("Choose a participant and a trial in the Replay tab first."));
        return;
    }
    const QString code = replayParticipant_->currentText();
    const int trial = replayTrial_->value();
    const QString suggested =
        QFileInfo(context_.path()).dir().filePath(QString("%1_trial%2.wav").arg(code).arg(trial));
    const QString file =
        QFileDialog::getSaveFileName(this, tr("Render trial to"), suggested, tr("WAV (*.wav)"));
    if (!file.isEmpty()) startReplay(code, trial - 1, file);
}

} // namespace underfoot::gui
