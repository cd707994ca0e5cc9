// SPDX-License-Identifier: GPL-3.0-or-later
// The participant window's contract, over every shipped protocol (protocols/*.toml) and every
// group: every screen a participant can see (waiting, briefing, each trial before the sound,
// during each lap, answering, after a refused Done, paused, answered; breaks; the end) is
// rendered offscreen at 1280x800 and searched for what a participant must never read: the
// experimenter's notes, the study's title, group ids and labels, the current stimulus's id,
// label, surface and soundscape ids, its clip's file name, its seeds and the study's, and the
// correct answer as an id (the answer buttons, which show the options' own labels, are left out
// of the search). On every trial screen every question, with its prompt, answers and values,
// lies inside the window's question area (no scrolling) and is not cut.
//
// Listening tests run on a copy of the protocol whose clips are 0.5 s long (rendering speed;
// no text depends on the length); lab-supplied recordings, not bundled, are stood in for by
// quiet files of their names. `UNDERFOOT_CONTRACT_SHOTS=DIR` saves each protocol's
// fullest trial screen there as PNG.
#include "app/gui/AnswerPanel.h"
#include "app/gui/MainWindow.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "engine/io/AudioFile.h"
#include "experiment/Catalogue.h"
#include "experiment/Store.h"
#include "experiment/TrialFlow.h"
#include "tests/gui/support/Console.h"

#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QTemporaryDir>
#include <QTest>

#include <map>
#include <memory>
#include <set>

using namespace underfoot;
using gui_test::button;
namespace ue = underfoot::experiment;

namespace {

QString s(const std::string& text) {
    return QString::fromStdString(text);
}

/// What one screen must not show, with the reason (for the failure message).
using Secrets = std::map<QString, QString>;

void addSecret(Secrets& out, const QString& text, const QString& why) {
    const QString t = text.trimmed();
    if (t.size() >= 2) out.emplace(t, why);
}

/// The secrets that hold for the whole study: notes (whole and line by line), the study's
/// title, the groups, the study seed.
Secrets studySecrets(const ue::Protocol& p, std::uint64_t studySeed) {
    Secrets out;
    addSecret(out, s(p.notes), "the notes");
    for (const QString& line : s(p.notes).split(QRegularExpression("[\\n.;:]")))
        if (line.trimmed().size() >= 16) addSecret(out, line, "a line of the notes");
    if (p.title != ue::participantTitle(p)) addSecret(out, s(p.title), "the study's title");
    for (const auto& g : p.groups) {
        if (p.groups.size() == 1 && g.label.empty()) continue; // a within design's implicit group
        addSecret(out, s(g.id), "a group id");
        addSecret(out, s(g.label), "a group label");
    }
    addSecret(out, QString::number(studySeed), "the study's seed");
    return out;
}

/// The secrets of the current trial: its stimulus, clip, seeds and correct answer ids.
Secrets trialSecrets(const ue::Protocol& p, const ue::TrialRecord& t) {
    Secrets out;
    const ue::Stimulus& st = t.stimulus;
    addSecret(out, s(st.id), "the stimulus id");
    addSecret(out, s(st.label), "the stimulus label");
    addSecret(out, s(st.surface), "the stimulus's surface id");
    addSecret(out, s(ue::baseSurface(st.surface)), "the stimulus's surface id");
    if (st.soundscape) addSecret(out, s(*st.soundscape), "the stimulus's soundscape id");
    if (st.clip) addSecret(out, s(*st.clip), "the lab clip's file");
    if (t.clip) {
        addSecret(out, s(t.clip->file), "the clip's file name");
        addSecret(out, QFileInfo(s(t.clip->file)).completeBaseName(), "the clip's file name");
    }
    addSecret(out, QString::number(t.plannedSeed), "the planned seed");
    if (t.renderSeed) addSecret(out, QString::number(*t.renderSeed), "the render seed");
    for (const auto& o : p.questions.surfaceOptions)
        if (ue::answerIsCorrect(o.id, st.surface)) addSecret(out, s(o.id), "the correct answer");
    if (st.soundscape)
        for (const auto& o : p.questions.soundscapeOptions)
            if (o.id == *st.soundscape) addSecret(out, s(o.id), "the correct soundscape answer");
    return out;
}

/// Whether `text` holds `secret` as a whole word (case-insensitive).
bool holds(const QString& text, const QString& secret) {
    const QRegularExpression re("(?<![\\p{L}\\p{N}_])" + QRegularExpression::escape(secret) +
                                    "(?![\\p{L}\\p{N}_])",
                                QRegularExpression::CaseInsensitiveOption);
    return re.match(text).hasMatch();
}

/// The window's texts without the questions' own wording: the answer buttons (an option's
/// label may equal an id: "wood"), the prompts and anchors (a prompt may name what every trial
/// plays: "walking through water"). Those are the same on every trial; the rest is searched.
QString searchable(const gui::ParticipantWindow& pw, const ue::Protocol& p) {
    QStringList texts = pw.visibleTexts();
    for (const auto* list : {&p.questions.surfaceOptions, &p.questions.soundscapeOptions})
        for (const auto& o : *list) {
            texts.removeAll(QString("%1   %2").arg(QChar(o.letter)).arg(s(o.label)));
            texts.removeAll(QString("Answer %1: %2").arg(QChar(o.letter)).arg(s(o.label)));
        }
    QStringList wording{s(p.questions.surfacePrompt), s(p.questions.soundscapePrompt)};
    for (const auto& sc : p.questions.scales) {
        wording << s(sc.prompt);
        for (const auto& a : ue::anchorTexts(sc)) wording << s(a);
    }
    wording.removeAll(QString());
    QString all = texts.join("\n");
    for (const QString& w : wording) all.replace(w, "<question>");
    return all;
}

} // namespace

class ParticipantContractTest : public QObject {
    Q_OBJECT
  private:
    gui_test::Console console_;
    int screens_ = 0;
    int layouts_ = 0;
    std::set<QString> searched_;
    QString shotsDir_;

    /// A listening test's protocol with 0.5 s clips, beside a link to the shipped data folder.
    QString shortClips(const QString& shipped) {
        QFile in(shipped);
        if (!in.open(QIODevice::ReadOnly)) return {};
        QString text = QString::fromUtf8(in.readAll());
        const qsizetype clips = text.indexOf("[clips]");
        const QRegularExpression seconds("seconds\\s*=\\s*[0-9.]+");
        const auto m = seconds.match(text, clips);
        if (clips < 0 || !m.hasMatch()) return {};
        text.replace(m.capturedStart(), m.capturedLength(), "seconds = 0.5");
        QDir().mkpath(console_.path("protocols"));
        QFile::link(QString(UNDERFOOT_SOURCE_DIR) + "/protocols/data",
                    console_.path("protocols/data"));
        const QString path = console_.path("protocols/" + QFileInfo(shipped).fileName());
        QFile out(path);
        if (!out.open(QIODevice::WriteOnly)) return {};
        out.write(text.toUtf8());
        return path;
    }

    /// Checks one screen: none of `secrets` in its texts.
    void checkScreen(const gui::ParticipantWindow& pw, const ue::Protocol& p,
                     const Secrets& secrets, const QString& where) {
        QCoreApplication::processEvents();
        ++screens_;
        const QString text = searchable(pw, p);
        for (const auto& [secret, why] : secrets) {
            searched_.insert(secret);
            QVERIFY2(
                !holds(text, secret),
                qPrintable(QString("%1: %2 '%3' is shown:\n%4").arg(where, why, secret, text)));
        }
    }

    /// Checks that every question of the trial screen lies inside the question area of a
    /// 1280x800 window and that no prompt or answer is cut.
    void checkLayout(gui::ParticipantWindow& pw, const QString& where) {
        QCoreApplication::processEvents();
        ++layouts_;
        QCOMPARE(pw.size(), QSize(1280, 800));
        QWidget* viewport = pw.answerArea()->viewport();
        const QRect area = viewport->rect();
        gui::AnswerPanel* panel = pw.answers();
        QVERIFY2(panel->sectionCount() > 0, qPrintable(where));
        for (int i = 0; i < panel->sectionCount(); ++i) {
            QWidget* question = panel->section(i);
            QVERIFY(question->isVisibleTo(&pw));
            const QRect r(question->mapTo(viewport, QPoint(0, 0)), question->size());
            QVERIFY2(area.contains(r), qPrintable(QString("%1: question %2 (%3) at %4,%5 %6x%7 "
                                                          "lies outside the %8x%9 area")
                                                      .arg(where)
                                                      .arg(i + 1)
                                                      .arg(question->accessibleName())
                                                      .arg(r.x())
                                                      .arg(r.y())
                                                      .arg(r.width())
                                                      .arg(r.height())
                                                      .arg(area.width())
                                                      .arg(area.height())));
            for (QWidget* child : question->findChildren<QWidget*>()) {
                const QRect c(child->mapTo(viewport, QPoint(0, 0)), child->size());
                QVERIFY2(area.contains(c), qPrintable(where + ": a widget of question " +
                                                      question->accessibleName()));
                if (auto* l = qobject_cast<QLabel*>(child); l && l->wordWrap())
                    QVERIFY2(l->height() >= l->heightForWidth(l->width()),
                             qPrintable(where + ": cut text: " + l->text()));
                if (auto* b = qobject_cast<QPushButton*>(child))
                    QVERIFY2(b->width() >= b->fontMetrics().horizontalAdvance(b->text()) + 16,
                             qPrintable(where + ": cut answer: " + b->text()));
            }
        }
    }

    void runProtocol(const QString& shipped) {
        const ue::Protocol shippedProtocol = ue::loadProtocol(shipped.toStdString());
        const QString name = QFileInfo(shipped).completeBaseName();
        const QString path = shippedProtocol.clips.enabled ? shortClips(shipped) : shipped;
        QVERIFY2(!path.isEmpty(), qPrintable(shipped));
        const auto window = console_.open("data-" + name);
        gui::MainWindow& w = *window;
        ue::StudySettings settings;
        settings.code = "C" + name.toStdString().substr(0, 6);
        settings.seed = 20240517;
        const QString created =
            w.context().createStudy(console_.path(name + ".db"), path, settings);
        QVERIFY2(created.isEmpty(), qPrintable(created));
        const ue::Protocol& p = w.context().store().protocol();
        const Secrets study = studySecrets(p, settings.seed);
        w.showView(1);
        gui::RunView* run = w.runView();
        if (p.clips.enabled) {
            // Lab-supplied clips (wading_realism's real recordings) are not bundled: a quiet
            // half second stands in for each, under its own name.
            for (const auto& st : p.stimuli) {
                if (!st.clip) continue;
                const QString file = QDir(run->clipFolder()).filePath(s(*st.clip));
                QDir().mkpath(QFileInfo(file).path());
                underfoot::engine::AudioBuffer standIn;
                standIn.sampleRateHz = 48000;
                standIn.channels = 2;
                standIn.samples.assign(48000, 0.01f);
                underfoot::engine::writeAudioFile(file.toStdString(), standIn);
            }
            QVERIFY(run->renderClips());
            QTRY_VERIFY_WITH_TIMEOUT(!run->renderingClips(), 300000);
            QVERIFY2(run->clipProblems().isEmpty(), qPrintable(run->clipStatus()));
        }
        gui::ParticipantWindow* pw = run->openParticipantWindow();
        pw->resize(1280, 800);
        checkScreen(*pw, p, study, name + " waiting");

        std::vector<std::string> groups;
        for (const auto& g : p.groups) groups.push_back(g.id);
        int maxQuestions = 0;
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
            const QString code = QString("P%1").arg(gi + 1);
            run->codeEdit()->setText(code);
            if (groups.size() > 1) {
                run->groupBox()->setCurrentIndex(run->groupBox()->findData(s(groups[gi])));
                for (auto* e : run->findChildren<QLineEdit*>())
                    if (e->accessibleName() == "Reason for overriding the group")
                        e->setText("every group is checked");
            }
            // The protocol's own registration questions: the first answer of each.
            for (const auto& f : p.participantFields)
                for (auto* box : run->findChildren<QComboBox*>())
                    if (box->accessibleName() == s(f.label)) box->setCurrentIndex(1);
            QVERIFY2(run->registerAndStart(), qPrintable(run->startMessage()));
            const QString who = QString("%1, group %2").arg(name, s(groups[gi]));
            checkScreen(*pw, p, study, who + ", briefing");
            QTest::mouseClick(button(run, "Start the trials"), Qt::LeftButton);
            int guard = 0;
            while (run->session() && run->session()->phase() != ue::SessionPhase::Finished &&
                   guard++ < 400) {
                if (run->pageName() == "break") {
                    checkScreen(*pw, p, study, who + ", break");
                    QTest::mouseClick(button(run, "Continue after the break"), Qt::LeftButton);
                    continue;
                }
                QCOMPARE(run->pageName(), QString("trial"));
                const int index = run->session()->current().index;
                const QString at = QString("%1, trial %2").arg(who).arg(index + 1);
                const auto secretsNow = [&] {
                    Secrets all = study;
                    const auto stored = w.context().store().trials(code.toStdString());
                    for (auto& [k, v] : trialSecrets(p, stored[static_cast<std::size_t>(index)]))
                        all.emplace(k, v);
                    return all;
                };
                checkScreen(*pw, p, secretsNow(), at + " before the sound");
                QTest::keyClick(run->trialPanel(), Qt::Key_Space);
                QVERIFY2(run->session()->playing(), qPrintable(run->trialMessage()));
                for (int lap = 0; lap < run->session()->lapCount(); ++lap) {
                    checkScreen(*pw, p, secretsNow(), at + QString(", lap %1").arg(lap + 1));
                    QTest::keyClick(run->trialPanel(), Qt::Key_L);
                }
                const Secrets secrets = secretsNow(); // render seed and clip known now
                checkScreen(*pw, p, secrets, at + ", answering");
                checkLayout(*pw, at + ", answering");
                const auto& sections = run->flow()->sections();
                maxQuestions = std::max(maxQuestions, static_cast<int>(sections.size()));
                // Done with nothing answered: refused, and the participant reads why.
                QTest::keyClick(pw, Qt::Key_Return);
                QCOMPARE(run->session()->current().index, index);
                QVERIFY2(!pw->notice().isEmpty(), qPrintable(at));
                // In the participant's words (the protocol's prompts), not the console's.
                QVERIFY2(pw->notice().startsWith("Please answer"), qPrintable(pw->notice()));
                checkScreen(*pw, p, secrets, at + ", Done refused");
                checkLayout(*pw, at + ", Done refused");
                if (!shotsDir_.isEmpty() && static_cast<int>(sections.size()) == maxQuestions)
                    pw->grab().save(QDir(shotsDir_).filePath(name + ".png"));
                // The experimenter's pause.
                QTest::mouseClick(button(run, "Pause or resume"), Qt::LeftButton);
                QVERIFY(pw->visibleTexts().contains("Please wait a moment."));
                checkScreen(*pw, p, secrets, at + ", paused");
                QTest::mouseClick(button(run, "Pause or resume"), Qt::LeftButton);
                // Every question answered, then Done.
                for (const auto& sec : sections) {
                    if (sec.scale)
                        run->flow()->setRating(sec.scale->id, sec.scale->min);
                    else
                        run->flow()->choose(
                            sec.kind,
                            sec.options[static_cast<std::size_t>(index) % sec.options.size()]
                                .letter);
                }
                pw->refresh();
                QVERIFY(pw->notice().isEmpty());
                checkScreen(*pw, p, secrets, at + ", answered");
                QTest::keyClick(pw, Qt::Key_Return);
                QVERIFY2(run->pageName() != "trial" || run->session()->current().index != index,
                         qPrintable(at + ": " + run->trialMessage()));
            }
            QCOMPARE(pw->heading(), QString("Thank you"));
            checkScreen(*pw, p, study, who + ", end");
            QTest::mouseClick(button(run, "Next participant"), Qt::LeftButton);
        }
        qInfo("%s: %zu groups, at most %d questions on one trial screen", qPrintable(name),
              groups.size(), maxQuestions);
        run->closeParticipantWindow();
    }

  private slots:
    void initTestCase() {
        QVERIFY(console_.prepare());
        shotsDir_ = qEnvironmentVariable("UNDERFOOT_CONTRACT_SHOTS");
    }

    void everyScreenOfEveryShippedProtocol() {
        const QDir dir(QString(UNDERFOOT_SOURCE_DIR) + "/protocols");
        const QStringList files = dir.entryList({"*.toml"}, QDir::Files, QDir::Name);
        QVERIFY(files.size() >= 7);
        for (const QString& f : files) {
            runProtocol(dir.filePath(f));
            if (QTest::currentTestFailed()) return;
        }
        qInfo("%lld protocols: %d participant screens searched for %zu distinct strings, none "
              "found; %d trial screens laid out at 1280x800, every question inside",
              static_cast<long long>(files.size()), screens_, searched_.size(), layouts_);
    }
};

QTEST_MAIN(ParticipantContractTest)
#include "test_participant_contract.moc"
