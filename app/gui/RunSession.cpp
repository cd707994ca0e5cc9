// SPDX-License-Identifier: GPL-3.0-or-later
// The Run view's session: registering and starting it (the console's player around the Setup
// view's engine and sensors), closing it, the sensor-fault pause, the audio line, the
// participant window and the screenshots' scripted trials. The pages and the keys are in
// RunView.cpp.
#include "app/gui/AudioOutput.h"
#include "app/gui/ConsolePlayer.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/QtText.h"
#include "app/gui/RunStartPage.h"
#include "app/gui/RunTrialPage.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/WalkerPlayer.h"

#include "base/Version.h"

#include <QCoreApplication>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QStackedWidget>
#include <QTimer>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

// The start page, delegated.

bool RunView::hasResumable() const {
    if (!context_.hasStudy()) return false;
    for (const auto& p : context_.store().participants())
        if (p.status == exp::ParticipantStatus::Active) return true;
    return false;
}
QString RunView::clipFolder() const {
    return start_->clipFolder();
}
void RunView::setClipFolder(const QString& folder) {
    start_->setClipFolder(folder);
}
QStringList RunView::clipProblems() const {
    return start_->clipProblems();
}
bool RunView::renderClips() {
    return !session_ && start_->renderClips();
}
bool RunView::renderingClips() const {
    return start_->rendering();
}
QString RunView::clipStatus() const {
    return start_->clipStatus();
}
QString RunView::startMessage() const {
    return start_->message();
}
QLineEdit* RunView::codeEdit() const {
    return start_->codeEdit();
}
QSpinBox* RunView::ageBox() const {
    return start_->ageBox();
}
QComboBox* RunView::genderBox() const {
    return start_->genderBox();
}
QComboBox* RunView::groupBox() const {
    return start_->groupBox();
}
QListWidget* RunView::resumeList() const {
    return start_->resumeList();
}
QLabel* RunView::resumeBanner() const {
    return start_->resumeBanner();
}

// The trial page, delegated.

QWidget* RunView::trialPanel() const {
    return trial_;
}
QString RunView::trialMessage() const {
    return trial_->message();
}
QString RunView::protocolStatus() const {
    return trial_->protocolStatus();
}
QString RunView::sensorFaultText() const {
    return trial_->faultText();
}
QString RunView::trialHeader() const {
    return trial_->header();
}
QString RunView::stimulusText() const {
    return trial_->stimulusText();
}
QString RunView::briefingText() const {
    return briefing_->text();
}

QString RunView::pageName() const {
    const QWidget* page = pages_->currentWidget();
    return page == start_          ? "start"
           : page == briefingPage_ ? "briefing"
           : page == trial_        ? "trial"
           : page == breakPage_    ? "break"
                                   : "finished";
}

// The session.

bool RunView::registerAndStart() {
    if (!context_.hasStudy()) {
        start_->setMessage(tr("No study open: create or open one in the Study view (Ctrl+1)."));
        return false;
    }
    if (session_) return false;
    const auto np = start_->participantFromForm();
    if (!np) return false;
    try {
        context_.store().registerParticipant(*np);
    } catch (const std::exception& e) {
        start_->setMessage(tr("%1\nNothing was registered; correct the form and press "
                              "Ctrl+Enter again.")
                               .arg(q(e.what())));
        return false;
    }
    start_->clearForm();
    context_.notifyDataChanged();
    return startSession(q(np->code));
}

bool RunView::startSession(const QString& code) {
    if (!context_.hasStudy() || session_) return false;
    exp::SessionSettings settings;
    settings.experimenter = start_->experimenter().toStdString();
    audioError_.clear();
    if (audio_ && autoStartAudio_ && !audio_->running()) audioError_ = audio_->start();
    const auto& protocol = context_.store().protocol();
    if (protocol.clips.enabled) {
        const QStringList problems = clipProblems();
        if (!problems.isEmpty()) {
            start_->setMessage(tr("The clips of this listening test are not ready in %1:\n%2\n"
                                  "Render them (Ctrl+Shift+C) or choose the folder that holds "
                                  "them, then start again.")
                                   .arg(clipFolder(), problems.mid(0, 6).join("\n")));
            return false;
        }
    }
    try {
        engine::LiveEngine* liveEngine =
            engineOverride_ ? engineOverride_ : (audio_ ? audio_->engine() : nullptr);
        console_ = std::make_unique<ConsolePlayer>(
            *player_, liveEngine, context_.path(), protocol,
            protocol.clips.enabled ? clipFolder() : QString(), injected_,
            sensors_ ? sensors_() : LiveSensors{}, code.toStdString());
    } catch (const std::exception& e) {
        start_->setMessage(q(e.what()));
        return false;
    }
    settings.audioConfig =
        console_->live() ? ("underfoot-gui live engine: " + (audio_ && !engineOverride_
                                                                 ? audio_->description()
                                                                 : QString("set by setLiveEngine")))
                               .toStdString()
                         : std::string("underfoot-gui without audio output (walker meters only)");
    settings.sensorConfig = console_->sensorConfig();
    settings.appVersion = underfoot::base::version();
    try {
        session_ = std::make_unique<exp::Session>(context_.store(), code.toStdString(), *console_,
                                                  settings);
    } catch (const std::exception& e) {
        start_->setMessage(q(e.what()));
        context_.notifyDataChanged();
        return false;
    }
    flow_ = std::make_unique<exp::TrialFlow>(context_.store(), *session_);
    start_->setMessage({});
    trial_->setFault({});
    trial_->setHeld(false);
    sensorTimer_->start();
    emit context_.sessionActiveChanged(true);
    context_.notifyDataChanged();
    showPhase();
    return true;
}

void RunView::closeSession() {
    if (!session_) return;
    try {
        if (session_->phase() != exp::SessionPhase::Finished) session_->interrupt();
    } catch (const std::exception&) {
        // The answers are committed already; only the session row's end could not be written.
    }
    flow_.reset();
    session_.reset();
    console_.reset();
    player_->stop();
    player_->setPaused(false);
    sensorTimer_->stop();
    trial_->setHeld(false);
    trial_->setFault({});
    emit context_.sessionActiveChanged(false);
    emit flowChanged();
    if (context_.hasStudy()) context_.notifyDataChanged();
    pages_->setCurrentWidget(start_);
    start_->refresh();
}

QString RunView::audioText() const {
    if (console_ && console_->live())
        return tr("Audio: %1")
            .arg(audio_ && !engineOverride_ ? audio_->description()
                                            : QString("set by setLiveEngine"));
    if (!audioError_.isEmpty())
        return tr("Audio output failed to start, the stimulus is not heard: %1").arg(audioError_);
    return tr("Audio output not started (Setup view, Ctrl+5): the stimulus is not heard; the "
              "meters follow the virtual walker.");
}

bool RunView::pollSensors() {
    if (!session_) return false;
    const bool wasPaused = session_->paused();
    bool paused = wasPaused;
    try {
        paused = session_->checkSensors();
    } catch (const std::exception& e) {
        // Storing the interruption failed; the session is paused all the same.
        setMessage(tr("The interruption could not be stored: %1").arg(q(e.what())));
        paused = session_->paused();
    }
    if (paused && !wasPaused) {
        showSensorFault();
        context_.notifyDataChanged();
        emit flowChanged();
    }
    return paused;
}

void RunView::showSensorFault() {
    trial_->setFault(tr("SENSOR FAULT — trial %1 interrupted, nothing recorded:\n%2\nFix the "
                        "sensor, then press Ctrl+Shift+S (the trial is presented again).")
                         .arg(session_->current().index + 1)
                         .arg(q(session_->pauseReason())));
    setMessage(tr("Answer keys are disabled until the sensor is back."));
}

bool RunView::resumeAfterSensorFault() {
    if (!session_ || !session_->paused()) return false;
    try {
        session_->resumeAfterFault();
    } catch (const std::exception& e) {
        setMessage(tr("Not resumed: %1. Check the connection, then press Ctrl+Shift+S again.")
                       .arg(q(e.what())));
        return false;
    }
    trial_->setFault({});
    showTrial();
    start();
    if (session_->playing())
        setMessage(
            tr("Sensor back: trial %1 is presented again.").arg(session_->current().index + 1),
            false);
    context_.notifyDataChanged();
    return true;
}

void RunView::onMeter(const GrfMeter& m) {
    if (console_ && console_->live() && audio_ && audio_->running()) {
        const auto lm = audio_->meters();
        trial_->setEngineText(tr("Audio: %1 · xruns %2 · callback load %3 % (worst %4 %) · GRF "
                                 "peak %5 N")
                                  .arg(audio_->description())
                                  .arg(lm.xruns)
                                  .arg(lm.loadPercent, 0, 'f', 1)
                                  .arg(lm.maxLoadPercent, 0, 'f', 1)
                                  .arg(static_cast<double>(lm.grfPeakNewtons), 0, 'f', 0),
                              lm.xruns > 0);
    }
    trial_->showMeter(m);
}

// The participant window.

ParticipantWindow* RunView::participantWindow() const {
    return participantWindow_.data();
}

ParticipantWindow* RunView::openParticipantWindow() {
    if (!participantWindow_) {
        participantWindow_ = new ParticipantWindow(); // a top-level window, deleted below
        connect(this, &RunView::flowChanged, participantWindow_.data(), [this] {
            if (participantWindow_) participantWindow_->setFlow(flow_.get());
        });
        connect(participantWindow_.data(), &ParticipantWindow::draftChanged, this, [this] {
            setMessage({}, false);
            renderDraft();
        });
        connect(participantWindow_.data(), &ParticipantWindow::commitRequested, this,
                &RunView::next);
        connect(participantWindow_.data(), &ParticipantWindow::replayRequested, this,
                &RunView::replayClip);
        connect(participantWindow_.data(), &ParticipantWindow::closed, this,
                [this] { setAnswerKeyShown(true); });
    }
    participantWindow_->setFlow(flow_.get());
    const bool ownScreen = participantWindow_->showOnParticipantScreen(window()->screen());
    // Sharing this view's screen: the participant could read the answer key here.
    setAnswerKeyShown(ownScreen);
    return participantWindow_.data();
}

void RunView::closeParticipantWindow() {
    if (!participantWindow_) return;
    participantWindow_->disconnect(this);
    delete participantWindow_.data();
    setAnswerKeyShown(true);
}

void RunView::setAnswerKeyShown(bool shown) {
    answerKeyShown_ = shown;
    trial_->setAnswerKeyShown(shown);
    if (session_ && pages_->currentWidget() == briefingPage_) showPhase();
}

// Screenshots.

bool RunView::startProtocolTrialForScreenshot(int laps) {
    if (!context_.hasStudy()) return false;
    if (context_.store().protocol().clips.enabled && !clipProblems().isEmpty()) {
        if (!renderClips()) return false;
        while (renderingClips()) QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
    }
    start_->fillForm("P001", 24, {}, {}, "demo");
    if (!registerAndStart()) return false;
    if (session_->phase() == exp::SessionPhase::Briefing) session_->finishBriefing();
    showPhase();
    const auto key = [this](int k, char c) {
        QKeyEvent e(QEvent::KeyPress, k, Qt::NoModifier, QString(QChar(c)));
        handleTrialKey(&e);
    };
    key(Qt::Key_Space, ' ');
    if (context_.store().protocol().clips.enabled) key(Qt::Key_R, 'r');
    for (int i = 0; i < laps; ++i) key(Qt::Key_L, 'l');
    key(Qt::Key_7, '7');
    return true;
}

bool RunView::startDemoTrialForScreenshot() {
    start_->fillForm("P001", 27, "female", "trainers", "demo");
    if (!registerAndStart()) return false;
    if (session_->phase() == exp::SessionPhase::Briefing) session_->finishBriefing();
    showPhase();
    start();
    for (auto [k, c] : {std::pair{Qt::Key_B, 'b'}, std::pair{Qt::Key_5, '5'}}) {
        QKeyEvent e(QEvent::KeyPress, k, Qt::NoModifier, QString(QChar(c)));
        handleTrialKey(&e);
    }
    // Let the walker run a little so the meters show a step.
    QElapsedTimer t;
    t.start();
    while (t.elapsed() < 700) QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
    return true;
}

} // namespace underfoot::gui
