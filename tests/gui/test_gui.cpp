// SPDX-License-Identifier: GPL-3.0-or-later
// The console driven through its widgets on Qt's offscreen platform: a complete session answered
// from the keyboard and checked in the study file, closing mid-session and resuming, the results
// view against the stored answers, protocol errors with file:line:column, and the sound palette.
#include "app/gui/DemoStudy.h"
#include "app/gui/HeatMap.h"
#include "app/gui/MainWindow.h"
#include "app/gui/PaletteView.h"
#include "app/gui/ResultsView.h"
#include "app/gui/RunView.h"
#include "app/gui/SetupView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/StudyView.h"
#include "engine/surfaces/Surface.h"
#include "experiment/Catalogue.h"
#include "experiment/Store.h"

#include <QComboBox>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTabWidget>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <map>
#include <memory>

using namespace underfoot;
namespace ue = underfoot::experiment;

namespace {

QPushButton* button(QWidget* root, const QString& accessibleName) {
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == accessibleName && b->isVisible()) return b;
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == accessibleName) return b;
    return nullptr;
}

/// What the test typed for one trial.
struct Typed {
    std::string answer, soundscape;
    std::map<std::string, int> ratings;
};

/// Answers the current trial from the keyboard: Space, the letter of the surface walked on,
/// digits for every scale (values cycling with the trial index), the soundscape letter when
/// asked, Enter. Returns what was typed.
Typed answerByKeyboard(gui::RunView& run, const ue::Protocol& p, int trialIndex) {
    QWidget* panel = run.trialPanel();
    const ue::TrialRecord& t = run.session()->current();
    Typed typed;
    QTest::keyClick(panel, Qt::Key_Space);
    if (p.questions.asksSurface()) {
        const std::string walked = ue::baseSurface(t.stimulus.surface);
        const ue::AnswerOption* o = p.questions.surfaceOption(walked);
        // Every third trial "I don't know", to exercise the whole answer list.
        if (trialIndex % 3 == 2 || !o) o = p.questions.surfaceOption(std::string(ue::kDontKnow));
        typed.answer = o->id;
        QTest::keyClick(panel, o->letter);
    }
    for (std::size_t s = 0; s < p.questions.scales.size(); ++s) {
        const auto& sc = p.questions.scales[s];
        const int span = sc.max - sc.min + 1;
        const int value = sc.min + (trialIndex + static_cast<int>(s)) % span;
        typed.ratings[sc.id] = value;
        if (value >= 10) {
            QTest::keyClick(panel, '1');
            QTest::keyClick(panel, '0');
        } else {
            QTest::keyClick(panel, static_cast<char>('0' + value));
        }
    }
    if (p.questions.asksSoundscape(run.session()->participant().groupId)) {
        const auto& options = p.questions.soundscapeOptions;
        const auto& o = options[static_cast<std::size_t>(trialIndex) % options.size()];
        typed.soundscape = o.id;
        QTest::keyClick(panel, o.letter);
    }
    QTest::keyClick(panel, Qt::Key_Return);
    return typed;
}

} // namespace

class GuiTest : public QObject {
    Q_OBJECT
  private:
    QTemporaryDir home_;
    std::unique_ptr<gui::MainWindow> makeWindow(const QString& study = {}) {
        gui::MainWindow::Options o;
        o.studyPath = study;
        o.dataDir = home_.filePath("data");
        o.createDemo = false;
        o.startAudio = false;
        auto w = std::make_unique<gui::MainWindow>(o);
        w->show();
        return w;
    }
    bool createStudy(gui::MainWindow& w, const QString& protocol, const QString& file) {
        w.showView(0);
        w.studyView()->protocolBox()->setCurrentText(protocol);
        w.studyView()->fileEdit()->setText(file);
        QTest::mouseClick(button(w.studyView(), "Create study"), Qt::LeftButton);
        return w.context().hasStudy() && w.context().path() == file;
    }
    void registerParticipant(gui::MainWindow& w, const QString& code) {
        w.showView(1);
        auto* run = w.runView();
        QTest::keyClicks(run->codeEdit(), code);
        run->ageBox()->setValue(31);
        run->genderBox()->setCurrentText("female");
        QTest::mouseClick(button(run, "Register and start"), Qt::LeftButton);
    }

  private slots:
    void initTestCase() {
        QVERIFY(home_.isValid());
        // Keep the user's settings (last study) out of the tests.
        qputenv("XDG_CONFIG_HOME", home_.filePath("config").toUtf8());
        qputenv("XDG_DATA_HOME", home_.filePath("share").toUtf8());
        QCoreApplication::setApplicationName("underfoot-gui-test");
    }

    void completeSessionByKeyboardIsStoredAndExported() {
        const QString file = home_.filePath("exp2.db");
        auto w = makeWindow();
        QVERIFY(
            createStudy(*w, QString(UNDERFOOT_SOURCE_DIR) + "/protocols/tvcg2011_exp2.toml", file));
        registerParticipant(*w, "P001");
        auto* run = w->runView();
        QVERIFY(run->session());
        QCOMPARE(run->pageName(), QString("briefing"));
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        const ue::Protocol protocol = w->context().store().protocol();
        std::map<int, Typed> typed;
        std::vector<double> commitMs;
        QElapsedTimer clock;
        clock.start();
        int guard = 0;
        while (run->pageName() != "finished" && guard++ < 100) {
            if (run->pageName() == "break") {
                QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                continue;
            }
            QCOMPARE(run->pageName(), QString("trial"));
            const int index = run->session()->current().index;
            typed[index] = answerByKeyboard(*run, protocol, index);
            QVERIFY2(run->trialMessage().isEmpty() || run->trialMessage().startsWith("Answer "),
                     qPrintable(run->trialMessage()));
            commitMs.push_back(run->lastCommitMs());
        }
        QCOMPARE(run->pageName(), QString("finished"));
        std::sort(commitMs.begin(), commitMs.end());
        qInfo("%zu trials answered by keyboard in %lld ms; commit through the UI: median %.2f "
              "ms, max %.2f ms",
              commitMs.size(), static_cast<long long>(clock.elapsed()),
              commitMs[commitMs.size() / 2], commitMs.back());

        // The results view shows the confusion matrix of exactly these answers.
        w->showView(2);
        auto* results = w->resultsView();
        const std::string group = w->context().store().participant("P001").groupId;
        results->groupBox()->setCurrentIndex(
            results->groupBox()->findData(QString::fromStdString(group)));
        const auto& m = results->heatMap()->matrix();
        QCOMPARE(QString::fromStdString(m.group), QString::fromStdString(group));
        QCOMPARE(results->heatMap()->total(), static_cast<double>(typed.size()));
        const auto trials = w->context().store().trials("P001");
        for (std::size_t r = 0; r < m.rows.size(); ++r)
            for (std::size_t c = 0; c < m.columns.options.size(); ++c) {
                double expected = 0;
                for (const auto& t : trials)
                    if (t.stimulus.surface == m.rows[r].surfaceId &&
                        t.stimulus.soundscape.value_or("") == m.rows[r].soundscapeId &&
                        typed[t.index].answer == m.columns.options[c].id)
                        ++expected;
                QCOMPARE(m.counts[r][c], expected);
            }

        // Export through the view (worker thread, progress bar).
        const QString folder = home_.filePath("export");
        QSignalSpy done(results, &gui::ResultsView::exportFinished);
        results->startExport(folder);
        QVERIFY(results->busy());
        QVERIFY(done.wait(60000));
        QCOMPARE(done.front().front().toString(), QString());
        for (const char* f : {"trials.csv", "ratings.csv", "codebook.md", "report.csv", "report.md",
                              "report.html", "report.tex"})
            QVERIFY2(QFile::exists(folder + "/" + f), f);
        QFile csv(folder + "/trials.csv");
        QVERIFY(csv.open(QIODevice::ReadOnly));
        QCOMPARE(csv.readAll().count('\n'), static_cast<qsizetype>(typed.size() + 1));
        w.reset();

        // Every answer is in the study file, as typed.
        const auto store = ue::StudyStore::open(file.toStdString());
        QCOMPARE(store.participant("P001").status, ue::ParticipantStatus::Completed);
        QCOMPARE(store.participant("P001").age.value_or(0), 31);
        const auto stored = store.trials("P001");
        QCOMPARE(stored.size(), typed.size());
        for (const auto& t : stored) {
            QVERIFY(t.answered);
            const Typed& k = typed.at(t.index);
            QCOMPARE(t.answer.answer, k.answer);
            QCOMPARE(t.answer.soundscapeAnswer, k.soundscape);
            QVERIFY(t.answer.ratings == k.ratings);
            QVERIFY(t.renderSeed.has_value());
        }
    }

    void practiceBreaksTwoDigitScalesAndLockOnAnswer() {
        const QString protocolFile = home_.filePath("small.toml");
        QFile f(protocolFile);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write(R"([protocol]
id = "gui_small"
version = 1
title = "GUI test: practice, breaks, 0-10 scale"
[design]
type = "within"
[input]
type = "walker"
walker = { cadence = 110.0 }
[[stimuli]]
id = "WD"
surface = "wood"
[[stimuli]]
id = "GL"
surface = "gravel"
[[stimuli]]
id = "MT"
surface = "metal"
[ordering]
repetitions = 2
order = "random"
practice = ["WD"]
break_every = 2
[questions]
comment = true
[questions.surface]
prompt = "Which surface?"
options = ["wood", "gravel", "metal"]
dont_know = true
[[questions.scales]]
id = "loudness"
prompt = "How loud?"
min = 0
max = 10
[rules]
lock = "answer"
)");
        f.close();
        const QString file = home_.filePath("small.db");
        auto w = makeWindow();
        QVERIFY(createStudy(*w, protocolFile, file));
        registerParticipant(*w, "Q1");
        auto* run = w->runView();
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QVERIFY(run->session()->current().practice);
        const ue::Protocol protocol = w->context().store().protocol();
        // Next before the stimulus started is refused with what to do.
        QTest::keyClick(run->trialPanel(), Qt::Key_Return);
        QVERIFY(run->trialMessage().contains("Space"));
        // An incomplete answer is refused and stays current.
        QTest::keyClick(run->trialPanel(), Qt::Key_Space);
        QTest::keyClick(run->trialPanel(), 'a');
        QTest::keyClick(run->trialPanel(), Qt::Key_Return);
        QVERIFY2(run->trialMessage().startsWith("Not stored yet"), qPrintable(run->trialMessage()));
        QCOMPARE(run->session()->current().index, 0);
        // lock = "answer": no change of a committed answer is offered.
        QVERIFY(!run->revisePrevious());
        // Typed "1" then "0" is 10 on a 0-10 scale.
        QTest::keyClick(run->trialPanel(), '1');
        QTest::keyClick(run->trialPanel(), '0');
        QTest::keyClick(run->trialPanel(), Qt::Key_Return);
        int breaks = 0, guard = 0;
        std::map<int, Typed> typed;
        while (run->pageName() != "finished" && guard++ < 50) {
            if (run->pageName() == "break") {
                ++breaks;
                QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                continue;
            }
            const int index = run->session()->current().index;
            if (index == 3) QVERIFY(run->excludeTrial("participant stopped walking"));
            typed[index] = answerByKeyboard(*run, protocol, index);
        }
        QCOMPARE(run->pageName(), QString("finished"));
        QCOMPARE(breaks, 2); // after main trials 2 and 4 of 6
        w.reset();
        auto store = ue::StudyStore::open(file.toStdString());
        const auto stored = store.trials("Q1");
        QCOMPARE(stored.size(), std::size_t(7));
        QVERIFY(stored[0].practice);
        QCOMPARE(stored[0].answer.answer, std::string("wood"));
        QCOMPARE(stored[0].answer.ratings.at("loudness"), 10);
        QVERIFY(stored[3].excluded);
        QCOMPARE(stored[3].exclusionReason, std::string("participant stopped walking"));
        for (const auto& t : stored) {
            QVERIFY(t.answered);
            if (t.index > 0) QVERIFY(t.answer.ratings == typed.at(t.index).ratings);
        }
        // lock = "answer" is the trial core's rule, not the store's (the store keeps only its
        // schema): tests/experiment/test_trial_flow.cpp refuses a change under it.
    }

    void closingMidSessionLosesNothingAndReopeningOffersResume() {
        const QString file = home_.filePath("exp1.db");
        std::map<int, Typed> typed;
        {
            auto w = makeWindow();
            QVERIFY(createStudy(*w, QString(UNDERFOOT_SOURCE_DIR) + "/protocols/tvcg2011_exp1.toml",
                                file));
            registerParticipant(*w, "R7");
            auto* run = w->runView();
            QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
            const ue::Protocol protocol = w->context().store().protocol();
            for (int i = 0; i < 3; ++i) {
                const int index = run->session()->current().index;
                typed[index] = answerByKeyboard(*run, protocol, i);
            }
            // lock = "next_trial": the third answer can still be changed (Ctrl+Z) ...
            QTest::keyClick(run->trialPanel(), Qt::Key_Z, Qt::ControlModifier);
            QCOMPARE(run->revising(), 2);
            const ue::AnswerOption* other = protocol.questions.surfaceOption("metal");
            QTest::keyClick(run->trialPanel(), other->letter);
            QTest::keyClick(run->trialPanel(), Qt::Key_Return);
            QCOMPARE(run->revising(), -1);
            QVERIFY2(run->trialMessage().contains("changed"), qPrintable(run->trialMessage()));
            typed[2].answer = "metal";
            // ... until the next stimulus starts.
            QTest::keyClick(run->trialPanel(), Qt::Key_Space);
            QTest::keyClick(run->trialPanel(), Qt::Key_Z, Qt::ControlModifier);
            QCOMPARE(run->revising(), -1);
            QVERIFY(run->trialMessage().contains("locked"));
            // The fourth trial is playing with an answer chosen but not committed.
            QTest::keyClick(run->trialPanel(), 'b');
            QVERIFY(w->close());
        }
        {
            const auto store = ue::StudyStore::open(file.toStdString());
            const auto stored = store.trials("R7");
            int answered = 0;
            for (const auto& t : stored) answered += t.answered ? 1 : 0;
            QCOMPARE(answered, 3);
            for (const auto& [index, k] : typed)
                QVERIFY2(stored[static_cast<std::size_t>(index)].answer.answer == k.answer,
                         qPrintable(QString("trial %1: stored %2, typed %3")
                                        .arg(index)
                                        .arg(QString::fromStdString(
                                            stored[static_cast<std::size_t>(index)].answer.answer))
                                        .arg(QString::fromStdString(k.answer))));
            QCOMPARE(store.firstUnanswered("R7").value_or(-1), 3);
        }
        auto w = makeWindow(file);
        auto* run = w->runView();
        QCOMPARE(w->tabs()->currentIndex(), 1); // the Run view opens on its own
        QVERIFY(run->resumeBanner()->isVisible());
        QVERIFY(run->resumeBanner()->text().contains("R7 at trial 4 of 26"));
        QVERIFY(run->resumeList()->currentItem());
        QTest::mouseClick(button(run, "Resume the selected participant"), Qt::LeftButton);
        QVERIFY(run->session());
        QVERIFY(run->session()->resumed());
        QCOMPARE(run->pageName(), QString("trial"));
        QCOMPARE(run->session()->current().index, 3);
        // While the session runs the study cannot be switched or participants dropped.
        QVERIFY(!w->studyView()->dropParticipant("R7", "left early"));
        run->closeSession();
        QVERIFY(!w->studyView()->dropParticipant("R7", ""));
        QVERIFY(w->studyView()->dropParticipant("R7", "left early"));
        QCOMPARE(w->context().store().participant("R7").status, ue::ParticipantStatus::Dropped);
    }

    void studySummaryCountsParticipantsInWords() {
        auto w = makeWindow();
        const QString file = home_.filePath("plural.db");
        QVERIFY(
            createStudy(*w, QString(UNDERFOOT_SOURCE_DIR) + "/protocols/tvcg2011_exp1.toml", file));
        QLabel* summary = nullptr;
        for (auto* l : w->studyView()->findChildren<QLabel*>())
            if (l->accessibleName() == "Study information") summary = l;
        QVERIFY(summary);
        QVERIFY2(summary->text().endsWith("· 0 participants"), qPrintable(summary->text()));
        registerParticipant(*w, "S1");
        QVERIFY(w->runView()->session());
        w->runView()->closeSession();
        QVERIFY2(summary->text().endsWith("· 1 participant"), qPrintable(summary->text()));
        registerParticipant(*w, "S2");
        w->runView()->closeSession();
        QVERIFY2(summary->text().endsWith("· 2 participants"), qPrintable(summary->text()));
    }

    void sessionRunsWhetherOrNotTheAudioOutputStarts() {
        gui::MainWindow::Options o;
        o.dataDir = home_.filePath("data");
        o.createDemo = false;
        o.startAudio = true; // this machine may have no sound card: the session still runs
        gui::MainWindow w(o);
        w.show();
        QVERIFY(createStudy(w, QString(UNDERFOOT_SOURCE_DIR) + "/protocols/tvcg2011_exp1.toml",
                            home_.filePath("audio.db")));
        QElapsedTimer t;
        t.start();
        registerParticipant(w, "A1");
        qInfo("session start with an audio output attempt: %lld ms",
              static_cast<long long>(t.elapsed()));
        auto* run = w.runView();
        QVERIFY(run->session());
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QCOMPARE(run->pageName(), QString("trial"));
        QTest::keyClick(run->trialPanel(), Qt::Key_Space);
        QVERIFY(run->session()->playing());
    }

    void studyViewMarksSimulatedParticipants() {
        // The demo study's participants are simulated: the Study view says so on every row, so
        // nobody mistakes synthetic answers for a real participant's.
        const QString dir = home_.filePath("demo-simulated");
        QVERIFY(QDir().mkpath(dir));
        QVERIFY2(gui::ensureDemoStudy(dir, 2).isEmpty(), "demo study not created");
        auto w = makeWindow(gui::demoStudyPath(dir));
        QVERIFY(w->context().hasStudy());
        w->showView(0);
        QTableWidget* table = nullptr;
        for (auto* t : w->studyView()->findChildren<QTableWidget*>())
            if (t->accessibleName() == "Participants") table = t;
        QVERIFY(table != nullptr);
        QCOMPARE(table->rowCount(), 2);
        for (int r = 0; r < table->rowCount(); ++r)
            QVERIFY2(table->item(r, 2)->text().contains("(simulated)"),
                     qPrintable(table->item(r, 2)->text()));
    }

    void badProtocolShowsFileLineColumnAndWhatToDo() {
        const QString bad = home_.filePath("bad.toml");
        QFile f(bad);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write(
            "[protocol]\nid = \"x\"\nversion = 1\ntitle = \"t\"\n[design]\ntype = \"sideways\"\n");
        f.close();
        auto w = makeWindow();
        QVERIFY(!createStudy(*w, bad, home_.filePath("never.db")));
        const QString text = w->studyView()->messages()->toPlainText();
        QVERIFY2(text.contains(QRegularExpression("bad\\.toml:6:\\d+:")), qPrintable(text));
        QVERIFY(text.contains("Fix "));
        QVERIFY(!QFile::exists(home_.filePath("never.db")));
    }

    void aFileThatIsNotAStudyIsRefusedWithWhatToDo() {
        const QString junk = home_.filePath("junk.db");
        QFile f(junk);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("this is not an SQLite database, just text that happens to end in .db\n");
        f.close();
        auto w = makeWindow(); // reopens the last study of the earlier tests, if any
        const QString before = w->context().path();
        QVERIFY(!w->studyView()->openFile(junk));
        QCOMPARE(w->context().path(), before); // a failed open leaves the open study as it was
        const QString text = w->studyView()->messages()->toPlainText();
        QVERIFY2(text.contains("not opened") && text.contains("Underfoot study"), qPrintable(text));
        QVERIFY(!w->studyView()->openFile(home_.filePath("missing.db")));
        QVERIFY(w->studyView()->messages()->toPlainText().contains("no such study file"));
    }

    void paletteMeasuresCostAndSavesAPresetThatLoads() {
        auto w = makeWindow();
        auto* palette = w->paletteView();
        QVERIFY(palette->selectSurface("wood_reverb"));
        // A parameter of the base preset (wood) and the preset's own reverb level.
        const auto before = engine::Surface::loadById("wood_reverb");
        const auto& params = before->parameters();
        const auto it = std::find_if(params.begin(), params.end(), [](const auto& p) {
            return p.path.starts_with("wood:") && p.value > 0;
        });
        QVERIFY(it != params.end());
        const auto& p0 = *it;
        const double changed = std::clamp(p0.value * 1.5, p0.minValue, p0.maxValue);
        QVERIFY(palette->setParameter(QString::fromStdString(p0.path), changed));
        QSignalSpy measured(palette, &gui::PaletteView::costMeasured);
        palette->measureCost();
        QVERIFY(measured.wait(120000));
        QVERIFY2(palette->costText().contains("% of one core"), qPrintable(palette->costText()));
        const QString saved = palette->saveAs("wood_reverb_test", "Wood test");
        QVERIFY2(!saved.isEmpty(), qPrintable(palette->message()));
        const auto after = engine::Surface::load(saved.toStdString());
        QCOMPARE(after->info().id, std::string("wood_reverb_test"));
        QVERIFY(after->info().reverb.has_value());
        QCOMPARE(after->parameters().size(), before->parameters().size());
        // The saved preset is self-contained: no base, so the parameter path loses its prefix.
        bool found = false;
        for (const auto& p : after->parameters())
            if (p.path.ends_with(p0.path.substr(p0.path.find('.') + 1)) &&
                std::abs(p.value - changed) < 1e-9 * std::abs(changed))
                found = true;
        QVERIFY2(found,
                 qPrintable(QString::fromStdString(p0.path + " " + std::to_string(changed))));
        QVERIFY(palette->saveAs("Bad Id!", "x").isEmpty());
    }

    void setupCalibratesStepThresholdsThatFindEveryStrike() {
        auto w = makeWindow();
        auto* setup = w->setupView();
        QVERIFY2(setup->calibrateSimulated(), qPrintable(setup->calibrationText()));
        // The simulator's script knows every foot strike (engine::ShoeScript::strikes()).
        QVERIFY(setup->expectedSteps() > 0);
        QCOMPARE(setup->detectedSteps(), setup->expectedSteps());
        QVERIFY(setup->saveThresholds().isEmpty()); // no participant code yet
    }

    void replayRendersAStoredWalkerTrial() {
        const QString file = home_.filePath("small.db"); // from the practice/breaks test
        QVERIFY(QFile::exists(file));
        auto w = makeWindow(file);
        auto* results = w->resultsView();
        QSignalSpy done(results, &gui::ResultsView::replayFinished);
        const QString wav = home_.filePath("q1_trial2.wav");
        results->startReplay("Q1", 1, wav);
        QVERIFY(done.wait(120000));
        QCOMPARE(done.front().front().toString(), QString());
        QVERIFY(QFileInfo(wav).size() > 48000 * 2 * 4); // more than a second of stereo float
        // Live replay: plays, or (no sound card here) says why not; an unplayed trial is refused.
        const QString live = results->playLive("Q1", 1);
        qInfo("live replay: %s", live.isEmpty() ? "playing" : qPrintable(live));
        QVERIFY(!results->playLive("Q1", 99).isEmpty());
    }
};

QTEST_MAIN(GuiTest)
#include "test_gui.moc"
