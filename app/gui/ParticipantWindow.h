// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The participant's window: full screen on a second screen when there is one, showing only
/// what experiment::TrialFlow::participantScreen() lets the participant see — the briefing made
/// from the protocol's questions, the question, the answer list, the scales with every anchor,
/// progress and breaks. Never the stimulus (its id, surface, soundscape, input), the order of
/// the plan, the group or the experimenter's notes: those stay in the Run view.
///
/// The participant answers by pointer (buttons) or keys (letters, digits, Up/Down, Left/Right,
/// Enter commits, Space or R replays a listening-test clip); the experimenter's Run view shows
/// the same draft and keeps control (start, laps, breaks, pause, exclusions).
#include <QWidget>

#include <vector>

class QLabel;
class QProgressBar;
class QPushButton;
class QGroupBox;
class QVBoxLayout;
class QScreen;

namespace underfoot::experiment {
class TrialFlow;
}

namespace underfoot::gui {

class ParticipantWindow : public QWidget {
    Q_OBJECT
  public:
    explicit ParticipantWindow(QWidget* parent = nullptr);

    /// Shows `flow` (null: a waiting page). Not owned; call again whenever it changes.
    void setFlow(experiment::TrialFlow* flow);
    /// Redraws from the flow.
    void refresh();
    /// The experimenter paused the session (Ctrl+P): "Please wait", answers disabled.
    void setHeld(bool held);
    /// Shows the window full screen on a screen other than `experimenterScreen` when there is
    /// one (returns true), else as a window on the same screen (returns false).
    bool showOnParticipantScreen(QScreen* experimenterScreen);
    /// Every text its widgets show (labels, buttons, group titles, tooltips), for tests.
    QStringList visibleTexts() const;
    /// The heading ("Trial 3 of 40", "Break", ...).
    QString heading() const;

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
    void rebuildSections();
    void renderDraft();

    experiment::TrialFlow* flow_ = nullptr;
    bool held_ = false;
    QLabel* heading_ = nullptr;
    QLabel* text_ = nullptr;
    QProgressBar* progress_ = nullptr;
    QWidget* sectionsHost_ = nullptr;
    QVBoxLayout* sectionsLayout_ = nullptr;
    QPushButton* done_ = nullptr;
    QPushButton* replay_ = nullptr;
    struct Section {
        QGroupBox* box = nullptr;
        std::vector<QPushButton*> buttons;
    };
    std::vector<Section> sections_;
    QString shownKey_; ///< heading + page of the sections built last (rebuilt when it changes)
};

} // namespace underfoot::gui
