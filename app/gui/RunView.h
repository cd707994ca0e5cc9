// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Run view: register a participant (pseudonymous code, demographics, group) or resume an
/// interrupted session (RunStartPage), then run the trials from the keyboard (RunTrialPage).
///
/// Keyboard map of a trial (also shown on the buttons):
///   Space         start the stimulus            a–p     surface answer (soundscape answer
///   1–9, 0        rating of the active scale            when its section is active)
///   Up / Down     previous / next answer section Left / Right  lower / raise the active rating
///   Enter         Next: commit the answer        Alt+M   comment field (Esc leaves it)
///   Ctrl+P        pause / resume                 Ctrl+E  exclude this trial (with a reason)
///   Ctrl+Shift+E  exclude the previous trial     Ctrl+W  end the session for now (resumable)
///   Ctrl+Shift+S  resume after a sensor fault (refused while the sensor still fails; the
///                 interrupted trial is then presented again)
///   Ctrl+Z        change the previous answer (only under lock = "next_trial", before the next
///                 stimulus starts; Enter stores the change, Esc cancels)
/// Listening tests ([clips]): Space presents the clip, Space or R replays it (counted); only the
/// scales asked in this block are shown. Lap protocols ([laps]): L (or Ctrl+L when L is an
/// answer letter) completes the lap being walked; Next is refused until every lap is done.
/// Every answer is committed to the study file (durably) by Next before anything else happens.
///
/// This view is an adapter of experiment::TrialFlow: it maps keys and buttons onto the flow's
/// calls and shows the flow's refusals with the console's keys; the rules (answer draft,
/// validation, lock rule, laps, clip replays, the pause, what the participant may see) are the
/// flow's. The participant window (ParticipantWindow, F11) draws the same flow for the
/// participant; while it shares the screen with this view, the answer key (stimulus, plan,
/// group, notes) is hidden here.
#include "experiment/Session.h"
#include "experiment/TrialFlow.h"

#include <QPointer>
#include <QWidget>

#include <functional>
#include <memory>

class QComboBox;
class QKeyEvent;
class QLabel;
class QLineEdit;
class QListWidget;
class QSpinBox;
class QStackedWidget;
class QTimer;

namespace underfoot::engine {
class SerialSource;
class OscGyroReceiver;
class LiveEngine;
} // namespace underfoot::engine

namespace underfoot::gui {

/// The sensors a session may use (the Setup view's connections; null when not connected).
struct LiveSensors {
    /// Connected, started FSR shoes; a session takes their frames while it runs.
    std::shared_ptr<engine::SerialSource> shoes;
    /// The listening OSC gyroscope receiver (water stimuli with the gyro input).
    std::shared_ptr<engine::OscGyroReceiver> gyros;
    /// Folder of the participants' step thresholds (`<code>.toml`; defaults when absent).
    QString thresholdsDir;
};

class StudyContext;
class WalkerPlayer;
struct GrfMeter;
class AudioOutput;
class ConsolePlayer;
class ParticipantWindow;
class RunStartPage;
class RunTrialPage;

class RunView : public QWidget {
    Q_OBJECT
  public:
    explicit RunView(StudyContext& context, QWidget* parent = nullptr);
    ~RunView() override;

    /// Whether the open study has a participant whose session was interrupted.
    bool hasResumable() const;
    /// Registers the participant described by the form and starts the session.
    bool registerAndStart();
    /// Starts (or resumes) the session of an existing participant.
    bool startSession(const QString& code);
    /// Ends the running session as interrupted (answers are already stored); no-op otherwise.
    void closeSession();
    /// Excludes the current (or, with `previous`, the last answered) trial with `reason`.
    bool excludeTrial(const QString& reason, bool previous = false);
    /// Loads the previous trial's answer for a change (lock rule permitting); false with the
    /// reason in the message line otherwise.
    bool revisePrevious();
    /// The trial whose answer is being changed (stored index), or -1.
    int revising() const { return flow_ && flow_->revising() ? *flow_->revising() : -1; }
    /// Folder of the listening-test clips of the open study (default: `clips/<protocol id>`
    /// next to the study file; empty when the protocol has no [clips]).
    QString clipFolder() const;
    /// Uses `folder` for the clips (checked at the next session start).
    void setClipFolder(const QString& folder);
    /// Problems that stop the listening test from starting (empty: the clips are ready).
    QStringList clipProblems() const;
    /// Renders the protocol's clips into clipFolder() on a worker thread (progress bar on the
    /// start page). Returns false when already rendering, a session runs or the protocol has no
    /// [clips].
    bool renderClips();
    /// Whether clips are being rendered.
    bool renderingClips() const;
    /// The clip status line of the start page.
    QString clipStatus() const;
    /// The message line of the start page.
    QString startMessage() const;
    /// The lap / clip line of the trial page.
    QString protocolStatus() const;
    /// For screenshots: registers a scratch participant and shows a trial with an answer chosen.
    bool startDemoTrialForScreenshot();
    /// For screenshots of listening / lap protocols: renders the clips when needed (waiting),
    /// registers a participant, presents the clip (or walks `laps` laps) and types a rating.
    bool startProtocolTrialForScreenshot(int laps);

    /// Plays stimuli through `output`'s live engine while it runs (the walker meters otherwise).
    /// With `autoStart`, a session start also starts the output (a failure is shown, the
    /// session runs without sound).
    void setAudioOutput(AudioOutput* output, bool autoStart) {
        audio_ = output;
        autoStartAudio_ = autoStart;
    }
    /// Presents the stimuli of the next sessions through `player` instead of the live engine
    /// (another front end's player, or a test double); null restores the default. Not owned.
    void setStimulusPlayer(experiment::StimulusPlayer* player) { injected_ = player; }
    /// Where a session start finds the connected sensors (MainWindow: the Setup view's).
    void setSensorProvider(std::function<LiveSensors()> provider) {
        sensors_ = std::move(provider);
    }
    /// Plays through `engine` instead of the audio output's (tests: an engine driven offline);
    /// null restores the default. Not owned.
    void setLiveEngine(engine::LiveEngine* engine) { engineOverride_ = engine; }
    /// Asks the session whether the sensors of the playing trial failed (what the 100 ms timer
    /// does while a trial plays); on a fault shows the banner. Returns whether it is paused.
    bool pollSensors();
    /// Resumes after a sensor fault (Ctrl+Shift+S) and presents the interrupted trial again;
    /// false with the reason in the message line while the sensor still fails.
    bool resumeAfterSensorFault();
    /// The sensor-fault banner's text ("" when hidden).
    QString sensorFaultText() const;
    /// The running session (nullptr when none).
    experiment::Session* session() const { return session_.get(); }
    /// The running session's trial flow (nullptr when none).
    experiment::TrialFlow* flow() const { return flow_.get(); }

    /// Opens the participant window (full screen on a second screen when there is one, else a
    /// window over this one) and returns it; F11 toggles it. While it shares this view's screen
    /// the answer key is hidden here (Ctrl+K shows it again for the experimenter).
    ParticipantWindow* openParticipantWindow();
    void closeParticipantWindow();
    /// The participant window (nullptr when not open).
    ParticipantWindow* participantWindow() const;
    /// Whether this view shows the answer key (stimulus, its details, the plan, the notes).
    bool answerKeyShown() const { return answerKeyShown_; }
    void setAnswerKeyShown(bool shown);
    /// The texts of the trial page's header and stimulus line (tests).
    QString trialHeader() const;
    QString stimulusText() const;
    /// The briefing page's text.
    QString briefingText() const;

    /// The widget that receives the trial keys (answer letters, digits, Enter, Space).
    QWidget* trialPanel() const;
    /// Milliseconds the last Next took to commit the answer to the store.
    double lastCommitMs() const { return lastCommitMs_; }
    /// The message line of the trial page (errors say what to do next).
    QString trialMessage() const;
    /// Which page is shown: "start", "briefing", "trial", "break", "finished".
    QString pageName() const;

    // Form fields (exposed for tests).
    QLineEdit* codeEdit() const;
    QSpinBox* ageBox() const;
    QComboBox* genderBox() const;
    QComboBox* groupBox() const;
    QListWidget* resumeList() const;
    QLabel* resumeBanner() const;

  signals:
    /// The session, the trial or the draft changed (the participant window refreshes).
    void flowChanged();

  private:
    QWidget* addMessagePage(QLabel*& label, const QString& button, const QString& name,
                            std::function<void()> action);
    void showPhase();
    void showTrial();
    void showResult(const experiment::FlowResult& result, const QString& done = {});
    void renderDraft();
    void refreshProtocolStatus();
    bool handleTrialKey(QKeyEvent* event);
    void start();
    void replayClip();
    void completeLap();
    void next();
    void togglePause();
    void showSensorFault();
    void askExclusion(bool previous);
    void onMeter(const GrfMeter& meter);
    void setMessage(const QString& text, bool error = true);
    QString audioText() const;

    StudyContext& context_;
    WalkerPlayer* player_ = nullptr;
    AudioOutput* audio_ = nullptr;
    bool autoStartAudio_ = false;
    QString audioError_;
    std::unique_ptr<ConsolePlayer> console_;
    std::function<LiveSensors()> sensors_;
    engine::LiveEngine* engineOverride_ = nullptr;
    experiment::StimulusPlayer* injected_ = nullptr;
    std::unique_ptr<experiment::Session> session_;
    std::unique_ptr<experiment::TrialFlow> flow_;
    QPointer<ParticipantWindow> participantWindow_;
    bool answerKeyShown_ = true;

    QStackedWidget* pages_ = nullptr;
    RunStartPage* start_ = nullptr;
    RunTrialPage* trial_ = nullptr;
    QWidget* briefingPage_ = nullptr;
    QWidget* breakPage_ = nullptr;
    QWidget* finishedPage_ = nullptr;
    QLabel* briefing_ = nullptr;
    QLabel* breakLabel_ = nullptr;
    QLabel* finishedLabel_ = nullptr;
    QTimer* sensorTimer_ = nullptr;

    double lastCommitMs_ = 0;
    QString lastTrialStats_; ///< the live engine's figures of the trial just answered
};

} // namespace underfoot::gui
