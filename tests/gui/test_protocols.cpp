// SPDX-License-Identifier: GPL-3.0-or-later
// The Run view's listening-test and lap protocols driven from the keyboard on Qt's offscreen
// platform: clips rendered from the GUI (worker thread), presented and replayed, rated on the
// scale of each block only; laps walked silent then with sound before the questions.
#include "app/gui/MainWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/SetupView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/StudyView.h"
#include "experiment/Clips.h"
#include "experiment/Store.h"
#include "tests/gui/support/Console.h"

#include <QComboBox>
#include <QFile>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QTemporaryDir>
#include <QTest>

#include <memory>
#include <set>

#include <arpa/inet.h>
#include <cstring>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

using namespace underfoot;
using gui_test::button;
namespace ue = underfoot::experiment;

namespace {

void typeValue(QWidget* panel, int value) {
    if (value >= 10) {
        QTest::keyClick(panel, '1');
        QTest::keyClick(panel, '0');
    } else {
        QTest::keyClick(panel, static_cast<char>('0' + value));
    }
}

/// An OSC message (address, one float) as bytes: strings NUL-padded to 4, big-endian float.
QByteArray oscFloat(const QByteArray& address, float value) {
    const auto pad = [](QByteArray b) {
        b.append('\0');
        while (b.size() % 4) b.append('\0');
        return b;
    };
    QByteArray out = pad(address) + pad(",f");
    std::uint32_t bits = 0;
    std::memcpy(&bits, &value, 4);
    bits = htonl(bits);
    out.append(reinterpret_cast<const char*>(&bits), 4);
    return out;
}

void sendUdp(int port, const QByteArray& bytes) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd, bytes.constData(), static_cast<std::size_t>(bytes.size()), 0,
             reinterpret_cast<const sockaddr*>(&to), sizeof to);
    ::close(fd);
}

} // namespace

class ProtocolsTest : public QObject {
    Q_OBJECT
  private:
    gui_test::Console console_;
    std::unique_ptr<gui::MainWindow> makeWindow() { return console_.open(); }
    static bool createStudy(gui::MainWindow& w, const QString& protocol, const QString& file) {
        return gui_test::Console::createByClicking(w, protocol, file);
    }
    void registerParticipant(gui::MainWindow& w, const QString& code) {
        w.showView(1);
        auto* run = w.runView();
        run->codeEdit()->clear();
        QTest::keyClicks(run->codeEdit(), code);
        run->ageBox()->setValue(29);
        QTest::mouseClick(button(run, "Register and start"), Qt::LeftButton);
    }
    /// A shipped protocol with one line changed (shorter clips keep the test fast).
    QString editedProtocol(const QString& shipped, const QByteArray& from, const QByteArray& to) {
        QFile in(QString(UNDERFOOT_SOURCE_DIR) + "/protocols/" + shipped);
        if (!in.open(QIODevice::ReadOnly)) return {};
        QByteArray text = in.readAll();
        if (!from.isEmpty()) {
            if (!text.contains(from)) return {};
            text.replace(from, to);
        }
        const QString path = console_.path(shipped);
        QFile out(path);
        if (!out.open(QIODevice::WriteOnly)) return {};
        out.write(text);
        return path;
    }

  private slots:
    void initTestCase() { QVERIFY(console_.prepare()); }

    void listeningTestRendersClipsAndRatesOneScalePerBlock() {
        const QString protocol =
            editedProtocol("wading_listening.toml", "seconds = 7", "seconds = 0.5");
        QVERIFY(!protocol.isEmpty());
        const QString file = console_.path("listening.db");
        auto w = makeWindow();
        QVERIFY(createStudy(*w, protocol, file));
        auto* run = w->runView();
        w->showView(1);

        // No clips yet: the session is refused with what to do.
        QVERIFY(!run->clipProblems().isEmpty());
        registerParticipant(*w, "L01");
        QVERIFY(!run->session());
        QVERIFY2(run->startMessage().contains("Render them"), qPrintable(run->startMessage()));

        // Rendered from the GUI on a worker thread.
        QVERIFY(run->renderClips());
        QVERIFY(run->renderingClips());
        QTRY_VERIFY_WITH_TIMEOUT(!run->renderingClips(), 300000);
        QVERIFY2(run->clipProblems().isEmpty(), qPrintable(run->clipStatus()));
        QVERIFY2(run->clipStatus().contains("6 clips ready"), qPrintable(run->clipStatus()));
        QVERIFY(run->startSession("L01"));
        QCOMPARE(run->pageName(), QString("briefing"));
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);

        QWidget* panel = run->trialPanel();
        std::map<int, std::pair<std::string, int>> typed; // trial -> (scale, value)
        int guard = 0;
        while (run->pageName() != "finished" && guard++ < 100) {
            if (run->pageName() == "break") {
                QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                continue;
            }
            QCOMPARE(run->pageName(), QString("trial"));
            const int index = run->session()->current().index;
            const auto asked = run->session()->askedScales();
            QCOMPARE(asked.size(), std::size_t{1}); // blocks = "scale": one scale per block
            // Enter before the clip: refused, nothing stored.
            QTest::keyClick(panel, Qt::Key_Return);
            QVERIFY(run->trialMessage().contains("Start the stimulus first"));
            QTest::keyClick(panel, Qt::Key_Space);
            QVERIFY2(run->protocolStatus().contains("replays: 0"),
                     qPrintable(run->protocolStatus()));
            if (index % 5 == 0) { // replays: Space and R
                QTest::keyClick(panel, Qt::Key_Space);
                QTest::keyClick(panel, 'r');
                QVERIFY2(run->protocolStatus().contains("replays: 2"),
                         qPrintable(run->protocolStatus()));
            }
            const int value = (index * 3) % 11;
            typeValue(panel, value);
            typed[index] = {asked.front()->id, value};
            QTest::keyClick(panel, Qt::Key_Return);
            QVERIFY2(run->trialMessage().isEmpty() || run->trialMessage().startsWith("Answer "),
                     qPrintable(run->trialMessage()));
        }
        QCOMPARE(run->pageName(), QString("finished"));
        QCOMPARE(typed.size(), std::size_t{24}); // 6 clips x 4 scale blocks

        auto store = ue::StudyStore::open(file.toStdString());
        std::map<std::string, int> perScale;
        for (const auto& t : store.trials("L01")) {
            QVERIFY(t.answered);
            const auto& [scale, value] = typed.at(t.index);
            QCOMPARE(t.answer.ratings.size(), std::size_t{1});
            QCOMPARE(t.answer.ratings.at(scale), value);
            QCOMPARE(t.replays, t.index % 5 == 0 ? 2 : 0);
            ++perScale[scale];
        }
        QCOMPARE(perScale.size(), std::size_t{4});
        for (const auto& [scale, n] : perScale) QCOMPARE(n, 6);
    }

    void lapProtocolWalksSilentThenSoundLapsBeforeTheQuestions() {
        const QString protocol = editedProtocol("wading_interactive.toml", {}, {});
        QVERIFY(!protocol.isEmpty());
        const QString file = console_.path("laps.db");
        auto w = makeWindow();
        QVERIFY(createStudy(*w, protocol, file));
        registerParticipant(*w, "W01");
        auto* run = w->runView();
        QVERIFY2(run->session(), qPrintable(run->startMessage()));
        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QWidget* panel = run->trialPanel();
        std::map<int, std::map<std::string, int>> typed;
        int guard = 0;
        while (run->pageName() != "finished" && guard++ < 20) {
            if (run->pageName() == "break") {
                QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                continue;
            }
            QCOMPARE(run->pageName(), QString("trial"));
            const int index = run->session()->current().index;
            QTest::keyClick(panel, 'l'); // before the condition started: refused
            QCOMPARE(run->session()->lapsDone(), 0);
            QTest::keyClick(panel, Qt::Key_Space);
            for (int lap = 1; lap <= 6; ++lap) {
                QVERIFY2(run->protocolStatus().contains(QString("Lap %1 of 6").arg(lap)),
                         qPrintable(run->protocolStatus()));
                QVERIFY(run->protocolStatus().contains(lap <= 3 ? "SILENT" : "WITH SOUND"));
                if (lap == 2) { // questions before the last lap: refused
                    QTest::keyClick(panel, Qt::Key_Return);
                    QVERIFY2(run->trialMessage().contains("being walked"),
                             qPrintable(run->trialMessage()));
                }
                QTest::keyClick(panel, 'l');
            }
            QVERIFY(run->protocolStatus().contains("6 of 6 done"));
            std::map<std::string, int> ratings;
            int k = 0;
            for (const ue::Scale* s : run->session()->askedScales()) {
                const int value = s->min + (index + k++) % (s->max - s->min + 1);
                ratings[s->id] = value;
                typeValue(panel, value);
            }
            typed[index] = ratings;
            QTest::keyClick(panel, Qt::Key_Return);
            QVERIFY2(run->trialMessage().isEmpty() || run->trialMessage().startsWith("Answer "),
                     qPrintable(run->trialMessage()));
        }
        QCOMPARE(run->pageName(), QString("finished"));
        QCOMPARE(typed.size(), std::size_t{3});
        auto store = ue::StudyStore::open(file.toStdString());
        for (const auto& t : store.trials("W01")) {
            QVERIFY(t.answered);
            QCOMPARE(t.lapsDone, 6);
            QCOMPARE(t.answer.ratings, typed.at(t.index));
            // AS is asked three items, the other conditions seven.
            QCOMPARE(t.answer.ratings.size(), std::size_t{t.stimulus.id == "AS" ? 3u : 7u});
        }
    }

    void testToneSaysWhyWhenNoDeviceRuns() {
        auto w = makeWindow(); // startAudio = false: no device runs
        w->showView(4);
        auto* setup = w->setupView();
        QVERIFY(!setup->testToneButton()->isEnabled());
        QVERIFY2(setup->testToneButton()->text().contains("No device runs"),
                 qPrintable(setup->testToneButton()->text()));
        const QString why = setup->toggleTestTone();
        QVERIFY2(why.contains("start the audio output first"), qPrintable(why));
        QVERIFY(!setup->testTonePlaying());
    }

    void setupShowsTheOscGyroscopeStatus() {
        auto w = makeWindow();
        w->showView(4);
        auto* setup = w->setupView();
        for (auto* box : setup->findChildren<QSpinBox*>())
            if (box->accessibleName() == "OSC gyroscope UDP port") box->setValue(0);
        QCOMPARE(setup->toggleGyroListening(), QString());
        const int port = setup->gyroPort();
        QVERIFY(port > 0);
        for (int i = 0; i < 20; ++i) {
            sendUdp(port, oscFloat("/underfoot/gyro/left_thigh", static_cast<float>(i)));
            sendUdp(port, oscFloat("/underfoot/gyro/right_thigh", static_cast<float>(-i)));
            QTest::qWait(10); // 100 Hz, as the sensors send
        }
        sendUdp(port, oscFloat("/underfoot/gyro/left_elbow", 1.0f)); // unknown limb
        QTRY_VERIFY2_WITH_TIMEOUT(setup->gyroStatusText().contains("right_thigh 20"),
                                  qPrintable(setup->gyroStatusText()), 5000);
        QTRY_VERIFY_WITH_TIMEOUT(setup->gyroStatusText().contains("1 rejected"), 5000);
        // Loss is counted from arrival gaps: on a loaded machine some may show; none is rejected.
        QVERIFY2(setup->gyroStatusText().contains("left_thigh 20"),
                 qPrintable(setup->gyroStatusText()));
        QVERIFY2(setup->gyroStatusText().contains("40 accepted"),
                 qPrintable(setup->gyroStatusText()));
        QCOMPARE(setup->toggleGyroListening(), QString());
        QCOMPARE(setup->gyroPort(), 0);
    }
};

QTEST_MAIN(ProtocolsTest)
#include "test_protocols.moc"
