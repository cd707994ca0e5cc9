// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/AnswerPanel.h"
#include "app/gui/QtText.h"

#include <QFrame>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>

#include <algorithm>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {
const char* kButton = "QPushButton { text-align: left; padding: 4px 10px; } "
                      "QPushButton:checked { background: #1f6feb; color: white; "
                      "font-weight: bold; }";
const char* kValue = "QPushButton:checked { background: #1f6feb; color: white; "
                     "font-weight: bold; }";
const char* kFrame = "QFrame#question { border: %1px solid %2; border-radius: 6px; }";
} // namespace

AnswerPanel::AnswerPanel(const AnswerPanelStyle& style, QWidget* parent)
    : QWidget(parent), style_(style) {
    QFont f = font();
    f.setPointSizeF(f.pointSizeF() * style_.fontFactor);
    setFont(f);
    auto* outer = new QVBoxLayout(this);
    outer->setContentsMargins(0, 0, 0, 0);
    grid_ = new QGridLayout;
    grid_->setContentsMargins(0, 0, 0, 0);
    grid_->setSpacing(8);
    outer->addLayout(grid_);
    outer->addStretch();
}

QWidget* AnswerPanel::section(int index) const {
    return index >= 0 && index < sectionCount() ? sections_[static_cast<std::size_t>(index)].frame
                                                : nullptr;
}

void AnswerPanel::rebuild(exp::TrialFlow* flow) {
    flow_ = flow;
    for (auto& s : sections_) delete s.frame;
    sections_.clear();
    if (!flow_) return;
    const auto& list = flow_->sections();
    const int columns = std::max(1, style_.columns);
    int row = 0;
    int column = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
        QFrame* frame = addSection(list[i]);
        frame->show(); // shown with the panel, even when the panel is on screen already
        if (list[i].kind == exp::SectionKind::Scale) {
            grid_->addWidget(frame, row, column);
            if (++column == columns) column = 0, ++row;
        } else {
            if (column > 0) column = 0, ++row;
            grid_->addWidget(frame, row++, 0, 1, columns);
        }
    }
    for (int c = 0; c < columns; ++c) grid_->setColumnStretch(c, 1);
}

QFrame* AnswerPanel::addSection(const exp::AnswerSection& sec) {
    Section s;
    s.frame = new QFrame(this);
    s.frame->setObjectName("question");
    auto* column = new QVBoxLayout(s.frame);
    column->setContentsMargins(10, 6, 10, 8);
    column->setSpacing(4);
    QString prompt = q(sec.prompt);
    if (style_.keyHints && sec.kind == exp::SectionKind::Scale)
        prompt += tr("  (digits %1–%2)").arg(sec.scale->min).arg(sec.scale->max);
    else if (style_.keyHints && !sec.options.empty())
        prompt += sec.kind == exp::SectionKind::Surface
                      ? tr("  (keys a–%1)").arg(QChar(sec.options.back().letter))
                      : tr("  (keys a–%1 when this question is active; Down moves here)")
                            .arg(QChar(sec.options.back().letter));
    auto* title = new QLabel(prompt, s.frame);
    title->setWordWrap(true);
    QFont bold = title->font();
    bold.setBold(true);
    title->setFont(bold);
    column->addWidget(title);
    s.frame->setAccessibleName(q(sec.prompt));

    if (sec.kind == exp::SectionKind::Scale) {
        const exp::Scale& sc = *sec.scale;
        QStringList anchors;
        for (const auto& a : exp::anchorTexts(sc)) anchors << q(a);
        auto* anchorLabel = new QLabel(anchors.join("   ·   "), s.frame);
        anchorLabel->setWordWrap(true);
        anchorLabel->setStyleSheet("color: #404040;");
        anchorLabel->setAccessibleName(tr("Anchors"));
        column->addWidget(anchorLabel);
        auto* row = new QHBoxLayout;
        column->addLayout(row);
        for (int v = sc.min; v <= sc.max; ++v) {
            auto* b = new QPushButton(QString::number(v), s.frame);
            b->setCheckable(true);
            b->setFocusPolicy(Qt::NoFocus);
            b->setMinimumSize(style_.valueButton);
            b->setStyleSheet(kValue);
            b->setAccessibleName(tr("%1: %2").arg(q(sc.prompt)).arg(v));
            connect(b, &QPushButton::clicked, this, [this, id = sc.id, v] {
                if (!flow_) return;
                const exp::FlowResult r = flow_->setRating(id, v);
                emit edited(r ? QString() : q(r.message));
            });
            row->addWidget(b);
            s.buttons.push_back(b);
        }
        row->addStretch();
    } else {
        auto* grid = new QGridLayout;
        column->addLayout(grid);
        std::size_t longest = 0;
        for (const auto& o : sec.options) longest = std::max(longest, o.label.size());
        // Long labels stay readable in three columns at 1280 px.
        const int columns = static_cast<int>(std::min<std::size_t>(
            longest > 26 ? 3 : 4, std::max<std::size_t>(1, sec.options.size())));
        for (std::size_t i = 0; i < sec.options.size(); ++i) {
            const auto& o = sec.options[i];
            auto* b =
                new QPushButton(QString("%1   %2").arg(QChar(o.letter)).arg(q(o.label)), s.frame);
            b->setCheckable(true);
            b->setFocusPolicy(Qt::NoFocus);
            b->setMinimumHeight(style_.optionHeight);
            b->setStyleSheet(kButton);
            b->setAccessibleName(tr("Answer %1: %2").arg(QChar(o.letter)).arg(q(o.label)));
            connect(b, &QPushButton::clicked, this, [this, kind = sec.kind, letter = o.letter] {
                if (!flow_) return;
                const exp::FlowResult r = flow_->choose(kind, letter);
                emit edited(r ? QString() : q(r.message));
            });
            grid->addWidget(b, static_cast<int>(i) / columns, static_cast<int>(i) % columns);
            s.buttons.push_back(b);
        }
    }
    sections_.push_back(std::move(s));
    return sections_.back().frame;
}

void AnswerPanel::render(const std::vector<int>& unanswered) {
    if (!flow_ || sections_.size() != flow_->sections().size()) return;
    const auto& draft = flow_->draft();
    const int active = flow_->activeSection();
    for (std::size_t i = 0; i < sections_.size(); ++i) {
        const exp::AnswerSection& sec = flow_->sections()[i];
        Section& s = sections_[i];
        const int index = static_cast<int>(i);
        const bool open =
            std::find(unanswered.begin(), unanswered.end(), index) != unanswered.end();
        s.frame->setStyleSheet(QString(kFrame)
                                   .arg(index == active || open ? 3 : 1)
                                   .arg(open              ? "#c62828"
                                        : index == active ? "#1f6feb"
                                                          : "palette(mid)"));
        if (sec.kind == exp::SectionKind::Scale) {
            const auto it = draft.ratings.find(sec.scale->id);
            for (std::size_t b = 0; b < s.buttons.size(); ++b)
                s.buttons[b]->setChecked(it != draft.ratings.end() &&
                                         it->second == sec.scale->min + static_cast<int>(b));
        } else {
            const std::string& chosen =
                sec.kind == exp::SectionKind::Surface ? draft.answer : draft.soundscapeAnswer;
            for (std::size_t b = 0; b < s.buttons.size(); ++b)
                s.buttons[b]->setChecked(sec.options[b].id == chosen);
        }
    }
}

} // namespace underfoot::gui
