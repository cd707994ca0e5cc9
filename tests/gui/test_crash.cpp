// SPDX-License-Identifier: GPL-3.0-or-later
// A real crash: a child process (this program, in child mode) runs the console, answers two
// trials by keyboard, chooses a third answer without committing it and kills itself with
// SIGKILL. The parent checks that both committed answers are in the study file and that the
// console reopened on it offers to resume at the third trial.
#include "app/gui/MainWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "experiment/Store.h"

#include <QApplication>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProcess>
#include <QPushButton>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>

#include <csignal>
#include <cstdio>
#include <unistd.h>

using namespace underfoot;
namespace ue = underfoot::experiment;

namespace {

QPushButton* button(QWidget* root, const QString& name) {
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == name) return b;
    return nullptr;
}

/// Child mode: answer two trials of `study`, choose a third answer, then die.
int runChild(const QString& study, const QString& dataDir) {
    gui::MainWindow::Options o;
    o.studyPath = study;
    o.dataDir = dataDir;
    o.createDemo = false;
    o.startAudio = false;
    gui::MainWindow w(o);
    w.show();
    w.showView(1);
    auto* run = w.runView();
    QTest::keyClicks(run->codeEdit(), "K9");
    QTest::mouseClick(button(run, "Register and start"), Qt::LeftButton);
    QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
    if (!run->session()) return 2;
    const auto& q = w.context().store().protocol().questions;
    for (int i = 0; i < 2; ++i) {
        const auto& t = run->session()->current();
        QTest::keyClick(run->trialPanel(), Qt::Key_Space);
        QTest::keyClick(run->trialPanel(),
                        q.surfaceOption(ue::baseSurface(t.stimulus.surface))->letter);
        QTest::keyClick(run->trialPanel(), Qt::Key_Return);
    }
    QTest::keyClick(run->trialPanel(), Qt::Key_Space);
    QTest::keyClick(run->trialPanel(), 'c');
    std::printf("answered 2\n");
    std::fflush(stdout);
    ::kill(::getpid(), SIGKILL);
    return 3; // not reached
}

} // namespace

class CrashTest : public QObject {
    Q_OBJECT
  private slots:
    void killedMidSessionLosesNoCommittedAnswerAndResumes() {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        const QString study = dir.filePath("crash.db");
        {
            const auto protocol = ue::loadProtocol(std::string(UNDERFOOT_SOURCE_DIR) +
                                                   "/protocols/tvcg2011_exp1.toml");
            ue::StudySettings settings;
            settings.code = "crash";
            ue::StudyStore::create(study.toStdString(), protocol, settings);
        }
        QProcess child;
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.insert("UNDERFOOT_GUI_CRASH_CHILD", study);
        env.insert("UNDERFOOT_GUI_CRASH_DATA", dir.filePath("data"));
        env.insert("XDG_CONFIG_HOME", dir.filePath("config"));
        env.insert("QT_QPA_PLATFORM", "offscreen");
        child.setProcessEnvironment(env);
        child.start(QCoreApplication::applicationFilePath(), {});
        QVERIFY(child.waitForFinished(120000));
        QCOMPARE(child.exitStatus(), QProcess::CrashExit);
        QVERIFY2(child.readAllStandardOutput().contains("answered 2"),
                 qPrintable(child.readAllStandardError()));

        {
            const auto store = ue::StudyStore::open(study.toStdString());
            const auto trials = store.trials("K9");
            QVERIFY(trials[0].answered);
            QVERIFY(trials[1].answered);
            QVERIFY(!trials[2].answered);
            QCOMPARE(trials[0].answer.answer, ue::baseSurface(trials[0].stimulus.surface));
            QCOMPARE(store.participant("K9").status, ue::ParticipantStatus::Active);
        }
        qputenv("XDG_CONFIG_HOME", dir.filePath("config2").toUtf8());
        gui::MainWindow::Options o;
        o.studyPath = study;
        o.dataDir = dir.filePath("data");
        o.createDemo = false;
        o.startAudio = false;
        gui::MainWindow w(o);
        w.show();
        QCOMPARE(w.tabs()->currentIndex(), 1);
        QVERIFY(w.runView()->resumeBanner()->text().contains("K9 at trial 3 of 26"));
        QTest::mouseClick(button(w.runView(), "Resume the selected participant"), Qt::LeftButton);
        QVERIFY(w.runView()->session());
        QCOMPARE(w.runView()->session()->current().index, 2);
    }
};

int main(int argc, char** argv) {
    const QByteArray childStudy = qgetenv("UNDERFOOT_GUI_CRASH_CHILD");
    QApplication app(argc, argv);
    QApplication::setApplicationName("underfoot-gui-test");
    if (!childStudy.isEmpty())
        return runChild(QString::fromUtf8(childStudy),
                        QString::fromUtf8(qgetenv("UNDERFOOT_GUI_CRASH_DATA")));
    CrashTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "test_crash.moc"
