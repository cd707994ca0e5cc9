// SPDX-License-Identifier: GPL-3.0-or-later
// The Run view's pages and keys: what each key and button asks of the trial flow, and how its
// answer is shown. The session's start, end and sensors are in RunSession.cpp.
#include "app/gui/RunView.h"
#include "app/gui/AudioOutput.h"
#include "app/gui/ConsolePlayer.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/QtText.h"
#include "app/gui/RunStartPage.h"
#include "app/gui/RunTrialPage.h"
#include "app/gui/StudyContext.h"
#include "app/gui/WalkerPlayer.h"

#include "app/wiring/Players.h"

#include <QElapsedTimer>
#include <QInputDialog>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QShortcut>
#include <QStackedWidget>
#include <QTimer>
#include <QVBoxLayout>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {
void addShortcut(QWidget* page, QKeySequence keys, QObject* receiver, std::function<void()> fn) {
    auto* sc = new QShortcut(keys, page);
    sc->setContext(Qt::WidgetWithChildrenShortcut);
    QObject::connect(sc, &QShortcut::activated, receiver, std::move(fn));
}
} // namespace

RunView::RunView(StudyContext& context, QWidget* parent) : QWidget(parent), context_(context) {
    player_ = new WalkerPlayer(this);
    pages_ = new QStackedWidget(this);
    const auto toggleParticipantWindow = [this] {
        if (participantWindow())
            closeParticipantWindow();
        else
            openParticipantWindow();
    };

    start_ = new RunStartPage(context_, pages_);
    pages_->addWidget(start_);
    connect(start_, &RunStartPage::registerRequested, this, &RunView::registerAndStart);
    connect(start_, &RunStartPage::resumeRequested, this,
            [this](const QString& code) { startSession(code); });
    connect(start_, &RunStartPage::renderRequested, this, &RunView::renderClips);
    connect(start_, &RunStartPage::participantWindowRequested, this, toggleParticipantWindow);

    briefingPage_ =
        addMessagePage(briefing_, tr("Start the trials  (Enter)"), tr("Start the trials"), [this] {
            if (!session_ || session_->phase() != exp::SessionPhase::Briefing) return;
            session_->finishBriefing();
            showPhase();
        });
    briefing_->setAlignment(Qt::AlignLeft | Qt::AlignTop);
    briefing_->setTextFormat(Qt::RichText);
    briefing_->setAccessibleName(tr("Briefing"));

    trial_ = new RunTrialPage(pages_);
    pages_->addWidget(trial_);
    trial_->setKeyHandler([this](QKeyEvent* e) { return handleTrialKey(e); });
    connect(trial_, &RunTrialPage::startClicked, this, &RunView::start);
    connect(trial_, &RunTrialPage::nextClicked, this, &RunView::next);
    connect(trial_, &RunTrialPage::pauseClicked, this, &RunView::togglePause);
    connect(trial_, &RunTrialPage::excludeClicked, this, [this] { askExclusion(false); });
    connect(trial_, &RunTrialPage::reviseClicked, this, [this] { revisePrevious(); });
    connect(trial_, &RunTrialPage::stopClicked, this, [this] { closeSession(); });
    connect(trial_, &RunTrialPage::edited, this, [this](const QString& refusal) {
        if (refusal.isEmpty())
            setMessage({}, false);
        else
            setMessage(refusal);
        renderDraft();
    });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::Key_P), this, [this] { togglePause(); });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::Key_E), this, [this] { askExclusion(false); });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_E), this,
                [this] { askExclusion(true); });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::Key_W), this, [this] { closeSession(); });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::Key_L), this, [this] { completeLap(); });
    addShortcut(trial_, QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S), this,
                [this] { resumeAfterSensorFault(); });
    sensorTimer_ = new QTimer(this);
    sensorTimer_->setInterval(100);
    connect(sensorTimer_, &QTimer::timeout, this, [this] { pollSensors(); });

    breakPage_ = addMessagePage(breakLabel_, tr("Continue after the break  (Enter)"),
                                tr("Continue after the break"), [this] {
                                    if (!session_ || session_->phase() != exp::SessionPhase::Break)
                                        return;
                                    session_->finishBreak();
                                    showPhase();
                                });
    breakLabel_->setFont(scaledFont(this, 1.6));
    breakLabel_->setAccessibleName(tr("Break"));
    finishedPage_ = addMessagePage(finishedLabel_, tr("Next participant  (Enter)"),
                                   tr("Next participant"), [this] {
                                       flow_.reset();
                                       session_.reset();
                                       emit flowChanged();
                                       console_.reset();
                                       emit context_.sessionActiveChanged(false);
                                       pages_->setCurrentWidget(start_);
                                       start_->refresh();
                                       start_->codeEdit()->setFocus();
                                   });
    finishedLabel_->setFont(scaledFont(this, 1.4));

    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addWidget(pages_);
    connect(player_, &WalkerPlayer::meter, this, &RunView::onMeter);
    // F11 opens / closes the participant window; Ctrl+K shows / hides the answer key here.
    addShortcut(this, QKeySequence(Qt::Key_F11), this, toggleParticipantWindow);
    addShortcut(this, QKeySequence(Qt::CTRL | Qt::Key_K), this,
                [this] { setAnswerKeyShown(!answerKeyShown_); });
    connect(&context_, &StudyContext::studyChanged, this, [this] {
        start_->setClipFolder({});
        closeSession();
        pages_->setCurrentWidget(start_);
    });
    connect(&context_, &StudyContext::dataChanged, this, [this] {
        if (pages_->currentWidget() == start_) start_->refresh();
    });
    start_->refresh();
}

RunView::~RunView() {
    closeParticipantWindow();
    closeSession();
}

QWidget* RunView::addMessagePage(QLabel*& label, const QString& button, const QString& name,
                                 std::function<void()> action) {
    auto* page = new QWidget(pages_);
    auto* layout = new QVBoxLayout(page);
    label = new QLabel(page);
    label->setAlignment(Qt::AlignCenter);
    label->setWordWrap(true);
    auto* b = new QPushButton(button, page);
    b->setDefault(true);
    b->setMinimumHeight(48);
    b->setAccessibleName(name);
    layout->addWidget(label, 1);
    layout->addWidget(b);
    pages_->addWidget(page);
    connect(b, &QPushButton::clicked, this, std::move(action));
    // Enter presses the page's button.
    for (auto key : {Qt::Key_Return, Qt::Key_Enter})
        addShortcut(page, QKeySequence(key), b, [b] { b->click(); });
    page->setFocusPolicy(Qt::StrongFocus);
    return page;
}

void RunView::showPhase() {
    if (!session_) return;
    const exp::ParticipantScreen screen = flow_->participantScreen();
    switch (session_->phase()) {
    case exp::SessionPhase::Briefing: {
        const auto& p = context_.store().protocol();
        const auto& part = session_->participant();
        int practice = 0;
        for (const auto& t : context_.store().trials(part.code)) practice += t.practice ? 1 : 0;
        // The experimenter's notes only while this screen is not the participant's; what the
        // participant reads is the flow's briefing.
        briefing_->setText(
            tr("<h2>%1</h2><p>Participant <b>%2</b>, group <b>%3</b>, session %4: %5 (%6)."
               "</p>%7<p><b>The participant reads:</b><br>%8</p><p>Press Enter when the "
               "briefing is done.</p>")
                .arg(answerKeyShown_ ? q(p.title).toHtmlEscaped() : tr("Briefing"),
                     q(part.code).toHtmlEscaped(),
                     answerKeyShown_ ? q(part.groupId).toHtmlEscaped() : tr("(hidden)"))
                .arg(session_->sessionNumber())
                .arg(counted(session_->trialCount(), tr("trial"), tr("trials")),
                     counted(practice, tr("practice trial"), tr("practice trials")),
                     answerKeyShown_ && !p.notes.empty()
                         ? tr("<p><b>Experimenter's notes:</b> %1</p>")
                               .arg(q(p.notes).toHtmlEscaped().replace("\n", " "))
                         : QString(),
                     q(screen.text).toHtmlEscaped().replace("\n", "<br>")));
        pages_->setCurrentWidget(briefingPage_);
        briefingPage_->setFocus();
        break;
    }
    case exp::SessionPhase::Practice:
    case exp::SessionPhase::Trial:
        showTrial();
        break;
    case exp::SessionPhase::Break:
        breakLabel_->setText(tr("Break — %1 of %2 answered.\nThe participant may rest. Press "
                                "Enter to continue.")
                                 .arg(screen.answered)
                                 .arg(counted(screen.total, tr("trial"), tr("trials"))));
        pages_->setCurrentWidget(breakPage_);
        breakPage_->setFocus();
        break;
    case exp::SessionPhase::Finished:
        finishedLabel_->setText(tr("Session complete: %1 stored for %2.\nResults are in the "
                                   "Results view (Ctrl+3).")
                                    .arg(counted(screen.answered, tr("answer"), tr("answers")),
                                         q(session_->participant().code)));
        pages_->setCurrentWidget(finishedPage_);
        finishedPage_->setFocus();
        emit context_.sessionActiveChanged(false);
        break;
    }
    emit flowChanged();
}

void RunView::showTrial() {
    flow_->reset();
    trial_->showTrial(*flow_, context_.store());
    trial_->setHeld(flow_->held());
    trial_->setEngineText(audioText() +
                          (lastTrialStats_.isEmpty() ? QString() : "\n" + lastTrialStats_));
    refreshProtocolStatus();
    pages_->setCurrentWidget(trial_);
    trial_->setFocus();
    emit flowChanged();
}

void RunView::renderDraft() {
    if (!flow_) return;
    trial_->renderDraft(flow_->participantScreen().unanswered);
    emit flowChanged();
}

void RunView::refreshProtocolStatus() {
    QStringList lines;
    if (flow_)
        for (const auto& l : flow_->experimenterStatus()) lines << q(l);
    trial_->setProtocolStatus(lines, flow_ && flow_->silentLapNow());
}

void RunView::setMessage(const QString& text, bool error) {
    trial_->setMessage(text, error);
}

/// A refusal of the flow, with the console's key for what to do next.
void RunView::showResult(const exp::FlowResult& r, const QString& done) {
    if (r) {
        setMessage(done, false);
        return;
    }
    const QString why = q(r.message);
    switch (r.refusal) {
    case exp::Refusal::NotStarted:
        setMessage(tr("%1 (Space starts it.)").arg(why));
        break;
    case exp::Refusal::LapsPending:
        setMessage(tr("%1 (L completes a lap.)").arg(why));
        break;
    case exp::Refusal::Incomplete:
        setMessage(tr("Not stored yet: %1. Complete the answer, then press Enter.").arg(why));
        break;
    case exp::Refusal::Paused:
        setMessage(flow_ && flow_->held()
                       ? tr("Paused: press Ctrl+P to resume first.")
                       : tr("Paused by a sensor fault: fix the sensor, then press Ctrl+Shift+S."));
        break;
    case exp::Refusal::Locked:
        setMessage(flow_ && flow_->revising()
                       ? tr("%1 (Enter stores the change, Esc cancels it.)").arg(why)
                       : why);
        break;
    default:
        setMessage(why);
    }
}

bool RunView::handleTrialKey(QKeyEvent* event) {
    if (!flow_ || pages_->currentWidget() != trial_) return false;
    const int key = event->key();
    const auto modifiers = event->modifiers();
    if (key == Qt::Key_Z && modifiers == Qt::ControlModifier) {
        revisePrevious();
        return true;
    }
    if (key == Qt::Key_Escape && flow_->revising()) {
        flow_->cancelRevision();
        showTrial();
        setMessage(tr("Change cancelled; the stored answer is unchanged."), false);
        return true;
    }
    if (modifiers & (Qt::ControlModifier | Qt::AltModifier | Qt::MetaModifier)) return false;
    const auto& protocol = flow_->protocol();
    if (key == Qt::Key_Return || key == Qt::Key_Enter) {
        next();
    } else if (key == Qt::Key_Space) {
        start(); // a playing clip: replayed
    } else if (key == Qt::Key_R && protocol.clips.enabled && !protocol.questions.asksSurface()) {
        replayClip();
    } else if (key == Qt::Key_L && protocol.laps.total() > 0 &&
               !protocol.questions.surfaceOptionByLetter('l')) {
        completeLap();
    } else if (key == Qt::Key_Up || key == Qt::Key_Down) {
        flow_->setActive(flow_->activeSection() + (key == Qt::Key_Down ? 1 : -1));
        renderDraft();
    } else if (key == Qt::Key_Left || key == Qt::Key_Right) {
        flow_->adjust(key == Qt::Key_Right ? 1 : -1);
        renderDraft();
    } else if (const QString text = event->text();
               text.size() == 1 && text.at(0).toLower() >= 'a' && text.at(0).toLower() <= 'z') {
        showResult(flow_->chooseLetter(text.at(0).toLower().toLatin1()));
        renderDraft();
    } else if (text.size() == 1 && text.at(0).isDigit()) {
        const exp::FlowResult r = flow_->typeDigit(text.at(0).digitValue());
        if (r.refusal != exp::Refusal::NotInTrial) showResult(r);
        renderDraft();
    } else {
        return false;
    }
    return true;
}

void RunView::start() {
    if (!flow_) return;
    const bool replay = session_->playing();
    const exp::FlowResult r = flow_->start();
    if (r.refusal == exp::Refusal::Failed) {
        setMessage(tr("%1\nThe stimulus did not start; check the Setup view, then press Space "
                      "again.")
                       .arg(q(r.message)));
        return;
    }
    showResult(r);
    if (!r) return;
    refreshProtocolStatus();
    emit flowChanged();
    if (replay) return;
    const auto& protocol = flow_->protocol();
    trial_->setStartButton(protocol.clips.enabled ? tr("Replay clip  (Space / R)") : tr("Playing…"),
                           protocol.clips.enabled && protocol.clips.replay);
    if (!player_->hasSource())
        trial_->setEngineText(tr("No sensor stream in this build: the stimulus is recorded as "
                                 "started; enter the participant's answer as usual."));
    context_.notifyDataChanged();
}

void RunView::replayClip() {
    if (!flow_) return;
    const exp::FlowResult r = flow_->replay();
    if (r.refusal == exp::Refusal::Failed)
        setMessage(tr("Not replayed: %1").arg(q(r.message)));
    else
        showResult(r);
    refreshProtocolStatus();
    emit flowChanged();
}

void RunView::completeLap() {
    if (!flow_) return;
    const exp::FlowResult r = flow_->completeLap();
    if (r.refusal == exp::Refusal::Failed) {
        setMessage(tr("Lap not stored: %1").arg(q(r.message)));
        return;
    }
    if (!r) {
        showResult(r);
        return;
    }
    refreshProtocolStatus();
    emit flowChanged();
    const QString lap =
        tr("Lap %1 of %2 stored").arg(session_->lapsDone()).arg(session_->lapCount());
    if (console_ && !console_->soundError().empty())
        setMessage(tr("%1, but the sound did not start: %2").arg(lap, q(console_->soundError())));
    else
        setMessage(lap + ".", false);
}

void RunView::next() {
    if (!flow_ || pages_->currentWidget() != trial_) return;
    flow_->setComment(trial_->comment().toStdString());
    if (const auto index = flow_->revising()) {
        const exp::FlowResult r = flow_->commitRevision();
        if (!r) {
            setMessage(tr("Not changed: %1").arg(q(r.message)));
            return;
        }
        context_.notifyDataChanged();
        showTrial();
        setMessage(tr("The answer of trial %1 was changed.").arg(*index + 1), false);
        return;
    }
    const bool wasPaused = session_->paused();
    QElapsedTimer timer;
    timer.start();
    const exp::FlowResult r = flow_->commit();
    if (!r) {
        if (!wasPaused && session_->paused()) {
            showSensorFault(); // the sensor failed while the answer was given
            emit flowChanged();
            return;
        }
        if (r.refusal == exp::Refusal::Failed)
            setMessage(tr("Not stored: %1").arg(q(r.message)));
        else
            showResult(r);
        renderDraft(); // the questions still open are framed on both screens
        return;
    }
    lastCommitMs_ = static_cast<double>(timer.nsecsElapsed()) * 1e-6;
    lastTrialStats_.clear();
    if (const auto* st = console_ ? console_->lastTrialStats() : nullptr; st && st->frames > 0)
        lastTrialStats_ =
            tr("Last trial: %1 s, %2 xruns, callback load %3 % average / %4 % worst, worst "
               "block %5 ms, %6 GRF frames dropped")
                .arg(static_cast<double>(st->frames) / audio_->settings().sampleRateHz, 0, 'f', 1)
                .arg(st->xruns)
                .arg(st->averageLoadPercent, 0, 'f', 1)
                .arg(st->maxLoadPercent, 0, 'f', 1)
                .arg(st->maxBlockSeconds * 1e3, 0, 'f', 2)
                .arg(st->droppedGrfFrames);
    context_.notifyDataChanged();
    showPhase();
    if (pages_->currentWidget() == trial_)
        setMessage(tr("Answer stored (%1 ms).").arg(lastCommitMs_, 0, 'f', 1), false);
}

bool RunView::revisePrevious() {
    if (!flow_ || pages_->currentWidget() != trial_) return false;
    const exp::FlowResult r = flow_->revisePrevious();
    if (!r) {
        showResult(r);
        return false;
    }
    const int index = *flow_->revising();
    trial_->showRevision(*flow_, index);
    setMessage(tr("Trial %1's stored answer is loaded; change it and press Enter.").arg(index + 1),
               false);
    emit flowChanged();
    return true;
}

void RunView::togglePause() {
    if (!flow_ || pages_->currentWidget() != trial_) return;
    if (session_->paused()) {
        setMessage(tr("Paused by a sensor fault: Ctrl+Shift+S resumes once the sensor is back."));
        return;
    }
    const exp::FlowResult r = flow_->held() ? flow_->resume() : flow_->pause();
    player_->setPaused(flow_->held());
    trial_->setHeld(flow_->held());
    if (r)
        setMessage({}, false);
    else
        setMessage(q(r.message));
    emit flowChanged();
}

bool RunView::excludeTrial(const QString& reason, bool previous) {
    if (!flow_ || !context_.hasStudy()) return false;
    if (reason.trimmed().isEmpty()) {
        setMessage(tr("An exclusion needs a reason (e.g. \"participant stopped walking\")."));
        return false;
    }
    std::string why;
    const auto target = flow_->exclusionTarget(previous, &why);
    if (!target) {
        if (previous) setMessage(q(why));
        return false;
    }
    try {
        context_.store().setExcluded(session_->participant().code, *target, true,
                                     reason.trimmed().toStdString());
    } catch (const std::exception& e) {
        setMessage(q(e.what()));
        return false;
    }
    setMessage(tr("Trial %1 excluded: %2 (re-include it in the Study view).")
                   .arg(*target + 1)
                   .arg(reason.trimmed()),
               false);
    context_.notifyDataChanged();
    return true;
}

void RunView::askExclusion(bool previous) {
    if (!flow_ || pages_->currentWidget() != trial_) return;
    bool ok = false;
    const QString reason = QInputDialog::getText(
        this, previous ? tr("Exclude the previous trial") : tr("Exclude this trial"),
        tr("Reason (stored with the trial; the trial is left out of the analysis):"),
        QLineEdit::Normal, QString(), &ok);
    if (ok) excludeTrial(reason, previous);
    trial_->setFocus();
}

} // namespace underfoot::gui
