// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/RunTrialPage.h"
#include "app/gui/AnswerPanel.h"
#include "app/gui/Figures.h"
#include "app/gui/QtText.h"
#include "app/gui/WalkerPlayer.h"

#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QShortcut>
#include <QVBoxLayout>

#include <cmath>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {
QPushButton* keyButton(const QString& text, const QString& name, QWidget* parent) {
    auto* b = new QPushButton(text, parent);
    b->setFocusPolicy(Qt::NoFocus); // the page keeps the keys
    b->setAccessibleName(name);
    return b;
}

/// The experimenter's line about what plays: surface, soundscape, modalities, reverb, input.
QString describeStimulus(const exp::TrialRecord& t) {
    const auto& s = t.stimulus;
    QString what = QString("<b>%1</b>").arg(surfaceLabel(s.surface).toHtmlEscaped());
    if (s.soundscape)
        what += RunTrialPage::tr(" · soundscape <b>%1</b>")
                    .arg(soundscapeLabel(*s.soundscape).toHtmlEscaped());
    what += QString(" · %1").arg(q(exp::toString(s.modalities)));
    if (s.reverb) what += RunTrialPage::tr(" · reverb %1").arg(q(*s.reverb));
    if (s.input.kind == exp::InputKind::Walker) {
        QString params;
        try {
            params = q(walkerParametersOf(s).toString());
        } catch (const std::exception&) {
            params = RunTrialPage::tr("protocol parameters");
        }
        what += RunTrialPage::tr(" · virtual walker (%1)").arg(params);
    } else {
        what += RunTrialPage::tr(" · sensor: %1").arg(q(exp::toString(s.input.sensor)));
    }
    return what + RunTrialPage::tr(" · stimulus <tt>%1</tt>, repetition %2")
                      .arg(q(s.id).toHtmlEscaped())
                      .arg(t.repetition);
}
} // namespace

RunTrialPage::RunTrialPage(QWidget* parent) : QWidget(parent) {
    setFocusPolicy(Qt::StrongFocus);
    setAccessibleName(tr("Trial"));
    setAccessibleDescription(tr("Space starts the stimulus; letters choose the answer; digits the "
                                "rating; Enter commits the answer and goes to the next trial"));
    header_ = new QLabel(this);
    header_->setFont(scaledFont(this, 1.5));
    header_->setAccessibleName(tr("Trial number"));
    stimulus_ = new QLabel(this);
    stimulus_->setFont(scaledFont(this, 1.15));
    stimulus_->setWordWrap(true);
    stimulus_->setAccessibleName(tr("What is playing"));
    lockRule_ = new QLabel(this);
    lockRule_->setStyleSheet("color: #505050;");

    auto* meters = new QGroupBox(tr("Walker / sensors"), this);
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
    stepLabel_->setFont(scaledFont(this, 1.3));
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

    startButton_ = keyButton(tr("Start stimulus  (Space)"), tr("Start the stimulus"), this);
    startButton_->setMinimumHeight(44);
    heldLabel_ = new QLabel(tr("PAUSED — Ctrl+P resumes"), this);
    heldLabel_->setStyleSheet("QLabel { background: #ffd7d7; color: #700; padding: 6px; "
                              "font-weight: bold; }");
    heldLabel_->hide();
    faultBanner_ = new QLabel(this);
    faultBanner_->setWordWrap(true);
    faultBanner_->setFont(scaledFont(this, 1.3));
    faultBanner_->setStyleSheet("QLabel { background: #c00; color: white; padding: 10px; "
                                "font-weight: bold; }");
    faultBanner_->setAccessibleName(tr("Sensor fault"));
    faultBanner_->hide();
    protocolStatus_ = new QLabel(this);
    protocolStatus_->setWordWrap(true);
    protocolStatus_->setFont(scaledFont(this, 1.15));
    protocolStatus_->setAccessibleName(tr("Clip and lap status"));
    protocolStatus_->hide();

    AnswerPanelStyle style;
    style.keyHints = true;
    answers_ = new AnswerPanel(style, this);
    connect(answers_, &AnswerPanel::edited, this, [this](const QString& refusal) {
        emit edited(refusal);
        setFocus();
    });
    auto* scroll = new QScrollArea(this);
    scroll->setWidget(answers_);
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setFocusPolicy(Qt::NoFocus);

    comment_ = new QLineEdit(this);
    comment_->setAccessibleName(tr("Comment"));
    comment_->setPlaceholderText(tr("optional; Enter commits the answer, Esc goes back to the "
                                    "answer keys"));
    auto* commentLabel = new QLabel(tr("Co&mment:"), this);
    commentLabel->setBuddy(comment_);
    connect(comment_, &QLineEdit::returnPressed, this, &RunTrialPage::nextClicked);
    auto* esc = new QShortcut(QKeySequence(Qt::Key_Escape), comment_);
    esc->setContext(Qt::WidgetShortcut);
    connect(esc, &QShortcut::activated, this, [this] { setFocus(); });

    nextButton_ =
        keyButton(tr("Next  (Enter)"), tr("Commit the answer and go to the next trial"), this);
    nextButton_->setMinimumHeight(44);
    pauseButton_ = keyButton(tr("Pause  (Ctrl+P)"), tr("Pause or resume"), this);
    auto* exclude = keyButton(tr("Exclude trial…  (Ctrl+E)"), tr("Exclude this trial"), this);
    auto* revise =
        keyButton(tr("Change previous answer  (Ctrl+Z)"), tr("Change the previous answer"), this);
    auto* stop = keyButton(tr("End session for now  (Ctrl+W)"),
                           tr("End the session; it can be resumed"), this);
    message_ = new QLabel(this);
    message_->setWordWrap(true);
    message_->setAccessibleName(tr("Message"));
    for (auto [button, signal] : {std::pair{startButton_, &RunTrialPage::startClicked},
                                  std::pair{nextButton_, &RunTrialPage::nextClicked},
                                  std::pair{pauseButton_, &RunTrialPage::pauseClicked},
                                  std::pair{exclude, &RunTrialPage::excludeClicked},
                                  std::pair{revise, &RunTrialPage::reviseClicked},
                                  std::pair{stop, &RunTrialPage::stopClicked}})
        connect(button, &QPushButton::clicked, this, [this, signal = signal] {
            emit(this->*signal)();
            setFocus();
        });

    planList_ = new QListWidget(this);
    planList_->setFocusPolicy(Qt::NoFocus);
    planList_->setAccessibleName(tr("Trials of this session"));
    planList_->setMaximumWidth(300);

    auto* left = new QVBoxLayout;
    left->addWidget(faultBanner_);
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
    auto* right = new QVBoxLayout;
    right->addWidget(startButton_);
    right->addWidget(heldLabel_);
    right->addWidget(protocolStatus_);
    right->addWidget(meters);
    right->addWidget(planList_, 1);
    auto* row = new QHBoxLayout(this);
    row->addLayout(left, 1);
    row->addLayout(right);
}

void RunTrialPage::keyPressEvent(QKeyEvent* event) {
    if (keys_ && keys_(event))
        event->accept();
    else
        QWidget::keyPressEvent(event);
}

void RunTrialPage::showTrial(exp::TrialFlow& flow, const exp::StudyStore& store) {
    const exp::Session& session = flow.session();
    const exp::TrialRecord& t = session.current();
    const exp::Protocol& p = flow.protocol();
    header_->setText(tr("%1 · participant %2 · group %3")
                         .arg(q(exp::trialLabel(t.index, session.trialCount(), t.practice)))
                         .arg(q(session.participant().code), q(session.participant().groupId)));
    stimulus_->setText(describeStimulus(t));
    lockRule_->setText(p.lock == exp::LockRule::OnAnswer
                           ? tr("Answers are locked once committed (protocol rule).")
                           : tr("The answer can be changed until the next stimulus starts "
                                "(protocol rule); Next commits it now."));
    comment_->clear();
    comment_->setVisible(p.questions.comment);
    answers_->rebuild(&flow);
    answers_->render();
    message_->clear();
    leftMeter_->setValue(0);
    rightMeter_->setValue(0);
    stepLabel_->setText(tr("steps: 0"));
    setStartButton(p.clips.enabled      ? tr("Play clip  (Space)")
                   : p.laps.total() > 0 ? tr("Start condition, lap 1  (Space)")
                                        : tr("Start stimulus  (Space)"),
                   true);
    // The session's plan, with answered trials ticked (1-based numbers, as people read them).
    planList_->clear();
    for (const auto& planned : store.trials(session.participant().code)) {
        auto* item = new QListWidgetItem(
            QString("%1 %2%3 %4")
                .arg(planned.answered ? QString::fromUtf8("\u2713") : QString("  "))
                .arg(planned.index + 1)
                .arg(planned.practice ? tr(" (practice)") : QString())
                .arg(q(planned.stimulus.id)),
            planList_);
        if (planned.excluded) item->setForeground(Qt::gray);
        if (planned.index == t.index) {
            planList_->setCurrentItem(item);
            QFont f = item->font();
            f.setBold(true);
            item->setFont(f);
        }
    }
    setAnswerKeyShown(answerKeyShown_);
}

void RunTrialPage::showRevision(exp::TrialFlow& flow, int index) {
    comment_->setText(q(flow.draft().comment));
    header_->setText(tr("Changing the answer of trial %1 — Enter stores the change, Esc cancels")
                         .arg(index + 1));
    startButton_->setEnabled(false);
    answers_->rebuild(&flow);
    answers_->render();
}

void RunTrialPage::renderDraft(const std::vector<int>& unanswered) {
    answers_->render(unanswered);
}

void RunTrialPage::setAnswerKeyShown(bool shown) {
    answerKeyShown_ = shown;
    stimulus_->setVisible(shown);
    planList_->setVisible(shown);
}

void RunTrialPage::setMessage(const QString& text, bool error) {
    message_->setText(text);
    message_->setStyleSheet(error ? "QLabel { color: #a00; font-weight: bold; }"
                                  : "QLabel { color: #176f2c; }");
}

QString RunTrialPage::message() const {
    return message_->text();
}

void RunTrialPage::setProtocolStatus(const QStringList& lines, bool silent) {
    protocolStatus_->setText(lines.join("\n"));
    protocolStatus_->setStyleSheet(
        silent
            ? "QLabel { background: #e8e8e8; color: #303030; padding: 6px; font-weight: bold; }"
            : "QLabel { background: #dff0ff; color: #0b3d6b; padding: 6px; font-weight: bold; }");
    protocolStatus_->setVisible(!lines.isEmpty());
}

QString RunTrialPage::protocolStatus() const {
    return protocolStatus_->text();
}

void RunTrialPage::setStartButton(const QString& text, bool enabled) {
    startButton_->setText(text);
    startButton_->setEnabled(enabled);
}

void RunTrialPage::setHeld(bool held) {
    held_ = held;
    heldLabel_->setVisible(held);
    pauseButton_->setText(held ? tr("Resume  (Ctrl+P)") : tr("Pause  (Ctrl+P)"));
    answers_->setEnabled(!held && faultBanner_->isHidden());
}

void RunTrialPage::setFault(const QString& text) {
    faultBanner_->setText(text);
    faultBanner_->setVisible(!text.isEmpty());
    answers_->setEnabled(text.isEmpty() && !held_);
    nextButton_->setEnabled(text.isEmpty());
    if (!text.isEmpty()) setStartButton(tr("Paused by a sensor fault"), false);
}

QString RunTrialPage::faultText() const {
    return faultBanner_->isHidden() ? QString() : faultBanner_->text();
}

void RunTrialPage::setEngineText(const QString& text, bool warn) {
    engineLabel_->setText(text);
    engineLabel_->setStyleSheet(warn ? "QLabel { color: #a00; }" : QString());
}

QString RunTrialPage::engineText() const {
    return engineLabel_->text();
}

void RunTrialPage::showMeter(const GrfMeter& m) {
    leftMeter_->setValue(static_cast<int>(std::lround(m.leftBw * 100)));
    rightMeter_->setValue(static_cast<int>(std::lround(m.rightBw * 100)));
    QString step = tr("steps: %1").arg(m.steps);
    if (m.leftStrike) step += QString::fromUtf8("   \u25cf L");
    if (m.rightStrike) step += QString::fromUtf8("   \u25cf R");
    stepLabel_->setText(step);
}

QString RunTrialPage::comment() const {
    return comment_->text().trimmed();
}

void RunTrialPage::setComment(const QString& text) {
    comment_->setText(text);
}

QString RunTrialPage::header() const {
    return header_->text();
}

QString RunTrialPage::stimulusText() const {
    return stimulus_->isHidden() ? QString() : stimulus_->text();
}

} // namespace underfoot::gui
