// SPDX-License-Identifier: GPL-3.0-or-later
// A sensor fault in the Run view: a test double of the stimulus player reports the FSR shoes as
// silent in the middle of a trial. The 100 ms timer pauses the session, the banner shows the
// reason, answer keys are refused, Resume (Ctrl+Shift+S) is refused while the fault persists and
// presents the same trial again once it is gone, and the study file has that trial interrupted
// once, then answered.
#include "app/gui/MainWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "experiment/Catalogue.h"
#include "experiment/Store.h"

#include <QApplication>
#include <QElapsedTimer>
#include <QLineEdit>
#include <QPushButton>
#include <QTemporaryDir>
#include <QTest>

#include <atomic>
#include <cstdio>

using namespace underfoot;
namespace ue = underfoot::experiment;

namespace {

QPushButton* button(QWidget* root, const QString& name) {
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == name) return b;
    return nullptr;
}

/// A player whose shoes fall silent while `silent` is set (any thread may read it).
class FaultyShoesPlayer final : public ue::StimulusPlayer {
  public:
    ue::StimulusStart start(const ue::Stimulus&, std::uint64_t plannedSeed) override {
        ++starts;
        ue::StimulusStart s;
        s.renderSeed = plannedSeed;
        return s;
    }
    void stop() override { ++stops; }
    std::optional<std::string> sensorFault() const override {
        if (silent.load()) return std::string("FSR shoes silent: no frame for 402 ms (test)");
        return std::nullopt;
    }
    std::atomic<bool> silent{false};
    int starts = 0, stops = 0;
};

} // namespace

class SensorFaultTest : public QObject {
    Q_OBJECT
  private slots:
    void faultPausesRefusesAnswersAndResumesTheSameTrial() {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        qputenv("XDG_CONFIG_HOME", dir.filePath("config").toUtf8());
        const QString study = dir.filePath("fault.db");
        {
            const auto protocol = ue::loadProtocol(std::string(UNDERFOOT_SOURCE_DIR) +
                                                   "/protocols/tvcg2011_exp1.toml");
            ue::StudySettings settings;
            settings.code = "fault";
            ue::StudyStore::create(study.toStdString(), protocol, settings);
        }
        gui::MainWindow::Options o;
        o.studyPath = study;
        o.dataDir = dir.filePath("data");
        o.createDemo = false;
        o.startAudio = false;
        gui::MainWindow w(o);
        w.show();
        w.activateWindow();
        QVERIFY(QTest::qWaitForWindowActive(&w));
        w.showView(1);
        auto* run = w.runView();
        FaultyShoesPlayer fake;
        run->setStimulusPlayer(&fake);
        QTest::keyClicks(run->codeEdit(), "F1");
        QTest::mouseClick(button(run, "Register and start"), Qt::LeftButton);
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QVERIFY(run->session());
        const auto& q = w.context().store().protocol().questions;
        QWidget* panel = run->trialPanel();
        panel->setFocus();
        const auto letterOf = [&] {
            return q.surfaceOption(ue::baseSurface(run->session()->current().stimulus.surface))
                ->letter;
        };

        // Trial 1 answered normally through the injected player.
        QTest::keyClick(panel, Qt::Key_Space);
        QCOMPARE(fake.starts, 1);
        QTest::keyClick(panel, letterOf());
        QTest::keyClick(panel, Qt::Key_Return);
        QCOMPARE(run->session()->current().index, 1);

        // Trial 2: the shoes fall silent mid-trial; the timer notices.
        QTest::keyClick(panel, Qt::Key_Space);
        QVERIFY(run->session()->playing());
        QVERIFY(run->sensorFaultText().isEmpty());
        const char letter = letterOf();
        QElapsedTimer clock;
        clock.start();
        fake.silent = true;
        QTRY_VERIFY_WITH_TIMEOUT(!run->sensorFaultText().isEmpty(), 2000);
        const qint64 pauseMs = clock.elapsed();
        std::printf("sensor fault shown %lld ms after the player reported it\n",
                    static_cast<long long>(pauseMs));
        QVERIFY2(pauseMs < 1000, qPrintable(QString::number(pauseMs)));
        QVERIFY(run->sensorFaultText().contains("FSR shoes silent: no frame for 402 ms"));
        QVERIFY(run->sensorFaultText().contains("trial 2"));
        QVERIFY(run->session()->paused());
        QVERIFY(!run->session()->playing());

        // Answer keys and Space are refused while paused.
        QTest::keyClick(panel, letter);
        QTest::keyClick(panel, Qt::Key_Space);
        QTest::keyClick(panel, Qt::Key_Return);
        QVERIFY(!run->session()->playing());
        QCOMPARE(run->session()->current().index, 1);
        QVERIFY(run->trialMessage().contains("sensor fault"));
        QCOMPARE(fake.starts, 2);

        // Resume is refused while the shoes are still silent.
        QTest::keyClick(panel, Qt::Key_S, Qt::ControlModifier | Qt::ShiftModifier);
        QVERIFY(run->session()->paused());
        QVERIFY2(run->trialMessage().contains("Not resumed") &&
                     run->trialMessage().contains("FSR shoes silent"),
                 qPrintable(run->trialMessage()));
        QVERIFY(!run->sensorFaultText().isEmpty());

        // The shoes are back: Ctrl+Shift+S resumes and presents trial 2 again.
        fake.silent = false;
        QTest::keyClick(panel, Qt::Key_S, Qt::ControlModifier | Qt::ShiftModifier);
        QVERIFY(!run->session()->paused());
        QVERIFY(run->sensorFaultText().isEmpty());
        QVERIFY(run->session()->playing());
        QCOMPARE(fake.starts, 3);
        QCOMPARE(run->session()->current().index, 1);
        QTest::keyClick(panel, letter);
        QTest::keyClick(panel, Qt::Key_Return);
        QCOMPARE(run->session()->current().index, 2);

        const auto store = ue::StudyStore::open(study.toStdString());
        const auto trials = store.trials("F1");
        QVERIFY(trials[0].answered);
        QCOMPARE(trials[0].interruptions, 0);
        QVERIFY(trials[1].answered);
        QCOMPARE(trials[1].interruptions, 1);
        QVERIFY(trials[1].interruptionReason.find("FSR shoes silent") != std::string::npos);
        QCOMPARE(trials[1].answer.answer, ue::baseSurface(trials[1].stimulus.surface));
        QVERIFY(!trials[2].answered);
        run->closeSession();
    }
};

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QApplication::setApplicationName("underfoot-gui-test");
    SensorFaultTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "test_sensor_fault.moc"
