// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/RunView.h"
#include "app/gui/Figures.h"
#include "app/gui/QtText.h"
#include "base/Version.h"

#include "app/gui/ConsolePlayer.h"

#include "app/gui/ScaleRow.h"

#include "app/gui/AudioOutput.h"
#include "app/gui/ParticipantWindow.h"
#include "app/gui/StudyContext.h"
#include "app/gui/WalkerPlayer.h"
#include "experiment/Catalogue.h"
#include "experiment/Clips.h"
#ifdef UNDERFOOT_HAVE_WIRING
#include "app/wiring/Adapters.h"
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#endif

#include <QFileDialog>
#include <QFutureWatcher>
#include <QtConcurrent/QtConcurrentRun>

#include <QComboBox>
#include <QCoreApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QFileInfo>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProgressBar>
#include <QPromise>
#include <QPushButton>
#include <QRegularExpressionValidator>
#include <QScrollArea>
#include <QShortcut>
#include <QSpinBox>
#include <QStackedWidget>
#include <QTimer>
#include <QVBoxLayout>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {

enum Page { StartPage, BriefingPage, TrialPage, BreakPage, FinishedPage };

QFont bigFont(const QWidget* w, double factor) {
    QFont f = w->font();
    f.setPointSizeF(f.pointSizeF() * factor);
    return f;
}
} // namespace

/// The trial page: receives the trial keys when it (or a child that ignores them) has focus.
class TrialPanel : public QWidget {
  public:
    TrialPanel(RunView* view, QWidget* parent) : QWidget(parent), view_(view) {
        setFocusPolicy(Qt::StrongFocus);
    }

  protected:
    void keyPressEvent(QKeyEvent* event) override {
        if (view_->handleTrialKey(event->key(), event->modifiers(), event->text()))
            event->accept();
        else
            QWidget::keyPressEvent(event);
    }

  private:
    RunView* view_;
};

RunView::RunView(StudyContext& context, QWidget* parent) : QWidget(parent), context_(context) {
    player_ = new WalkerPlayer(this);
    pages_ = new QStackedWidget(this);
    buildStartPage();

    // Briefing.
    auto* briefingPage = new QWidget(pages_);
    auto* bl = new QVBoxLayout(briefingPage);
    briefing_ = new QLabel(briefingPage);
    briefing_->setWordWrap(true);
    briefing_->setTextFormat(Qt::RichText);
    briefing_->setAccessibleName(tr("Briefing"));
    auto* startTrials = new QPushButton(tr("Start the trials  (Enter)"), briefingPage);
    startTrials->setDefault(true);
    startTrials->setMinimumHeight(48);
    startTrials->setAccessibleName(tr("Start the trials"));
    bl->addWidget(briefing_, 1);
    bl->addWidget(startTrials);
    pages_->addWidget(briefingPage);
    connect(startTrials, &QPushButton::clicked, this, [this] {
        if (!session_ || session_->phase() != exp::SessionPhase::Briefing) return;
        session_->finishBriefing();
        showPhase();
    });

    buildTrialPage();

    // Break.
    auto* breakPage = new QWidget(pages_);
    auto* brl = new QVBoxLayout(breakPage);
    breakLabel_ = new QLabel(breakPage);
    breakLabel_->setAlignment(Qt::AlignCenter);
    breakLabel_->setFont(bigFont(this, 1.6));
    breakLabel_->setAccessibleName(tr("Break"));
    auto* cont = new QPushButton(tr("Continue after the break  (Enter)"), breakPage);
    cont->setMinimumHeight(48);
    cont->setAccessibleName(tr("Continue after the break"));
    brl->addWidget(breakLabel_, 1);
    brl->addWidget(cont);
    pages_->addWidget(breakPage);
    connect(cont, &QPushButton::clicked, this, [this] {
        if (!session_ || session_->phase() != exp::SessionPhase::Break) return;
        session_->finishBreak();
        showPhase();
    });

    // Finished.
    auto* finishedPage = new QWidget(pages_);
    auto* fl = new QVBoxLayout(finishedPage);
    finishedLabel_ = new QLabel(finishedPage);
    finishedLabel_->setAlignment(Qt::AlignCenter);
    finishedLabel_->setFont(bigFont(this, 1.4));
    finishedLabel_->setWordWrap(true);
    auto* again = new QPushButton(tr("Next participant  (Enter)"), finishedPage);
    again->setMinimumHeight(48);
    again->setAccessibleName(tr("Next participant"));
    fl->addWidget(finishedLabel_, 1);
    fl->addWidget(again);
    pages_->addWidget(finishedPage);
    connect(again, &QPushButton::clicked, this, [this] {
        flow_.reset();
        session_.reset();
        emit flowChanged();
        console_.reset();
        emit context_.sessionActiveChanged(false);
        pages_->setCurrentIndex(StartPage);
        refreshStart();
        code_->setFocus();
    });

    // Enter on the briefing, break and finished pages presses their button.
    for (auto [page, button] : {std::pair{briefingPage, startTrials}, std::pair{breakPage, cont},
                                std::pair{finishedPage, again}}) {
        for (auto key : {Qt::Key_Return, Qt::Key_Enter}) {
            auto* sc = new QShortcut(QKeySequence(key), page);
            sc->setContext(Qt::WidgetWithChildrenShortcut);
            connect(sc, &QShortcut::activated, button, &QPushButton::click);
        }
        page->setFocusPolicy(Qt::StrongFocus);
    }

    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addWidget(pages_);
    connect(player_, &WalkerPlayer::meter, this, &RunView::onMeter);
    // F11 opens / closes the participant window; Ctrl+K shows / hides the answer key here.
    auto* scF11 = new QShortcut(QKeySequence(Qt::Key_F11), this);
    scF11->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scF11, &QShortcut::activated, this, [this] {
        if (participantWindow())
            closeParticipantWindow();
        else
            openParticipantWindow();
    });
    auto* scK = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_K), this);
    scK->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scK, &QShortcut::activated, this, [this] { setAnswerKeyShown(!answerKeyShown_); });
    connect(&context_, &StudyContext::studyChanged, this, [this] {
        clipDir_.clear();
        closeSession();
        pages_->setCurrentIndex(StartPage);
    });
    connect(&context_, &StudyContext::dataChanged, this, [this] {
        if (pages_->currentIndex() == StartPage) refreshStart();
    });
    refreshStart();
}

RunView::~RunView() {
    closeParticipantWindow();
    // A clip render in flight stops before its next clip; wait for it (it holds no view data).
    for (auto* w : findChildren<QFutureWatcher<QString>*>()) {
        w->disconnect(this);
        w->cancel();
        w->waitForFinished();
    }
    closeSession();
}

QWidget* RunView::trialPanel() const {
    return trial_;
}
QString RunView::trialMessage() const {
    return message_->text();
}

QString RunView::pageName() const {
    static const char* names[] = {"start", "briefing", "trial", "break", "finished"};
    return names[pages_->currentIndex()];
}

void RunView::buildStartPage() {
    auto* page = new QWidget(pages_);
    auto* reg = new QGroupBox(tr("Register a participant"), page);
    auto* fl = new QFormLayout(reg);
    const auto addRow = [&](const QString& label, QWidget* field, const QString& name) {
        auto* l = new QLabel(label, reg);
        l->setBuddy(field);
        field->setAccessibleName(name);
        fl->addRow(l, field);
    };
    code_ = new QLineEdit(reg);
    code_->setPlaceholderText(tr("pseudonymous code, e.g. P014 (never a name)"));
    code_->setValidator(
        new QRegularExpressionValidator(QRegularExpression("[A-Za-z0-9_.-]{0,32}"), code_));
    code_->setAccessibleDescription(tr("Letters, digits, dot, dash, underscore; up to 32"));
    addRow(tr("&Code:"), code_, tr("Participant code"));
    age_ = new QSpinBox(reg);
    age_->setRange(0, 120);
    age_->setSpecialValueText(tr("not given"));
    addRow(tr("&Age:"), age_, tr("Age in years"));
    gender_ = new QComboBox(reg);
    gender_->setEditable(true);
    gender_->addItems({"", "female", "male", "non-binary", "prefer not to say"});
    addRow(tr("&Gender:"), gender_, tr("Gender"));
    shoes_ = new QLineEdit(reg);
    shoes_->setPlaceholderText(tr("e.g. trainers, leather soles, sandals"));
    addRow(tr("S&hoes:"), shoes_, tr("Shoe type"));
    hearing_ = new QComboBox(reg);
    hearing_->setEditable(true);
    hearing_->addItems({"", "normal (self-reported)", "impairment reported", "tested normal"});
    addRow(tr("Hea&ring:"), hearing_, tr("Hearing"));
    group_ = new QComboBox(reg);
    addRow(tr("Gro&up:"), group_, tr("Group assignment"));
    overrideReason_ = new QLineEdit(reg);
    overrideReason_->setPlaceholderText(tr("needed when a group is chosen by hand"));
    addRow(tr("Override r&eason:"), overrideReason_, tr("Reason for overriding the group"));
    experimenter_ = new QLineEdit(reg);
    experimenter_->setPlaceholderText(tr("recorded with the session"));
    addRow(tr("E&xperimenter:"), experimenter_, tr("Experimenter"));
    auto* registerButton = new QPushButton(tr("Register and start  (Ctrl+Enter)"), reg);
    registerButton->setMinimumHeight(40);
    registerButton->setAccessibleName(tr("Register and start"));
    fl->addRow(registerButton);

    auto* resume = new QGroupBox(tr("Resume or continue a participant"), page);
    auto* rl = new QVBoxLayout(resume);
    resumeBanner_ = new QLabel(resume);
    resumeBanner_->setWordWrap(true);
    resumeBanner_->setStyleSheet("QLabel { background: #fff3cd; color: #5c4400; padding: 8px; "
                                 "border: 1px solid #e0c36a; }");
    resumeBanner_->setAccessibleName(tr("Interrupted session"));
    resumeList_ = new QListWidget(resume);
    resumeList_->setAccessibleName(tr("Participants who have not finished"));
    auto* resumeButton = new QPushButton(tr("Resume selected  (Ctrl+R)"), resume);
    resumeButton->setMinimumHeight(40);
    resumeButton->setAccessibleName(tr("Resume the selected participant"));
    rl->addWidget(resumeBanner_);
    rl->addWidget(resumeList_, 1);
    rl->addWidget(resumeButton);

    startMessage_ = new QLabel(page);
    startMessage_->setWordWrap(true);
    startMessage_->setAccessibleName(tr("Message"));
    startMessage_->setTextInteractionFlags(Qt::TextSelectableByMouse);

    // Listening tests: the pre-rendered clips every participant hears.
    clipBox_ = new QGroupBox(tr("Listening-test clips"), page);
    auto* cl = new QGridLayout(clipBox_);
    clipStatus_ = new QLabel(clipBox_);
    clipStatus_->setWordWrap(true);
    clipStatus_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    clipStatus_->setAccessibleName(tr("Clip status"));
    clipProgress_ = new QProgressBar(clipBox_);
    clipProgress_->setAccessibleName(tr("Clip rendering progress"));
    clipProgress_->hide();
    clipRender_ = new QPushButton(tr("Render clips  (Ctrl+Shift+C)"), clipBox_);
    clipRender_->setAccessibleName(tr("Render the clips of the protocol"));
    auto* clipPick = new QPushButton(tr("Choose clip folder…"), clipBox_);
    clipPick->setAccessibleName(tr("Choose the folder holding the clips"));
    cl->addWidget(clipStatus_, 0, 0, 1, 3);
    cl->addWidget(clipProgress_, 1, 0);
    cl->addWidget(clipRender_, 1, 1);
    cl->addWidget(clipPick, 1, 2);
    cl->setColumnStretch(0, 1);
    connect(clipRender_, &QPushButton::clicked, this, [this] { renderClips(); });
    connect(clipPick, &QPushButton::clicked, this, [this] {
        const QString dir = QFileDialog::getExistingDirectory(this, tr("Clip folder"), clipDir_);
        if (!dir.isEmpty()) setClipFolder(dir);
    });
    auto* scC = new QShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_C), page);
    scC->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scC, &QShortcut::activated, this, [this] { renderClips(); });

    auto* top = new QHBoxLayout;
    top->addWidget(reg, 1);
    top->addWidget(resume, 1);
    auto* pl = new QVBoxLayout(page);
    pl->addLayout(top, 1);
    pl->addWidget(clipBox_);
    auto* participantButton =
        new QPushButton(tr("Participant window (second screen when there is one)  (F11)"), page);
    participantButton->setAccessibleName(tr("Open or close the participant window"));
    participantButton->setToolTip(
        tr("Shows the participant only the briefing, the questions, the answers, the scales and "
           "progress; never the stimulus, the plan or your notes."));
    connect(participantButton, &QPushButton::clicked, this, [this] {
        if (participantWindow())
            closeParticipantWindow();
        else
            openParticipantWindow();
    });
    auto* participantRow = new QHBoxLayout;
    participantRow->addWidget(participantButton);
    participantRow->addStretch();
    pl->addLayout(participantRow);
    pl->addWidget(startMessage_);
    pages_->addWidget(page);

    connect(registerButton, &QPushButton::clicked, this, &RunView::registerAndStart);
    for (auto key : {Qt::Key_Return, Qt::Key_Enter}) {
        auto* sc = new QShortcut(QKeySequence(Qt::CTRL | key), page);
        sc->setContext(Qt::WidgetWithChildrenShortcut);
        connect(sc, &QShortcut::activated, this, &RunView::registerAndStart);
    }
    const auto resumeSelected = [this] {
        auto* item = resumeList_->currentItem();
        if (!item || item->data(Qt::UserRole).toString().isEmpty()) {
            startMessage_->setText(tr("Select a participant in the list first (Up/Down)."));
            return;
        }
        startSession(item->data(Qt::UserRole).toString());
    };
    connect(resumeButton, &QPushButton::clicked, this, resumeSelected);
    connect(resumeList_, &QListWidget::itemActivated, this, resumeSelected);
    auto* scR = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_R), page);
    scR->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scR, &QShortcut::activated, this, resumeSelected);
}

void RunView::buildTrialPage() {
    trial_ = new TrialPanel(this, pages_);
    trial_->setAccessibleName(tr("Trial"));
    trial_->setAccessibleDescription(
        tr("Space starts the stimulus; letters choose the answer; digits the rating; Enter "
           "commits the answer and goes to the next trial"));
    header_ = new QLabel(trial_);
    header_->setFont(bigFont(this, 1.5));
    header_->setAccessibleName(tr("Trial number"));
    stimulus_ = new QLabel(trial_);
    stimulus_->setFont(bigFont(this, 1.15));
    stimulus_->setWordWrap(true);
    stimulus_->setAccessibleName(tr("What is playing"));
    lockRule_ = new QLabel(trial_);
    lockRule_->setStyleSheet("color: #505050;");

    auto* meters = new QGroupBox(tr("Walker / sensors"), trial_);
    auto* ml = new QGridLayout(meters);
    leftMeter_ = new QProgressBar(meters);
    rightMeter_ = new QProgressBar(meters);
    for (auto* m : {leftMeter_, rightMeter_}) {
        m->setRange(0, 150);
        m->setFormat("%v % BW");
        m->setMinimumWidth(120);
    }
    leftMeter_->setAccessibleName(tr("Left foot force"));
    rightMeter_->setAccessibleName(tr("Right foot force"));
    stepLabel_ = new QLabel(meters);
    stepLabel_->setFont(bigFont(this, 1.3));
    stepLabel_->setAccessibleName(tr("Step indicator"));
    engineLabel_ = new QLabel(meters);
    engineLabel_->setWordWrap(true);
    engineLabel_->setAccessibleName(tr("Audio engine status"));
    ml->addWidget(new QLabel(tr("Left GRF"), meters), 0, 0);
    ml->addWidget(leftMeter_, 0, 1);
    ml->addWidget(new QLabel(tr("Right GRF"), meters), 1, 0);
    ml->addWidget(rightMeter_, 1, 1);
    ml->addWidget(stepLabel_, 2, 0, 1, 2);
    ml->addWidget(engineLabel_, 3, 0, 1, 2);
    ml->setColumnStretch(1, 1);
    meters->setMaximumWidth(300);

    playButton_ = new QPushButton(tr("Start stimulus  (Space)"), trial_);
    playButton_->setMinimumHeight(44);
    playButton_->setFocusPolicy(Qt::NoFocus);
    playButton_->setAccessibleName(tr("Start the stimulus"));
    pausedLabel_ = new QLabel(tr("PAUSED — Ctrl+P resumes"), trial_);
    pausedLabel_->setStyleSheet("QLabel { background: #ffd7d7; color: #700; padding: 6px; "
                                "font-weight: bold; }");
    pausedLabel_->hide();
    faultBanner_ = new QLabel(trial_);
    faultBanner_->setWordWrap(true);
    faultBanner_->setFont(bigFont(this, 1.3));
    faultBanner_->setStyleSheet("QLabel { background: #c00; color: white; padding: 10px; "
                                "font-weight: bold; }");
    faultBanner_->setAccessibleName(tr("Sensor fault"));
    faultBanner_->hide();
    sensorTimer_ = new QTimer(this);
    sensorTimer_->setInterval(100);
    connect(sensorTimer_, &QTimer::timeout, this, [this] { pollSensors(); });
    protocolStatus_ = new QLabel(trial_);
    protocolStatus_->setWordWrap(true);
    protocolStatus_->setFont(bigFont(this, 1.15));
    protocolStatus_->setAccessibleName(tr("Clip and lap status"));
    protocolStatus_->hide();

    sectionsHost_ = new QWidget(trial_);
    new QVBoxLayout(sectionsHost_);
    auto* scroll = new QScrollArea(trial_);
    scroll->setWidget(sectionsHost_);
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setFocusPolicy(Qt::NoFocus);

    comment_ = new QLineEdit(trial_);
    comment_->setAccessibleName(tr("Comment"));
    comment_->setPlaceholderText(tr("optional; Enter commits the answer, Esc goes back to the "
                                    "answer keys"));
    auto* commentLabel = new QLabel(tr("Co&mment:"), trial_);
    commentLabel->setBuddy(comment_);

    nextButton_ = new QPushButton(tr("Next  (Enter)"), trial_);
    nextButton_->setMinimumHeight(44);
    nextButton_->setFocusPolicy(Qt::NoFocus);
    nextButton_->setAccessibleName(tr("Commit the answer and go to the next trial"));
    pauseButton_ = new QPushButton(tr("Pause  (Ctrl+P)"), trial_);
    pauseButton_->setFocusPolicy(Qt::NoFocus);
    pauseButton_->setAccessibleName(tr("Pause or resume"));
    auto* exclude = new QPushButton(tr("Exclude trial…  (Ctrl+E)"), trial_);
    exclude->setFocusPolicy(Qt::NoFocus);
    exclude->setAccessibleName(tr("Exclude this trial"));
    auto* revise = new QPushButton(tr("Change previous answer  (Ctrl+Z)"), trial_);
    revise->setFocusPolicy(Qt::NoFocus);
    revise->setAccessibleName(tr("Change the previous answer"));
    connect(revise, &QPushButton::clicked, this, [this] {
        revisePrevious();
        trial_->setFocus();
    });
    auto* stop = new QPushButton(tr("End session for now  (Ctrl+W)"), trial_);
    stop->setFocusPolicy(Qt::NoFocus);
    stop->setAccessibleName(tr("End the session; it can be resumed"));
    message_ = new QLabel(trial_);
    message_->setWordWrap(true);
    message_->setAccessibleName(tr("Message"));

    planList_ = new QListWidget(trial_);
    planList_->setFocusPolicy(Qt::NoFocus);
    planList_->setAccessibleName(tr("Trials of this session"));
    planList_->setMaximumWidth(300);

    auto* left = new QVBoxLayout;
    left->addWidget(header_);
    left->addWidget(stimulus_);
    left->addWidget(lockRule_);
    left->addWidget(scroll, 1);
    auto* commentRow = new QHBoxLayout;
    commentRow->addWidget(commentLabel);
    commentRow->addWidget(comment_, 1);
    left->addLayout(commentRow);
    auto* buttons = new QHBoxLayout;
    buttons->addWidget(nextButton_, 2);
    buttons->addWidget(pauseButton_);
    buttons->addWidget(exclude);
    buttons->addWidget(revise);
    buttons->addWidget(stop);
    left->addLayout(buttons);
    left->addWidget(message_);
    left->insertWidget(0, faultBanner_);
    auto* right = new QVBoxLayout;
    right->addWidget(playButton_);
    right->addWidget(pausedLabel_);
    right->addWidget(protocolStatus_);
    right->addWidget(meters);
    right->addWidget(planList_, 1);
    auto* row = new QHBoxLayout(trial_);
    row->addLayout(left, 1);
    row->addLayout(right);
    pages_->addWidget(trial_);

    connect(playButton_, &QPushButton::clicked, this, [this] {
        if (session_ && session_->playing() && context_.store().protocol().clips.enabled)
            replayClip();
        else
            play();
        trial_->setFocus();
    });
    connect(nextButton_, &QPushButton::clicked, this, &RunView::next);
    connect(pauseButton_, &QPushButton::clicked, this, &RunView::togglePause);
    connect(exclude, &QPushButton::clicked, this, [this] { askExclusion(false); });
    connect(stop, &QPushButton::clicked, this, [this] { closeSession(); });
    connect(comment_, &QLineEdit::returnPressed, this, &RunView::next);
    auto* esc = new QShortcut(QKeySequence(Qt::Key_Escape), comment_);
    esc->setContext(Qt::WidgetShortcut);
    connect(esc, &QShortcut::activated, trial_, [this] { trial_->setFocus(); });
    const auto shortcut = [this](QKeySequence seq, auto fn) {
        auto* sc = new QShortcut(seq, trial_);
        sc->setContext(Qt::WidgetWithChildrenShortcut);
        connect(sc, &QShortcut::activated, this, fn);
    };
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_P), [this] { togglePause(); });
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_E), [this] { askExclusion(false); });
    shortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_E), [this] { askExclusion(true); });
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_W), [this] { closeSession(); });
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_L), [this] { completeLap(); });
    shortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S), [this] { resumeAfterSensorFault(); });
}

bool RunView::hasResumable() const {
    if (!context_.hasStudy()) return false;
    for (const auto& p : context_.store().participants())
        if (p.status == exp::ParticipantStatus::Active) return true;
    return false;
}

void RunView::refreshStart() {
    resumeList_->clear();
    group_->clear();
    resumeBanner_->hide();
    refreshClips();
    if (!context_.hasStudy()) {
        startMessage_->setText(tr("No study open: create or open one in the Study view (Ctrl+1)."));
        return;
    }
    startMessage_->clear();
    const auto& store = context_.store();
    const auto people = store.participants();
    try {
        const QString next = q(store.nextGroup(static_cast<int>(people.size())));
        group_->addItem(tr("balanced assignment (next: %1)").arg(next), QString());
    } catch (const std::exception& e) {
        group_->addItem(tr("balanced assignment"), QString());
        startMessage_->setText(q(e.what()));
    }
    for (const auto& g : store.protocol().groups)
        group_->addItem(tr("override: %1 — %2").arg(q(g.id), q(g.label)), q(g.id));
    const auto counts = store.progressCounts();
    QStringList interrupted;
    for (const auto& p : people) {
        if (p.status == exp::ParticipantStatus::Completed ||
            p.status == exp::ParticipantStatus::Dropped)
            continue;
        const auto it = counts.find(p.code);
        const int answered = it == counts.end() ? 0 : it->second.first;
        const int planned = it == counts.end() ? 0 : it->second.second;
        auto* item = new QListWidgetItem(tr("%1 — group %2 — %3 of %4 answered (%5)")
                                             .arg(q(p.code), q(p.groupId))
                                             .arg(answered)
                                             .arg(planned)
                                             .arg(q(exp::toString(p.status))),
                                         resumeList_);
        item->setData(Qt::UserRole, q(p.code));
        if (p.status == exp::ParticipantStatus::Active) {
            interrupted << tr("%1 at trial %2 of %3").arg(q(p.code)).arg(answered + 1).arg(planned);
            if (!resumeList_->currentItem()) resumeList_->setCurrentItem(item);
        }
    }
    if (resumeList_->count() == 0) {
        auto* item = new QListWidgetItem(tr("Every registered participant has finished (or "
                                            "dropped out). Register the next one on the left."),
                                         resumeList_);
        item->setFlags(Qt::NoItemFlags);
    }
    if (!interrupted.isEmpty()) {
        resumeBanner_->setText(tr("Interrupted session: %1. Every answer given so far is stored. "
                                  "Press Ctrl+R to resume.")
                                   .arg(interrupted.join(", ")));
        resumeBanner_->show();
    }
}

bool RunView::registerAndStart() {
    if (!context_.hasStudy()) {
        startMessage_->setText(tr("No study open: create or open one in the Study view (Ctrl+1)."));
        return false;
    }
    if (session_) return false;
    exp::NewParticipant np;
    np.code = code_->text().trimmed().toStdString();
    if (np.code.empty()) {
        startMessage_->setText(tr("Type the participant's pseudonymous code first (Alt+C)."));
        code_->setFocus();
        return false;
    }
    if (age_->value() > 0) np.age = age_->value();
    np.gender = gender_->currentText().trimmed().toStdString();
    np.shoes = shoes_->text().trimmed().toStdString();
    np.hearing = hearing_->currentText().trimmed().toStdString();
    const QString group = group_->currentData().toString();
    if (!group.isEmpty()) {
        np.groupOverride = group.toStdString();
        np.overrideReason = overrideReason_->text().trimmed().toStdString();
        if (np.overrideReason.empty()) {
            startMessage_->setText(tr("A group chosen by hand needs a reason (Alt+E), or choose "
                                      "balanced assignment."));
            overrideReason_->setFocus();
            return false;
        }
    }
    try {
        context_.store().registerParticipant(np);
    } catch (const std::exception& e) {
        startMessage_->setText(tr("%1\nNothing was registered; correct the form and press "
                                  "Ctrl+Enter again.")
                                   .arg(q(e.what())));
        return false;
    }
    code_->clear();
    age_->setValue(0);
    overrideReason_->clear();
    context_.notifyDataChanged();
    return startSession(q(np.code));
}

bool RunView::startSession(const QString& code) {
    if (!context_.hasStudy() || session_) return false;
    exp::SessionSettings settings;
    settings.experimenter = experimenter_->text().trimmed().toStdString();
    audioError_.clear();
    if (audio_ && autoStartAudio_ && !audio_->running()) audioError_ = audio_->start();
    const auto& protocol = context_.store().protocol();
    if (protocol.clips.enabled) {
        const QStringList problems = clipProblems();
        if (!problems.isEmpty()) {
            startMessage_->setText(tr("The clips of this listening test are not ready in %1:\n%2\n"
                                      "Render them (Ctrl+Shift+C) or choose the folder that "
                                      "holds them, then start again.")
                                       .arg(clipDir_, problems.mid(0, 6).join("\n")));
            return false;
        }
    }
    try {
        engine::LiveEngine* liveEngine =
            engineOverride_ ? engineOverride_ : (audio_ ? audio_->engine() : nullptr);
        console_ = std::make_unique<ConsolePlayer>(*player_, liveEngine, context_.path(), protocol,
                                                   protocol.clips.enabled ? clipDir_ : QString(),
                                                   injected_, sensors_ ? sensors_() : LiveSensors{},
                                                   code.toStdString());
    } catch (const std::exception& e) {
        startMessage_->setText(q(e.what()));
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
        startMessage_->setText(q(e.what()));
        context_.notifyDataChanged();
        return false;
    }
    flow_ = std::make_unique<exp::TrialFlow>(context_.store(), *session_);
    startMessage_->clear();
    paused_ = false;
    faultBanner_->hide();
    sensorTimer_->start();
    emit context_.sessionActiveChanged(true);
    context_.notifyDataChanged();
    showPhase();
    return true;
}

void RunView::showPhase() {
    if (!session_) return;
    const auto& p = context_.store().protocol();
    switch (session_->phase()) {
    case exp::SessionPhase::Briefing: {
        const auto& part = session_->participant();
        int practice = 0;
        for (const auto& t : context_.store().trials(part.code)) practice += t.practice ? 1 : 0;
        // The experimenter's notes (the protocol's description) only while this screen is not
        // the participant's; the participant's briefing is what the participant window shows.
        const QString participantText =
            flow_ ? q(flow_->participantBriefing()).toHtmlEscaped().replace("\n", "<br>")
                  : QString();
        briefing_->setText(
            tr("<h2>%1</h2><p>Participant <b>%2</b>, group <b>%3</b>, session "
               "%4: %5 trials (%6 practice).</p>%7<p><b>The participant reads:</b><br>%8</p>"
               "<p>Press Enter when the briefing is done.</p>")
                .arg(answerKeyShown_ ? q(p.title).toHtmlEscaped() : tr("Briefing"),
                     q(part.code).toHtmlEscaped(),
                     answerKeyShown_ ? q(part.groupId) : tr("(hidden)"))
                .arg(session_->sessionNumber())
                .arg(session_->trialCount())
                .arg(practice)
                .arg(answerKeyShown_ ? tr("<p><b>Experimenter's notes:</b> %1</p>")
                                           .arg(q(p.description).toHtmlEscaped().replace("\n", " "))
                                     : QString(),
                     participantText));
        pages_->setCurrentIndex(BriefingPage);
        pages_->currentWidget()->setFocus();
        break;
    }
    case exp::SessionPhase::Practice:
    case exp::SessionPhase::Trial:
        showTrial();
        break;
    case exp::SessionPhase::Break:
        breakLabel_->setText(tr("Break — %1 of %2 trials answered.\nThe participant may rest. "
                                "Press Enter to continue.")
                                 .arg(session_->answeredCount())
                                 .arg(session_->trialCount()));
        pages_->setCurrentIndex(BreakPage);
        pages_->currentWidget()->setFocus();
        break;
    case exp::SessionPhase::Finished:
        finishedLabel_->setText(tr("Session complete: %1 answers stored for %2.\nResults are in "
                                   "the Results view (Ctrl+3).")
                                    .arg(session_->answeredCount())
                                    .arg(q(session_->participant().code)));
        pages_->setCurrentIndex(FinishedPage);
        pages_->currentWidget()->setFocus();
        emit context_.sessionActiveChanged(false);
        break;
    }
    emit flowChanged();
}

void RunView::showTrial() {
    flow_->reset();
    const auto& t = session_->current();
    const auto& p = context_.store().protocol();
    header_->setText(tr("%1 · participant %2 · group %3")
                         .arg(q(exp::trialLabel(t.index, session_->trialCount(), t.practice)))
                         .arg(q(session_->participant().code), q(session_->participant().groupId)));
    const auto& s = t.stimulus;
    QString what = tr("<b>%1</b>").arg(surfaceLabel(s.surface).toHtmlEscaped());
    if (s.soundscape)
        what += tr(" · soundscape <b>%1</b>").arg(soundscapeLabel(*s.soundscape).toHtmlEscaped());
    what += tr(" · %1").arg(q(exp::toString(s.modalities)));
    if (s.reverb) what += tr(" · reverb %1").arg(q(*s.reverb));
    if (s.input.kind == exp::InputKind::Walker) {
        QString params;
        try {
            params = q(walkerParametersOf(s).toString());
        } catch (const std::exception&) {
            params = tr("protocol parameters");
        }
        what += tr(" · virtual walker (%1)").arg(params);
    } else {
        what += tr(" · sensor: %1").arg(q(exp::toString(s.input.sensor)));
    }
    what += tr(" · stimulus <tt>%1</tt>, repetition %2").arg(q(s.id)).arg(t.repetition);
    stimulus_->setText(what);
    lockRule_->setText(p.lock == exp::LockRule::OnAnswer
                           ? tr("Answers are locked once committed (protocol rule).")
                           : tr("The answer can be changed until the next stimulus starts "
                                "(protocol rule); Next commits it now."));
    comment_->clear();
    rebuildAnswerSections();
    setActive(0);
    message_->clear();
    leftMeter_->setValue(0);
    rightMeter_->setValue(0);
    stepLabel_->setText(tr("steps: 0"));
    playButton_->setEnabled(true);
    playButton_->setText(p.clips.enabled      ? tr("Play clip  (Space)")
                         : p.laps.total() > 0 ? tr("Start condition, lap 1  (Space)")
                                              : tr("Start stimulus  (Space)"));
    refreshProtocolStatus();
    engineLabel_->setText(
        console_ && console_->live()
            ? tr("Audio: %1")
                  .arg(audio_ && !engineOverride_ ? audio_->description()
                                                  : QString("set by setLiveEngine"))
        : !audioError_.isEmpty()
            ? tr("Audio output failed to start, the stimulus is not heard: %1").arg(audioError_)
            : tr("Audio output not started (Setup view, Ctrl+5): the stimulus "
                 "is not heard; the meters follow the virtual walker."));
    if (!lastTrialStats_.isEmpty())
        engineLabel_->setText(engineLabel_->text() + "\n" + lastTrialStats_);
    // The session's plan, with answered trials ticked (1-based numbers, as people read them).
    planList_->clear();
    const auto trials = context_.store().trials(session_->participant().code);
    for (const auto& tr_ : trials) {
        auto* item =
            new QListWidgetItem(QString("%1 %2%3 %4")
                                    .arg(tr_.answered ? QString::fromUtf8("\u2713") : QString("  "))
                                    .arg(tr_.index + 1)
                                    .arg(tr_.practice ? tr(" (practice)") : QString())
                                    .arg(q(tr_.stimulus.id)),
                                planList_);
        if (tr_.excluded) item->setForeground(Qt::gray);
        if (tr_.index == t.index) {
            planList_->setCurrentItem(item);
            QFont f = item->font();
            f.setBold(true);
            item->setFont(f);
        }
    }
    stimulus_->setVisible(answerKeyShown_);
    planList_->setVisible(answerKeyShown_);
    pages_->setCurrentIndex(TrialPage);
    trial_->setFocus();
}

void RunView::rebuildAnswerSections() {
    auto* layout = static_cast<QVBoxLayout*>(sectionsHost_->layout());
    for (auto& s : sections_) delete s.box;
    sections_.clear();
    while (auto* item = layout->takeAt(0)) delete item;
    const auto& q_ = context_.store().protocol().questions;
    for (const exp::AnswerSection& sec : flow_->sections()) {
        Section s;
        s.kind = sec.kind;
        s.scale = sec.scale;
        const int index = static_cast<int>(sections_.size());
        if (sec.kind != SectionKind::Scale) {
            const QString keys =
                sec.kind == SectionKind::Surface
                    ? tr("%1  (keys a–%2)").arg(q(sec.prompt)).arg(QChar(sec.options.back().letter))
                    : tr("%1  (keys a–%2 when this section is active; Down moves here)")
                          .arg(q(sec.prompt))
                          .arg(QChar(sec.options.back().letter));
            s.box = new QGroupBox(keys, sectionsHost_);
            auto* grid = new QGridLayout(s.box);
            std::size_t longest = 0;
            for (const auto& o : sec.options) longest = std::max(longest, o.label.size());
            const int columns = longest > 26 ? 3 : 4; // long labels stay readable at 1280 px
            for (std::size_t i = 0; i < sec.options.size(); ++i) {
                const auto& o = sec.options[i];
                auto* b =
                    new QPushButton(QString("%1   %2").arg(QChar(o.letter)).arg(q(o.label)), s.box);
                b->setCheckable(true);
                b->setFocusPolicy(Qt::NoFocus);
                b->setMinimumHeight(36);
                b->setFont(bigFont(this, 1.1));
                b->setStyleSheet("QPushButton { text-align: left; padding-left: 10px; } "
                                 "QPushButton:checked { background: #1f6feb; color: white; "
                                 "font-weight: bold; }");
                b->setAccessibleName(tr("Answer %1: %2").arg(QChar(o.letter)).arg(q(o.label)));
                const char letter = o.letter;
                const SectionKind kind = sec.kind;
                connect(b, &QPushButton::clicked, this, [this, kind, letter] {
                    chooseOption(kind, letter);
                    trial_->setFocus();
                });
                grid->addWidget(b, static_cast<int>(i) / columns, static_cast<int>(i) % columns);
                s.buttons.push_back(b);
            }
        } else {
            const auto& sc = *sec.scale;
            QStringList anchors;
            for (const auto& a : exp::anchorTexts(sc)) anchors << q(a);
            s.box = new QGroupBox(
                tr("%1  (digits %2–%3)").arg(q(sc.prompt)).arg(sc.min).arg(sc.max), sectionsHost_);
            auto* column = new QVBoxLayout(s.box);
            auto* anchorLabel = new QLabel(anchors.join("   ·   "), s.box);
            anchorLabel->setWordWrap(true);
            anchorLabel->setStyleSheet("color: #404040;");
            anchorLabel->setAccessibleName(tr("Anchors of %1").arg(q(sc.id)));
            column->addWidget(anchorLabel);
            ScaleRowStyle style;
            style.minimumButtonSize = {48, 36};
            style.font = bigFont(this, 1.1);
            s.buttons = addScaleRow(column, s.box, sc, style, [this, index, id = sc.id](int v) {
                flow_->setRating(id, v);
                setActive(index);
                trial_->setFocus();
            });
        }
        layout->addWidget(s.box);
        sections_.push_back(std::move(s));
    }
    layout->addStretch();
    comment_->setVisible(q_.comment);
}

void RunView::setActive(int section) {
    if (!flow_) return;
    flow_->setActive(section);
    renderDraft();
}

void RunView::renderDraft() {
    if (!flow_) return;
    const int active = flow_->activeSection();
    const auto& draft = flow_->draft();
    for (int i = 0; i < static_cast<int>(sections_.size()); ++i) {
        auto& s = sections_[static_cast<std::size_t>(i)];
        s.box->setStyleSheet(
            i == active ? "QGroupBox { border: 2px solid #1f6feb; border-radius: 4px; "
                          "margin-top: 1.4em; font-weight: bold; } QGroupBox::title { "
                          "subcontrol-origin: margin; left: 8px; }"
                        : "QGroupBox { border: 1px solid palette(mid); border-radius: 4px; "
                          "margin-top: 1.4em; } QGroupBox::title { subcontrol-origin: margin; "
                          "left: 8px; }");
        if (s.kind == SectionKind::Scale) {
            const auto it = draft.ratings.find(s.scale->id);
            showScaleValue(s.buttons, *s.scale,
                           it != draft.ratings.end() ? std::optional<int>(it->second)
                                                     : std::nullopt);
        } else {
            const auto& options = flow_->sections()[static_cast<std::size_t>(i)].options;
            const std::string& chosen =
                s.kind == SectionKind::Surface ? draft.answer : draft.soundscapeAnswer;
            for (std::size_t b = 0; b < s.buttons.size(); ++b)
                s.buttons[b]->setChecked(options[b].id == chosen);
        }
    }
    emit flowChanged();
}

void RunView::showFlowResult(const exp::FlowResult& result) {
    if (result)
        message_->clear();
    else
        setMessage(q(result.message));
}

void RunView::chooseOption(SectionKind kind, char letter) {
    showFlowResult(flow_->choose(kind, letter));
    renderDraft();
}

void RunView::typeDigit(int digit) {
    const auto r = flow_->typeDigit(digit);
    if (r.refusal != exp::Refusal::NotAllowed && r.refusal != exp::Refusal::NotInTrial)
        showFlowResult(r);
    renderDraft();
}

void RunView::adjustRating(int delta) {
    flow_->adjust(delta);
    renderDraft();
}

bool RunView::handleTrialKey(int key, Qt::KeyboardModifiers modifiers, const QString& text) {
    if (!session_ || !flow_ || pages_->currentIndex() != TrialPage) return false;
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
    if (session_->paused()) {
        setMessage(tr("Paused by a sensor fault: fix the sensor, then press Ctrl+Shift+S."));
        return true;
    }
    if (key == Qt::Key_Return || key == Qt::Key_Enter) {
        next();
        return true;
    }
    if (paused_) {
        setMessage(tr("Paused: press Ctrl+P to resume first."));
        return true;
    }
    const auto& protocol = context_.store().protocol();
    const bool revising = flow_->revising().has_value();
    if (key == Qt::Key_Space) {
        if (revising)
            setMessage(tr("Store the changed answer (Enter) or cancel (Esc) first."));
        else if (protocol.clips.enabled && session_->playing())
            replayClip();
        else
            play();
        return true;
    }
    if (key == Qt::Key_R && protocol.clips.enabled && !protocol.questions.asksSurface() &&
        !revising) {
        replayClip();
        return true;
    }
    if (key == Qt::Key_L && protocol.laps.total() > 0 &&
        !protocol.questions.surfaceOptionByLetter('l') && !revising) {
        completeLap();
        return true;
    }
    if (key == Qt::Key_Up || key == Qt::Key_Down) {
        setActive(flow_->activeSection() + (key == Qt::Key_Down ? 1 : -1));
        return true;
    }
    if (key == Qt::Key_Left || key == Qt::Key_Right) {
        adjustRating(key == Qt::Key_Right ? 1 : -1);
        return true;
    }
    if (text.size() == 1) {
        const QChar c = text.at(0).toLower();
        if (c >= 'a' && c <= 'z') {
            const auto r = flow_->chooseLetter(c.toLatin1());
            if (r || r.message.rfind("No answer", 0) == 0) showFlowResult(r);
            renderDraft();
            return true;
        }
        if (c >= '0' && c <= '9') {
            typeDigit(c.digitValue());
            return true;
        }
    }
    return false;
}

void RunView::play() {
    if (!session_ || !flow_ || paused_ || session_->paused()) return;
    if (session_->phase() != exp::SessionPhase::Trial &&
        session_->phase() != exp::SessionPhase::Practice)
        return;
    if (session_->playing()) return;
    const exp::FlowResult r = flow_->start();
    if (!r) {
        setMessage(tr("%1\nThe stimulus did not start; check the Setup view, then press Space "
                      "again.")
                       .arg(q(r.message)));
        return;
    }
    const auto& protocol = context_.store().protocol();
    playButton_->setEnabled(protocol.clips.enabled && protocol.clips.replay);
    playButton_->setText(protocol.clips.enabled ? tr("Replay clip  (Space / R)") : tr("Playing…"));
    refreshProtocolStatus();
    if (!player_->hasSource())
        engineLabel_->setText(tr("No sensor stream in this build: the stimulus is recorded as "
                                 "started; enter the participant's answer as usual."));
    emit flowChanged();
    context_.notifyDataChanged();
}

void RunView::next() {
    if (!session_ || !flow_ || pages_->currentIndex() != TrialPage) return;
    if (paused_) {
        setMessage(tr("Paused: press Ctrl+P to resume first."));
        return;
    }
    flow_->setComment(comment_->text().trimmed().toStdString());
    if (const auto index = flow_->revising()) {
        const exp::FlowResult r = flow_->commitRevision();
        if (!r) {
            setMessage(tr("Not changed: %1").arg(q(r.message)));
            return;
        }
        context_.notifyDataChanged();
        showTrial();
        setMessage(tr("The answer of trial %1 was changed.").arg(*index + 1), false);
        emit flowChanged();
        return;
    }
    QElapsedTimer timer;
    timer.start();
    const exp::FlowResult r = flow_->commit();
    switch (r.refusal) {
    case exp::Refusal::None:
        break;
    case exp::Refusal::NotStarted:
        setMessage(tr("Start the stimulus first (Space); the answer belongs to what was heard."));
        return;
    case exp::Refusal::LapsPending:
        setMessage(tr("Lap %1 of %2 is being walked: the questions come after the last lap (L "
                      "completes a lap).")
                       .arg(session_->lapsDone() + 1)
                       .arg(session_->lapCount()));
        return;
    case exp::Refusal::Incomplete:
        setMessage(
            tr("Not stored yet: %1. Complete the answer, then press Enter.").arg(q(r.message)));
        return;
    default:
        if (session_->paused()) {
            showSensorFault();
            emit flowChanged();
            return;
        }
        setMessage(tr("Not stored: %1").arg(q(r.message)));
        return;
    }
    lastCommitMs_ = static_cast<double>(timer.nsecsElapsed()) * 1e-6;
    lastTrialStats_.clear();
#ifdef UNDERFOOT_HAVE_WIRING
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
#endif
    context_.notifyDataChanged();
    showPhase();
    if (pages_->currentIndex() == TrialPage)
        setMessage(tr("Answer stored (%1 ms).").arg(lastCommitMs_, 0, 'f', 1), false);
}

bool RunView::revisePrevious() {
    if (!session_ || !flow_ || pages_->currentIndex() != TrialPage || paused_) return false;
    const exp::FlowResult r = flow_->revisePrevious();
    if (!r) {
        setMessage(q(r.message));
        return false;
    }
    const int index = *flow_->revising();
    comment_->setText(QString::fromStdString(flow_->draft().comment));
    header_->setText(tr("Changing the answer of trial %1 — Enter stores the change, Esc cancels")
                         .arg(index + 1));
    playButton_->setEnabled(false);
    rebuildAnswerSections();
    renderDraft();
    setMessage(tr("Trial %1's stored answer is loaded; change it and press Enter.").arg(index + 1),
               false);
    return true;
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
    }
    return paused;
}

void RunView::showSensorFault() {
    faultBanner_->setText(tr("SENSOR FAULT — trial %1 interrupted, nothing recorded:\n%2\n"
                             "Fix the sensor, then press Ctrl+Shift+S (the trial is presented "
                             "again).")
                              .arg(session_->current().index + 1)
                              .arg(q(session_->pauseReason())));
    faultBanner_->show();
    sectionsHost_->setEnabled(false);
    nextButton_->setEnabled(false);
    playButton_->setEnabled(false);
    playButton_->setText(tr("Paused by a sensor fault"));
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
    faultBanner_->hide();
    nextButton_->setEnabled(true);
    sectionsHost_->setEnabled(!paused_);
    showTrial();
    play();
    if (session_->playing())
        setMessage(
            tr("Sensor back: trial %1 is presented again.").arg(session_->current().index + 1),
            false);
    context_.notifyDataChanged();
    return true;
}

QString RunView::sensorFaultText() const {
    return faultBanner_->isHidden() ? QString() : faultBanner_->text();
}

void RunView::togglePause() {
    if (!session_ || pages_->currentIndex() != TrialPage) return;
    if (session_->paused()) {
        setMessage(tr("Paused by a sensor fault: Ctrl+Shift+S resumes once the sensor is back."));
        return;
    }
    paused_ = !paused_;
    player_->setPaused(paused_);
    pausedLabel_->setVisible(paused_);
    pauseButton_->setText(paused_ ? tr("Resume  (Ctrl+P)") : tr("Pause  (Ctrl+P)"));
    sectionsHost_->setEnabled(!paused_);
    emit flowChanged();
    try {
        context_.store().journal(paused_ ? "paused" : "resumed", session_->participant().code,
                                 session_->current().index, "{}");
    } catch (const std::exception& e) {
        setMessage(q(e.what()));
    }
}

bool RunView::excludeTrial(const QString& reason, bool previous) {
    if (!session_ || !context_.hasStudy()) return false;
    if (reason.trimmed().isEmpty()) {
        setMessage(tr("An exclusion needs a reason (e.g. \"participant stopped walking\")."));
        return false;
    }
    const auto code = session_->participant().code;
    std::string why;
    const auto target = flow_ ? flow_->exclusionTarget(previous, &why) : std::nullopt;
    if (!target) {
        if (previous) setMessage(q(why));
        return false;
    }
    const int index = *target;
    try {
        context_.store().setExcluded(code, index, true, reason.trimmed().toStdString());
    } catch (const std::exception& e) {
        setMessage(q(e.what()));
        return false;
    }
    setMessage(tr("Trial %1 excluded: %2 (re-include it in the Study view).")
                   .arg(index + 1)
                   .arg(reason.trimmed()),
               false);
    context_.notifyDataChanged();
    return true;
}

void RunView::askExclusion(bool previous) {
    if (!session_ || pages_->currentIndex() != TrialPage) return;
    bool ok = false;
    const QString reason = QInputDialog::getText(
        this, previous ? tr("Exclude the previous trial") : tr("Exclude this trial"),
        tr("Reason (stored with the trial; the trial is left out of the analysis):"),
        QLineEdit::Normal, QString(), &ok);
    if (ok) excludeTrial(reason, previous);
    trial_->setFocus();
}

void RunView::onMeter(const GrfMeter& m) {
    if (console_ && console_->live() && audio_ && audio_->running()) {
        const auto lm = audio_->meters();
        engineLabel_->setText(tr("Audio: %1 · xruns %2 · callback load %3 % (worst %4 %) · GRF "
                                 "peak %5 N")
                                  .arg(audio_->description())
                                  .arg(lm.xruns)
                                  .arg(lm.loadPercent, 0, 'f', 1)
                                  .arg(lm.maxLoadPercent, 0, 'f', 1)
                                  .arg(static_cast<double>(lm.grfPeakNewtons), 0, 'f', 0));
        engineLabel_->setStyleSheet(lm.xruns > 0 ? "QLabel { color: #a00; }" : QString());
    }
    leftMeter_->setValue(static_cast<int>(std::lround(m.leftBw * 100)));
    rightMeter_->setValue(static_cast<int>(std::lround(m.rightBw * 100)));
    QString step = tr("steps: %1").arg(m.steps);
    if (m.leftStrike) step += QString::fromUtf8("   \u25cf L");
    if (m.rightStrike) step += QString::fromUtf8("   \u25cf R");
    stepLabel_->setText(step);
}

void RunView::setMessage(const QString& text, bool error) {
    message_->setText(text);
    message_->setStyleSheet(error ? "QLabel { color: #a00; font-weight: bold; }"
                                  : "QLabel { color: #176f2c; }");
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
    paused_ = false;
    pausedLabel_->hide();
    sensorTimer_->stop();
    faultBanner_->hide();
    sectionsHost_->setEnabled(true);
    emit context_.sessionActiveChanged(false);
    emit flowChanged();
    if (context_.hasStudy()) context_.notifyDataChanged();
    pages_->setCurrentIndex(StartPage);
    refreshStart();
}

void RunView::refreshClips() {
    const bool clips = context_.hasStudy() && context_.store().protocol().clips.enabled;
    clipBox_->setVisible(clips);
    if (!clips) {
        clipDir_.clear();
        return;
    }
    if (clipDir_.isEmpty())
        clipDir_ =
            QFileInfo(context_.path()).dir().filePath("clips/" + q(context_.store().protocol().id));
    clipRender_->setEnabled(!rendering_);
    if (rendering_) return;
    const QStringList problems = clipProblems();
    clipStatus_->setText(
        problems.isEmpty()
            ? tr("%1 clips ready in %2 (manifest checked: every file as rendered).")
                  .arg(exp::readClipManifest(clipDir_.toStdString()).size())
                  .arg(clipDir_)
            : tr("Clips not ready in %1 — %2%3. Render them (Ctrl+Shift+C) or choose the folder "
                 "that holds them.")
                  .arg(clipDir_, problems.front())
                  .arg(problems.size() > 1 ? tr(" (and %1 more)").arg(problems.size() - 1)
                                           : QString()));
    clipStatus_->setStyleSheet(problems.isEmpty() ? "color: #0a5c0a;" : "color: #8a1c00;");
}

void RunView::setClipFolder(const QString& folder) {
    clipDir_ = folder;
    refreshClips();
}

QStringList RunView::clipProblems() const {
    QStringList out;
    if (!context_.hasStudy() || !context_.store().protocol().clips.enabled) return out;
    try {
        for (const auto& p : exp::checkClips(context_.store().protocol(), clipDir_.toStdString()))
            out << q(p);
    } catch (const std::exception& e) {
        out << q(e.what());
    }
    return out;
}

QString RunView::startMessage() const {
    return startMessage_->text();
}

QString RunView::clipStatus() const {
    return clipStatus_->text();
}

bool RunView::renderClips() {
    if (rendering_ || session_ || !context_.hasStudy() ||
        !context_.store().protocol().clips.enabled)
        return false;
#ifdef UNDERFOOT_HAVE_WIRING
    rendering_ = true;
    clipRender_->setEnabled(false);
    clipProgress_->setRange(0, 0);
    clipProgress_->show();
    clipStatus_->setText(tr("Rendering the clips into %1…").arg(clipDir_));
    clipStatus_->setStyleSheet({});
    // The worker gets its own copy of the protocol: the study may be closed meanwhile.
    auto protocol = std::make_shared<exp::Protocol>(context_.store().protocol());
    const std::string dir = clipDir_.toStdString();
    auto* watcher = new QFutureWatcher<QString>(this);
    connect(watcher, &QFutureWatcher<QString>::progressRangeChanged, clipProgress_,
            &QProgressBar::setRange);
    connect(watcher, &QFutureWatcher<QString>::progressValueChanged, clipProgress_,
            &QProgressBar::setValue);
    connect(watcher, &QFutureWatcher<QString>::finished, this, [this, watcher] {
        const QString error = watcher->future().resultCount() > 0 ? watcher->result() : QString();
        watcher->deleteLater();
        rendering_ = false;
        clipProgress_->hide();
        refreshClips();
        if (!error.isEmpty()) {
            clipStatus_->setText(tr("Rendering failed: %1").arg(error));
            clipStatus_->setStyleSheet("color: #8a1c00;");
        }
    });
    // Progress goes through the promise (thread-safe); a cancelled future (view closing) stops
    // before the next clip.
    watcher->setFuture(QtConcurrent::run([protocol, dir](QPromise<QString>& promise) {
        try {
            wiring::renderClipFolder(*protocol, dir, 48000.0,
                                     [&promise](int done, int total, const std::string&) {
                                         promise.setProgressRange(0, total);
                                         promise.setProgressValue(done);
                                         return !promise.isCanceled();
                                     });
            promise.addResult(QString());
        } catch (const std::exception& e) {
            promise.addResult(QString::fromStdString(e.what()));
        }
    }));
    return true;
#else
    clipStatus_->setText(tr("This build has no engine wiring: render the clips with `underfoot "
                            "clips -p PROTOCOL -o %1`, then start.")
                             .arg(clipDir_));
    return false;
#endif
}

QString RunView::protocolStatus() const {
    return protocolStatus_->text();
}

void RunView::refreshProtocolStatus() {
    if (!session_ || !flow_ ||
        (session_->phase() != exp::SessionPhase::Trial &&
         session_->phase() != exp::SessionPhase::Practice)) {
        protocolStatus_->hide();
        return;
    }
    QStringList lines;
    for (const auto& l : flow_->experimenterStatus()) lines << q(l);
    protocolStatus_->setText(lines.join("\n"));
    protocolStatus_->setStyleSheet(
        flow_->silentLapNow()
            ? "QLabel { background: #e8e8e8; color: #303030; padding: 6px; font-weight: bold; }"
            : "QLabel { background: #dff0ff; color: #0b3d6b; padding: 6px; font-weight: bold; }");
    protocolStatus_->setVisible(!lines.isEmpty());
    emit flowChanged();
}

void RunView::completeLap() {
    if (!session_ || !flow_ || session_->lapCount() == 0) return;
    if (paused_) {
        setMessage(tr("Paused: press Ctrl+P to resume first."));
        return;
    }
    const exp::FlowResult r = flow_->completeLap();
    if (r.refusal == exp::Refusal::NotStarted) {
        setMessage(tr("Start the condition first (Space), then L after each lap."));
        return;
    }
    if (r.refusal == exp::Refusal::NotAllowed) {
        setMessage(tr("All %1 laps are done; enter the answers and press Enter.")
                       .arg(session_->lapCount()));
        return;
    }
    if (!r) {
        setMessage(tr("Lap not stored: %1").arg(q(r.message)));
        return;
    }
    refreshProtocolStatus();
    if (console_ && !console_->soundError().empty()) {
        setMessage(tr("Lap %1 of %2 stored, but the sound did not start: %3")
                       .arg(session_->lapsDone())
                       .arg(session_->lapCount())
                       .arg(q(console_->soundError())));
        return;
    }
    setMessage(tr("Lap %1 of %2 stored.").arg(session_->lapsDone()).arg(session_->lapCount()),
               false);
}

void RunView::replayClip() {
    if (!session_ || !flow_ || !context_.store().protocol().clips.enabled) return;
    if (!session_->playing()) {
        play();
        return;
    }
    const exp::FlowResult r = flow_->replay();
    if (r.refusal == exp::Refusal::NotAllowed) {
        setMessage(q(r.message));
        return;
    }
    if (!r) {
        setMessage(tr("Not replayed: %1").arg(q(r.message)));
        return;
    }
    refreshProtocolStatus();
}

bool RunView::startProtocolTrialForScreenshot(int laps) {
    if (!context_.hasStudy()) return false;
    if (context_.store().protocol().clips.enabled && !clipProblems().isEmpty()) {
        if (!renderClips()) return false;
        while (rendering_) QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
    }
    code_->setText("P001");
    age_->setValue(24);
    experimenter_->setText("demo");
    if (!registerAndStart()) return false;
    if (session_->phase() == exp::SessionPhase::Briefing) session_->finishBriefing();
    showPhase();
    handleTrialKey(Qt::Key_Space, Qt::NoModifier, " ");
    if (context_.store().protocol().clips.enabled) handleTrialKey(Qt::Key_R, Qt::NoModifier, "r");
    for (int i = 0; i < laps; ++i) handleTrialKey(Qt::Key_L, Qt::NoModifier, "l");
    handleTrialKey(Qt::Key_7, Qt::NoModifier, "7");
    return true;
}

bool RunView::startDemoTrialForScreenshot() {
    code_->setText("P001");
    age_->setValue(27);
    gender_->setCurrentText("female");
    shoes_->setText("trainers");
    experimenter_->setText("demo");
    if (!registerAndStart()) return false;
    if (session_->phase() == exp::SessionPhase::Briefing) session_->finishBriefing();
    showPhase();
    play();
    handleTrialKey(Qt::Key_B, Qt::NoModifier, "b");
    handleTrialKey(Qt::Key_5, Qt::NoModifier, "5");
    // Let the walker run a little so the meters show a step.
    QElapsedTimer t;
    t.start();
    while (t.elapsed() < 700) QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
    return true;
}

} // namespace underfoot::gui

namespace underfoot::gui {

ParticipantWindow* RunView::participantWindow() const {
    return participantWindow_.data();
}

ParticipantWindow* RunView::openParticipantWindow() {
    if (!participantWindow_) {
        participantWindow_ = new ParticipantWindow(); // a top-level window, deleted below
        connect(this, &RunView::flowChanged, participantWindow_.data(), [this] {
            if (!participantWindow_) return;
            participantWindow_->setHeld(paused_);
            participantWindow_->setFlow(flow_.get());
        });
        connect(participantWindow_.data(), &ParticipantWindow::draftChanged, this, [this] {
            renderDraft();
            message_->clear();
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
    stimulus_->setVisible(shown);
    planList_->setVisible(shown);
    if (session_ && pages_->currentIndex() == BriefingPage) showPhase();
}

QString RunView::trialHeader() const {
    return header_->text();
}

QString RunView::stimulusText() const {
    return stimulus_->isHidden() ? QString() : stimulus_->text();
}

QString RunView::briefingText() const {
    return briefing_->text();
}

} // namespace underfoot::gui
