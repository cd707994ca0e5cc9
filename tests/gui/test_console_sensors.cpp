// SPDX-License-Identifier: GPL-3.0-or-later
// The Setup view's connected sensors reach the Run view's sessions: emulated shoes (the engine's
// ShoeScript at 1 kHz, written from a thread) on a socat pseudo-terminal pair are connected in
// the Setup view; a session of an FSR protocol then plays its stimulus through the live player
// of a LiveEngine driven offline (no device), writes the trial's sensor log, and the Setup view
// refuses to record a calibration while the session holds the shoes. Without connected shoes
// the same stimulus is refused with a message naming the missing shoes.
#include "app/gui/MainWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/SetupView.h"
#include "app/gui/StudyContext.h"
#include "engine/dsp/Random.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Catalogue.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"
#include "tests/common/PacedOfflineEngine.h"
#include "tests/common/SocatHelpers.h"

#include <QApplication>
#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QLineEdit>
#include <QPushButton>
#include <QTemporaryDir>
#include <QTest>

#include <atomic>
#include <cstdio>
#include <thread>

using namespace underfoot;
namespace ue = underfoot::experiment;
namespace eng = underfoot::engine;

namespace {

const char* kProtocol = R"(
[protocol]
id = "fsr_gui"
version = 1
title = "FSR from the console"
[design]
type = "within"
[input]
type = "sensor"
sensor = "fsr"
[[stimuli]]
id = "WD"
surface = "wood"
[ordering]
repetitions = 2
[questions.surface]
options = ["wood", "gravel"]
)";

QPushButton* button(QWidget* root, const QString& name) {
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == name) return b;
    return nullptr;
}

using OfflineEngine = underfoot::test::PacedOfflineEngine;

/// The scripted walk (stand 0.5 s, then 80 steps) written at 1 kHz to `fd` until destroyed.
class ShoeWriter {
  public:
    explicit ShoeWriter(int fd) : script_(makeScript()), writer_(fd, script_) {}

  private:
    static eng::ShoeScript makeScript() {
        eng::ShoeScript script(eng::ShoeWalkOptions{}, 8);
        script.stand(500);
        script.walk(80);
        return script;
    }
    eng::ShoeScript script_;
    underfoot::test::ShoeLineWriter writer_;
};

QString makeStudy(const QTemporaryDir& dir) {
    const QString study = dir.filePath("fsr.db");
    ue::StudySettings settings;
    settings.code = "fsr";
    ue::StudyStore::create(study.toStdString(), ue::parseProtocol(kProtocol, "fsr.toml"), settings);
    return study;
}

gui::MainWindow::Options windowOptions(const QTemporaryDir& dir, const QString& study) {
    gui::MainWindow::Options o;
    o.studyPath = study;
    o.dataDir = dir.filePath("data");
    o.createDemo = false;
    o.startAudio = false;
    return o;
}

void startSession(gui::RunView* run, const QString& code) {
    QTest::keyClicks(run->codeEdit(), code);
    QTest::mouseClick(button(run, "Register and start"), Qt::LeftButton);
    QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
}

} // namespace

class LiveSensorsTest : public QObject {
    Q_OBJECT
  private slots:
    void fsrStimulusIsRefusedWithoutConnectedShoes() {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        const QString study = makeStudy(dir);
        OfflineEngine offline;
        gui::MainWindow w(windowOptions(dir, study));
        w.show();
        w.showView(1);
        auto* run = w.runView();
        run->setLiveEngine(&offline.engine);
        startSession(run, "P0");
        QVERIFY(run->session());
        run->trialPanel()->setFocus();
        QTest::keyClick(run->trialPanel(), Qt::Key_Space);
        QVERIFY(!run->session()->playing());
        QVERIFY2(run->trialMessage().contains("driven by the FSR shoes, but no shoe source is "
                                              "connected"),
                 qPrintable(run->trialMessage()));
    }

    void fsrStimulusPlaysWithTheSetupViewsShoes() {
        if (!underfoot::test::socatInstalled()) QSKIP("socat is not installed");
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        const QString study = makeStudy(dir);
        underfoot::test::SocatPair pair("gui_shoes");
        QVERIFY(pair.ready());
        const int fd = underfoot::test::openWriter(pair.shoes);
        QVERIFY(fd >= 0);
        OfflineEngine offline;
        {
            ShoeWriter writer(fd);
            gui::MainWindow w(windowOptions(dir, study));
            w.show();
            auto* setup = w.setupView();
            w.showView(4);
            QComboBox* port = nullptr;
            for (auto* c : setup->findChildren<QComboBox*>())
                if (c->accessibleName() == "Serial port of the shoes") port = c;
            QVERIFY(port);
            port->setEditText(QString::fromStdString(pair.app));
            QPushButton* connect = button(setup, "Connect the shoes for the sessions");
            QVERIFY(connect);
            QTest::mouseClick(connect, Qt::LeftButton);
            QVERIFY2(setup->connectedShoes(), qPrintable(setup->sensorStatusText()));
            QTRY_VERIFY_WITH_TIMEOUT(setup->connectedShoes()->recordable(), 5000);
            QTRY_VERIFY_WITH_TIMEOUT(setup->sensorStatusText().contains("running"), 2000);
            QVERIFY(!setup->shoesInSession());

            w.showView(1);
            auto* run = w.runView();
            run->setLiveEngine(&offline.engine);
            startSession(run, "P1");
            QVERIFY(run->session());
            QVERIFY(setup->shoesInSession());
            // The session reopened the port with its step detector attached.
            QTRY_VERIFY_WITH_TIMEOUT(setup->connectedShoes()->recordable(), 5000);

            // Calibration is refused while the session holds the shoes.
            setup->toggleSerialRecording();
            QVERIFY2(setup->sensorStatusText().contains("in use by the running session"),
                     qPrintable(setup->sensorStatusText()));

            QWidget* panel = run->trialPanel();
            panel->setFocus();
            QTest::keyClick(panel, Qt::Key_Space);
            QVERIFY2(run->session()->playing(), qPrintable(run->trialMessage()));
            QTest::qWait(1500); // steps of the scripted walk reach the player and the log
            QVERIFY2(run->sensorFaultText().isEmpty(), qPrintable(run->sensorFaultText()));
            const int index = run->session()->current().index;
            const auto& q = w.context().store().protocol().questions;
            QTest::keyClick(
                panel, q.surfaceOption(ue::baseSurface(run->session()->current().stimulus.surface))
                           ->letter);
            QTest::keyClick(panel, Qt::Key_Return);
            const ue::TrialRecord t = w.context().store().trial("P1", index);
            QVERIFY(t.answered);
            QVERIFY(t.sensorLog.has_value());
            const QString log =
                QFileInfo(study).dir().filePath(QString::fromStdString(*t.sensorLog));
            QFile file(log);
            QVERIFY2(file.open(QIODevice::ReadOnly), qPrintable(log));
            const QList<QByteArray> lines = file.readAll().split('\n');
            int frames = 0, steps = 0;
            for (const auto& line : lines) {
                if (line.contains(",frame,")) ++frames;
                if (line.contains(",step,")) ++steps;
            }
            std::printf("[ measured ] sensor log of the console's FSR trial: %d frame rows, %d "
                        "step rows (%s)\n",
                        frames, steps, qPrintable(log));
            QVERIFY2(frames > 500, qPrintable(QString::number(frames)));
            QVERIFY2(steps > 0, "no step of the scripted walk was detected");
        }
        ::close(fd);
    }
};

int main(int argc, char** argv) {
    // The settings are written when the application ends: into a folder that outlives it.
    QTemporaryDir config;
    qputenv("XDG_CONFIG_HOME", config.path().toUtf8());
    int result = 0;
    {
        QApplication app(argc, argv);
        LiveSensorsTest test;
        result = QTest::qExec(&test, argc, argv);
    }
    if (underfoot::test::socatInstalled()) { // ScratchDir's GoogleTest cleanup does not run here
        std::error_code ec;
        std::filesystem::remove_all(underfoot::test::scratchDir("socat"), ec);
    }
    return result;
}
#include "test_console_sensors.moc"
