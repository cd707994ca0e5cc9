// SPDX-License-Identifier: GPL-3.0-or-later
// The participant window (QTest, offscreen): over the Run view's session it shows the
// participant's briefing, the questions, answer lists, scales with anchors and 1-based progress,
// and never the answer key (stimulus ids, surfaces or soundscapes played, the plan's order),
// the group or the experimenter's notes. Answers given on either window are stored.
#include "app/gui/AnswerPanel.h"
#include "app/gui/MainWindow.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/StudyView.h"
#include "experiment/Catalogue.h"
#include "experiment/Store.h"
#include "tests/gui/support/Console.h"

#include <QComboBox>
#include <QGroupBox>
#include <QLineEdit>
#include <QPushButton>
#include <QRegularExpression>
#include <QSpinBox>
#include <QTemporaryDir>
#include <QTest>

#include <memory>

using namespace underfoot;
using gui_test::button;
namespace ue = underfoot::experiment;

namespace {
/// Every text of the participant window, minus the heading (which carries the trial number).
QString body(const gui::ParticipantWindow& pw) {
    QStringList texts = pw.visibleTexts();
    texts.removeAll(pw.heading());
    return texts.join("\n");
}
} // namespace

class ParticipantTest : public QObject {
    Q_OBJECT
  private:
    gui_test::Console console_;

  private slots:
    void initTestCase() { QVERIFY(console_.prepare()); }

    void participantWindowShowsNoAnswerKeyAndTakesAnswers() {
        const auto window = console_.open("data");
        gui::MainWindow& w = *window;
        const QString file = console_.path("exp2.db");
        const QString protocolPath =
            QString(UNDERFOOT_SOURCE_DIR) + "/protocols/tvcg2011_exp2.toml";
        QVERIFY(gui_test::Console::createByClicking(w, protocolPath, file));
        const ue::Protocol& p = w.context().store().protocol();

        // The participant window is open before the participant arrives.
        w.showView(1);
        gui::RunView* run = w.runView();
        gui::ParticipantWindow* pw = run->openParticipantWindow();
        QVERIFY(pw);
        QCOMPARE(pw->heading(), QString("Welcome"));
        // Offscreen has one screen: the window shares the Run view's screen, so the Run view
        // hides the answer key.
        QVERIFY(!run->answerKeyShown());

        // A participant of the incoherent group (the soundscape question is asked).
        QTest::keyClicks(run->codeEdit(), "P001");
        run->groupBox()->setCurrentIndex(run->groupBox()->findData("incoherent"));
        for (auto* e : run->findChildren<QLineEdit*>())
            if (e->accessibleName() == "Reason for overriding the group")
                e->setText("soundscape group needed by the test");
        QVERIFY(run->registerAndStart());
        QCOMPARE(run->pageName(), QString("briefing"));

        // Briefing: the participant reads the questions, not the notes, title or group.
        const QString notesStart = QString::fromStdString(p.notes).left(40);
        QVERIFY(!notesStart.isEmpty());
        QVERIFY2(!run->briefingText().contains(notesStart), qPrintable(run->briefingText()));
        QString briefing = pw->visibleTexts().join("\n");
        QVERIFY2(briefing.contains(QString::fromStdString(p.questions.surfacePrompt)),
                 qPrintable(briefing));
        for (const QString& secret :
             {notesStart, QString::fromStdString(p.title), QString("incoherent"),
              QString("coherent"), QString("footsteps alone")})
            QVERIFY2(!briefing.contains(secret, Qt::CaseInsensitive), qPrintable(secret));
        // With the key shown again (Ctrl+K: the experimenter's own screen) the notes come back.
        run->setAnswerKeyShown(true);
        QVERIFY(run->briefingText().contains(notesStart));
        run->setAnswerKeyShown(false);
        QVERIFY(!run->briefingText().contains(notesStart));

        QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QCOMPARE(run->pageName(), QString("trial"));
        QVERIFY2(run->stimulusText().isEmpty(), qPrintable(run->stimulusText()));

        const auto plan = w.context().store().trials("P001");
        const int total = static_cast<int>(plan.size());
        QString firstBody;
        int n = 0;
        while (run->session() && run->session()->phase() != ue::SessionPhase::Finished) {
            if (run->pageName() == "break") {
                QCOMPARE(pw->heading(), QString("Break"));
                QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                continue;
            }
            QCOMPARE(run->pageName(), QString("trial"));
            ++n;
            const ue::TrialRecord t = run->session()->current();
            QCOMPARE(pw->heading(), QString("Trial %1 of %2").arg(t.index + 1).arg(total));
            QCOMPARE(t.index + 1, n);
            QVERIFY2(run->trialHeader().startsWith(QString("Trial %1 of %2").arg(n).arg(total)),
                     qPrintable(run->trialHeader()));
            // Before the stimulus the participant cannot answer.
            QTest::keyClick(pw, 'a');
            QVERIFY(run->flow()->draft().answer.empty());
            QTest::keyClick(run->trialPanel(), Qt::Key_Space);
            QVERIFY(run->session()->playing());

            // Nothing that depends on the stimulus: the same body on every trial...
            const QString b = body(*pw);
            if (firstBody.isEmpty()) firstBody = b;
            QCOMPARE(b, firstBody);
            // ...and no stimulus id, order, group or note anywhere.
            for (const auto& planned : plan)
                QVERIFY2(
                    !b.contains(QRegularExpression(
                        "\\b" +
                        QRegularExpression::escape(QString::fromStdString(planned.stimulus.id)) +
                        "\\b")),
                    qPrintable(QString::fromStdString(planned.stimulus.id)));
            QVERIFY(!b.contains(notesStart));
            QVERIFY(!b.contains("incoherent", Qt::CaseInsensitive));
            QVERIFY(!b.contains("stimulus", Qt::CaseInsensitive));
            QVERIFY(!b.contains("repetition", Qt::CaseInsensitive));

            // The experimenter's pause (Ctrl+P) holds the participant's answers.
            if (n == 2) {
                QTest::mouseClick(button(run, "Pause or resume"), Qt::LeftButton);
                QVERIFY(pw->visibleTexts().contains("Please wait a moment."));
                QTest::keyClick(pw, 'a');
                QVERIFY(run->flow()->draft().answer.empty());
                QTest::mouseClick(button(run, "Pause or resume"), Qt::LeftButton);
                QVERIFY(pw->visibleTexts().contains("Please answer."));
            }
            // Odd trials answered on the participant window, even ones on the Run view.
            QWidget* target = n % 2 ? static_cast<QWidget*>(pw) : run->trialPanel();
            const ue::AnswerOption& surface =
                p.questions.surfaceOptions[static_cast<std::size_t>(n) %
                                           p.questions.surfaceOptions.size()];
            QTest::keyClick(target, surface.letter);
            QTest::keyClick(target, static_cast<char>('1' + n % 7));
            QTest::keyClick(target, static_cast<char>('1' + (n + 3) % 7));
            const ue::AnswerOption& scape =
                p.questions.soundscapeOptions[static_cast<std::size_t>(n) %
                                              p.questions.soundscapeOptions.size()];
            QTest::keyClick(target, scape.letter);
            // The draft shows on both windows.
            QCOMPARE(run->flow()->draft().answer, surface.id);
            QTest::keyClick(target, Qt::Key_Return);
            QVERIFY2(run->pageName() != "trial" || run->trialMessage().startsWith("Answer stored"),
                     qPrintable(QString("trial %1 (%2): %3")
                                    .arg(n)
                                    .arg(n % 2 ? "participant window" : "Run view")
                                    .arg(run->trialMessage())));
            const auto stored =
                w.context().store().trials("P001")[static_cast<std::size_t>(t.index)];
            QVERIFY(stored.answered);
            QCOMPARE(stored.answer.answer, surface.id);
            QCOMPARE(stored.answer.soundscapeAnswer, scape.id);
            QCOMPARE(stored.answer.ratings.at("realism"), 1 + n % 7);
            QCOMPARE(stored.answer.ratings.at("quality"), 1 + (n + 3) % 7);
        }
        QCOMPARE(n, total);
        QCOMPARE(pw->heading(), QString("Thank you"));
        run->closeParticipantWindow();
        QVERIFY(run->answerKeyShown());
    }

    void participantClickAnswersAndScaleAnchors() {
        const auto window = console_.open("data2");
        gui::MainWindow& w = *window;
        ue::StudySettings settings;
        settings.code = "LAPS";
        const QString created = w.context().createStudy(
            console_.path("laps.db"),
            QString(UNDERFOOT_SOURCE_DIR) + "/protocols/wading_interactive.toml", settings);
        QVERIFY2(created.isEmpty(), qPrintable(created));
        w.showView(1);
        gui::RunView* run = w.runView();
        gui::ParticipantWindow* pw = run->openParticipantWindow();
        QTest::keyClicks(run->codeEdit(), "P002");
        QVERIFY2(run->registerAndStart(), qPrintable(run->startMessage()));
        if (run->pageName() == "briefing")
            QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
        QCOMPARE(run->pageName(), QString("trial"));
        QTest::keyClick(run->trialPanel(), Qt::Key_Space);
        QVERIFY2(pw->visibleTexts().join("\n").contains("Lap 1 of"),
                 qPrintable(pw->visibleTexts().join("\n")));
        for (int lap = 0; lap < run->session()->lapCount(); ++lap)
            QTest::keyClick(run->trialPanel(), Qt::Key_L);
        QVERIFY2(pw->visibleTexts().join("\n").contains("Please answer"),
                 qPrintable(pw->visibleTexts().join("\n")));
        const auto& sections = run->flow()->sections();
        QVERIFY(!sections.empty());
        // Every anchor of every asked scale is on the participant's screen.
        const QString all = pw->visibleTexts().join("\n");
        for (const auto& s : sections)
            if (s.scale)
                for (const auto& a : ue::anchorTexts(*s.scale))
                    QVERIFY2(all.contains(QString::fromStdString(a)), a.c_str());
        // A click on a scale button of the participant window sets the rating in the Run view.
        for (std::size_t i = 0; i < sections.size(); ++i) {
            const auto& s = sections[i];
            if (!s.scale) continue;
            QPushButton* pick = nullptr;
            QWidget* question = pw->answers()->section(static_cast<int>(i));
            QVERIFY(question);
            QCOMPARE(question->accessibleName(), QString::fromStdString(s.prompt));
            for (auto* b : question->findChildren<QPushButton*>())
                if (b->text() == QString::number(s.scale->max)) pick = b;
            QVERIFY(pick);
            QTest::mouseClick(pick, Qt::LeftButton);
            QCOMPARE(run->flow()->draft().ratings.at(s.scale->id), s.scale->max);
            break;
        }
        run->closeSession();
        QCOMPARE(pw->heading(), QString("Welcome"));
    }
};

QTEST_MAIN(ParticipantTest)
#include "test_participant.moc"
