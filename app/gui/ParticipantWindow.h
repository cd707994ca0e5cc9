// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The participant's window: full screen on a second screen when there is one, drawing only
/// experiment::TrialFlow::participantScreen() — the briefing, the questions with their answers
/// and every anchor, progress, breaks, what to do now, and why Done was refused (the questions
/// still open, framed in red). Never the stimulus (its id, surface, soundscape, input, clip),
/// the order of the plan, the group or the experimenter's notes: those stay in the Run view.
///
/// The participant answers by pointer (buttons) or keys (letters, digits, Up/Down, Left/Right,
/// Enter commits, Space or R asks to hear the clip again); the keys go to the flow, which
/// decides. The experimenter's Run view shows the same draft and keeps control (start, laps,
/// breaks, pause, exclusions). At 1280×800 every question of the shipped protocols fits without
/// scrolling (tests/gui/test_participant_contract.cpp).
#include <QWidget>

class QLabel;
class QProgressBar;
class QPushButton;
class QScreen;
class QScrollArea;

namespace underfoot::experiment {
class TrialFlow;
}

namespace underfoot::gui {

class AnswerPanel;

class ParticipantWindow : public QWidget {
    Q_OBJECT
  public:
    explicit ParticipantWindow(QWidget* parent = nullptr);

    /// Shows `flow` (null: a waiting page). Not owned; call again whenever it changes.
    void setFlow(experiment::TrialFlow* flow);
    /// Redraws from the flow's participant screen.
    void refresh();
    /// Shows the window full screen on a screen other than `experimenterScreen` when there is
    /// one (returns true), else as a window on the same screen (returns false).
    bool showOnParticipantScreen(QScreen* experimenterScreen);
    /// Every text its visible widgets show (labels, buttons, tooltips, accessible names).
    QStringList visibleTexts() const;
    /// The heading ("Trial 3 of 40", "Break", ...).
    QString heading() const;
    /// Why Done was refused ("" when nothing was).
    QString notice() const;
    /// The questions (layout checks).
    AnswerPanel* answers() const { return answers_; }
    /// The area the questions are shown in (what lies outside it needs scrolling).
    QScrollArea* answerArea() const { return scroll_; }

  signals:
    /// The participant changed the draft (chose an answer or a rating).
    void draftChanged();
    /// The participant pressed Done / Enter.
    void commitRequested();
    /// The participant asked to hear the clip again.
    void replayRequested();
    /// The window was closed.
    void closed();

  protected:
    void keyPressEvent(QKeyEvent* event) override;
    void closeEvent(QCloseEvent* event) override;

  private:
    experiment::TrialFlow* flow_ = nullptr;
    QLabel* heading_ = nullptr;
    QLabel* text_ = nullptr;
    QLabel* notice_ = nullptr;
    QProgressBar* progress_ = nullptr;
    AnswerPanel* answers_ = nullptr;
    QScrollArea* scroll_ = nullptr;
    QPushButton* done_ = nullptr;
    QPushButton* replay_ = nullptr;
    QString shownKey_; ///< page + heading + revision of the questions built last
};

} // namespace underfoot::gui
