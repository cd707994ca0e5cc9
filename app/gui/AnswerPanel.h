// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The questions of the current trial as buttons, drawn from an experiment::TrialFlow: each
/// question's prompt (wrapped), its answer list (letter and label) in a grid, or its scale as a
/// row of value buttons under every anchor. The active question is framed, the draft's choices
/// are checked, and questions left open after a refused Done are framed in red. A click goes to
/// the flow, which decides; the panel only draws what the flow holds.
///
/// The experimenter's Run view and the participant's window each show one, with their own
/// sizes (AnswerPanelStyle); neither keeps a copy of the draft.
#include "experiment/TrialFlow.h"

#include <QSize>
#include <QWidget>

#include <vector>

class QFrame;
class QGridLayout;
class QLabel;
class QPushButton;

namespace underfoot::gui {

struct AnswerPanelStyle {
    /// Font of the prompts, answers and values, relative to the panel's.
    double fontFactor = 1.1;
    /// Height of an answer button.
    int optionHeight = 36;
    /// Size of a scale's value button.
    QSize valueButton{48, 36};
    /// Scale questions side by side (answer lists always take a whole row).
    int columns = 1;
    /// The keys after each prompt ("keys a–p", "digits 1–7"): the experimenter's keyboard.
    bool keyHints = false;
};

class AnswerPanel : public QWidget {
    Q_OBJECT
  public:
    explicit AnswerPanel(const AnswerPanelStyle& style, QWidget* parent = nullptr);

    /// Builds the questions of `flow`'s draft (none for null or outside a trial). Call when the
    /// trial, a revision or the flow changes; render() after every change of the draft.
    void rebuild(experiment::TrialFlow* flow);
    /// Checks the draft's choices, frames the active question and, in red, the `unanswered` ones
    /// (indices into the flow's sections).
    void render(const std::vector<int>& unanswered = {});

    int sectionCount() const { return static_cast<int>(sections_.size()); }
    /// The frame of question `index` (its prompt, answers or scale), for layout checks.
    QWidget* section(int index) const;

  signals:
    /// A click was forwarded to the flow: `refusal` is its reason when refused, else empty.
    void edited(const QString& refusal);

  private:
    struct Section {
        QFrame* frame = nullptr;
        std::vector<QPushButton*> buttons;
    };
    QFrame* addSection(const experiment::AnswerSection& section);

    AnswerPanelStyle style_;
    experiment::TrialFlow* flow_ = nullptr;
    QGridLayout* grid_ = nullptr;
    std::vector<Section> sections_;
};

} // namespace underfoot::gui
