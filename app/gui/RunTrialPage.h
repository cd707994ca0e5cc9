// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Run view's trial page, as the experimenter sees it: the trial number and participant, the
/// answer key (what is playing, the plan with answered trials ticked; hidden while the
/// participant can see this screen), the protocol's lock rule, the questions (AnswerPanel), the
/// comment, the buttons with their keys, the clip or lap line, the walker's force meters and the
/// audio engine's figures, the sensor-fault banner and the message line. It draws what the Run
/// view gives it and reports clicks; the trial's rules are experiment::TrialFlow's.
#include "experiment/TrialFlow.h"

#include <QWidget>

#include <functional>

class QKeyEvent;
class QLabel;
class QLineEdit;
class QListWidget;
class QProgressBar;
class QPushButton;

namespace underfoot::gui {

class AnswerPanel;
struct GrfMeter;

class RunTrialPage : public QWidget {
    Q_OBJECT
  public:
    explicit RunTrialPage(QWidget* parent = nullptr);

    /// Keys pressed while the page (or a child that ignores them) has focus go to `handler`,
    /// which returns whether it took the key.
    void setKeyHandler(std::function<bool(QKeyEvent*)> handler) { keys_ = std::move(handler); }

    /// Shows the flow's current trial: header, answer key, lock rule, questions, start button
    /// and plan; clears the comment, the meters and the message.
    void showTrial(experiment::TrialFlow& flow, const experiment::StudyStore& store);
    /// Shows the change of the previous answer (trial `index`, 0-based) that the flow has loaded.
    void showRevision(experiment::TrialFlow& flow, int index);
    /// Redraws the draft (checked answers, active and open questions).
    void renderDraft(const std::vector<int>& unanswered = {});
    /// Shows or hides the answer key (stimulus line and plan).
    void setAnswerKeyShown(bool shown);

    void setMessage(const QString& text, bool error = true);
    QString message() const;
    /// The clip / lap lines (hidden when empty); `silent`: a silent baseline lap is walked.
    void setProtocolStatus(const QStringList& lines, bool silent);
    QString protocolStatus() const;
    /// The start button's text and state.
    void setStartButton(const QString& text, bool enabled);
    /// The experimenter's pause: the banner, the button's text, the questions disabled.
    void setHeld(bool held);
    /// The sensor-fault banner (empty text hides it); the questions and Next are disabled while
    /// it shows.
    void setFault(const QString& text);
    QString faultText() const;
    /// The audio line under the meters (`warn`: drawn in red).
    void setEngineText(const QString& text, bool warn = false);
    QString engineText() const;
    void showMeter(const GrfMeter& meter);

    QString comment() const;
    void setComment(const QString& text);
    QString header() const;
    /// The stimulus line ("" while the answer key is hidden).
    QString stimulusText() const;
    AnswerPanel* answers() const { return answers_; }

  signals:
    void startClicked();
    void nextClicked();
    void pauseClicked();
    void excludeClicked();
    void reviseClicked();
    void stopClicked();
    /// The experimenter clicked an answer: `refusal` is the flow's reason when refused.
    void edited(const QString& refusal);

  protected:
    void keyPressEvent(QKeyEvent* event) override;

  private:
    std::function<bool(QKeyEvent*)> keys_;
    bool answerKeyShown_ = true;
    QLabel* header_ = nullptr;
    QLabel* stimulus_ = nullptr;
    QLabel* lockRule_ = nullptr;
    QProgressBar* leftMeter_ = nullptr;
    QProgressBar* rightMeter_ = nullptr;
    QLabel* stepLabel_ = nullptr;
    QLabel* engineLabel_ = nullptr;
    QLabel* protocolStatus_ = nullptr;
    QPushButton* startButton_ = nullptr;
    QPushButton* nextButton_ = nullptr;
    QPushButton* pauseButton_ = nullptr;
    QLabel* heldLabel_ = nullptr;
    QLabel* faultBanner_ = nullptr;
    QLineEdit* comment_ = nullptr;
    QLabel* message_ = nullptr;
    QListWidget* planList_ = nullptr;
    AnswerPanel* answers_ = nullptr;
    bool held_ = false;
};

} // namespace underfoot::gui
