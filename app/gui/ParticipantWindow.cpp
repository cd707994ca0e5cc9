// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/ParticipantWindow.h"
#include "app/gui/QtText.h"

#include "app/gui/ScaleRow.h"

#include "experiment/TrialFlow.h"

#include <QCloseEvent>
#include <QGridLayout>
#include <QGroupBox>
#include <QGuiApplication>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QScreen>
#include <QScrollArea>
#include <QVBoxLayout>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {
QFont scaled(const QWidget* w, double factor) {
    QFont f = w->font();
    f.setPointSizeF(f.pointSizeF() * factor);
    return f;
}
const char* kChecked = "QPushButton { text-align: left; padding: 6px 12px; } "
                       "QPushButton:checked { background: #1f6feb; color: white; "
                       "font-weight: bold; }";
} // namespace

ParticipantWindow::ParticipantWindow(QWidget* parent) : QWidget(parent, Qt::Window) {
    setWindowTitle(tr("Underfoot — participant"));
    setAccessibleName(tr("Participant window"));
    setFocusPolicy(Qt::StrongFocus);
    heading_ = new QLabel(this);
    heading_->setFont(scaled(this, 2.0));
    heading_->setAlignment(Qt::AlignCenter);
    heading_->setAccessibleName(tr("Progress"));
    progress_ = new QProgressBar(this);
    progress_->setTextVisible(false);
    progress_->setMaximumHeight(10);
    progress_->setAccessibleName(tr("Trials answered"));
    text_ = new QLabel(this);
    text_->setWordWrap(true);
    text_->setFont(scaled(this, 1.4));
    text_->setAlignment(Qt::AlignCenter);
    text_->setAccessibleName(tr("Instructions"));
    sectionsHost_ = new QWidget(this);
    sectionsLayout_ = new QVBoxLayout(sectionsHost_);
    auto* scroll = new QScrollArea(this);
    scroll->setWidget(sectionsHost_);
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setFocusPolicy(Qt::NoFocus);
    replay_ = new QPushButton(tr("Listen again  (Space)"), this);
    replay_->setFont(scaled(this, 1.3));
    replay_->setMinimumHeight(56);
    replay_->setFocusPolicy(Qt::NoFocus);
    done_ = new QPushButton(tr("Done  (Enter)"), this);
    done_->setFont(scaled(this, 1.5));
    done_->setMinimumHeight(64);
    done_->setFocusPolicy(Qt::NoFocus);
    done_->setAccessibleName(tr("Give this answer"));
    connect(done_, &QPushButton::clicked, this, [this] {
        emit commitRequested();
        setFocus();
    });
    connect(replay_, &QPushButton::clicked, this, [this] {
        emit replayRequested();
        setFocus();
    });
    auto* buttons = new QHBoxLayout;
    buttons->addWidget(replay_);
    buttons->addWidget(done_, 2);
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(48, 32, 48, 32);
    layout->addWidget(heading_);
    layout->addWidget(progress_);
    layout->addWidget(text_);
    layout->addWidget(scroll, 1);
    layout->addLayout(buttons);
    refresh();
}

void ParticipantWindow::setHeld(bool held) {
    held_ = held;
}

void ParticipantWindow::setFlow(exp::TrialFlow* flow) {
    flow_ = flow;
    refresh();
}

QString ParticipantWindow::heading() const {
    return heading_->text();
}

void ParticipantWindow::refresh() {
    if (!flow_) {
        heading_->setText(tr("Welcome"));
        text_->setText(tr("Please wait: the experimenter prepares the session."));
        progress_->hide();
        shownKey_.clear();
        rebuildSections();
        done_->hide();
        replay_->hide();
        return;
    }
    exp::ParticipantScreen s = flow_->participantScreen();
    if (held_ && s.page == exp::ParticipantScreen::Page::Trial) {
        s.answering = false;
        s.text = "Please wait a moment.";
    }
    heading_->setText(q(s.heading));
    text_->setText(q(s.text));
    progress_->setVisible(s.total > 0);
    progress_->setRange(0, std::max(1, s.total));
    progress_->setValue(s.answered);
    const QString key = QString("%1|%2|%3")
                            .arg(static_cast<int>(s.page))
                            .arg(q(s.heading))
                            .arg(static_cast<int>(s.sections.size()));
    if (key != shownKey_) {
        shownKey_ = key;
        rebuildSections();
    }
    const bool trial = s.page == exp::ParticipantScreen::Page::Trial;
    sectionsHost_->setEnabled(s.answering);
    done_->setVisible(trial);
    done_->setEnabled(s.answering);
    const auto& p = flow_->protocol();
    replay_->setVisible(trial && p.clips.enabled && p.clips.replay);
    replay_->setEnabled(s.answering);
    renderDraft();
}

void ParticipantWindow::rebuildSections() {
    for (auto& s : sections_) delete s.box;
    sections_.clear();
    while (auto* item = sectionsLayout_->takeAt(0)) delete item;
    if (!flow_ || flow_->participantScreen().page != exp::ParticipantScreen::Page::Trial) return;
    const auto& list = flow_->sections();
    for (std::size_t i = 0; i < list.size(); ++i) {
        const exp::AnswerSection& sec = list[i];
        Section s;
        s.box = new QGroupBox(q(sec.prompt), sectionsHost_);
        s.box->setFont(scaled(this, 1.3));
        const int index = static_cast<int>(i);
        if (sec.kind != exp::SectionKind::Scale) {
            auto* grid = new QGridLayout(s.box);
            const int columns = sec.options.size() > 8 ? 4 : 3;
            for (std::size_t o = 0; o < sec.options.size(); ++o) {
                const auto& opt = sec.options[o];
                auto* b = new QPushButton(
                    QString("%1   %2").arg(QChar(opt.letter)).arg(q(opt.label)), s.box);
                b->setCheckable(true);
                b->setFocusPolicy(Qt::NoFocus);
                b->setMinimumHeight(48);
                b->setStyleSheet(kChecked);
                const exp::SectionKind kind = sec.kind;
                const char letter = opt.letter;
                connect(b, &QPushButton::clicked, this, [this, kind, letter] {
                    if (flow_) flow_->choose(kind, letter);
                    emit draftChanged();
                    setFocus();
                });
                grid->addWidget(b, static_cast<int>(o) / columns, static_cast<int>(o) % columns);
                s.buttons.push_back(b);
            }
        } else {
            const exp::Scale& sc = *sec.scale;
            auto* column = new QVBoxLayout(s.box);
            QStringList anchors;
            for (const auto& a : exp::anchorTexts(sc)) anchors << q(a);
            auto* anchorLabel = new QLabel(anchors.join("\n"), s.box);
            anchorLabel->setWordWrap(true);
            column->addWidget(anchorLabel);
            ScaleRowStyle style;
            style.minimumButtonSize = {56, 48};
            s.buttons = addScaleRow(column, s.box, sc, style, [this, id = sc.id, index](int v) {
                if (flow_) {
                    flow_->setRating(id, v);
                    flow_->setActive(index);
                }
                emit draftChanged();
                setFocus();
            });
        }
        sectionsLayout_->addWidget(s.box);
        sections_.push_back(std::move(s));
    }
    sectionsLayout_->addStretch();
}

void ParticipantWindow::renderDraft() {
    if (!flow_ || sections_.size() != flow_->sections().size()) return;
    const auto& draft = flow_->draft();
    const int active = flow_->activeSection();
    for (std::size_t i = 0; i < sections_.size(); ++i) {
        const auto& sec = flow_->sections()[i];
        auto& s = sections_[i];
        s.box->setStyleSheet(static_cast<int>(i) == active
                                 ? "QGroupBox { border: 3px solid #1f6feb; border-radius: 6px; "
                                   "margin-top: 1.6em; } QGroupBox::title { subcontrol-origin: "
                                   "margin; left: 10px; }"
                                 : "QGroupBox { border: 1px solid palette(mid); border-radius: "
                                   "6px; margin-top: 1.6em; } QGroupBox::title { "
                                   "subcontrol-origin: margin; left: 10px; }");
        if (sec.kind == exp::SectionKind::Scale) {
            const auto it = draft.ratings.find(sec.scale->id);
            showScaleValue(s.buttons, *sec.scale,
                           it != draft.ratings.end() ? std::optional<int>(it->second)
                                                     : std::nullopt);
        } else {
            const std::string& chosen =
                sec.kind == exp::SectionKind::Surface ? draft.answer : draft.soundscapeAnswer;
            for (std::size_t b = 0; b < s.buttons.size(); ++b)
                s.buttons[b]->setChecked(sec.options[b].id == chosen);
        }
    }
}

bool ParticipantWindow::showOnParticipantScreen(QScreen* experimenterScreen) {
    QScreen* target = nullptr;
    for (QScreen* screen : QGuiApplication::screens())
        if (screen != experimenterScreen) {
            target = screen;
            break;
        }
    if (target) {
        setScreen(target);
        setGeometry(target->geometry());
        showFullScreen();
    } else {
        resize(1024, 700);
        show();
    }
    raise();
    activateWindow();
    setFocus();
    return target != nullptr;
}

void ParticipantWindow::keyPressEvent(QKeyEvent* event) {
    if (!flow_ || event->modifiers() & (Qt::ControlModifier | Qt::AltModifier)) {
        QWidget::keyPressEvent(event);
        return;
    }
    const exp::ParticipantScreen s = flow_->participantScreen();
    if (s.page != exp::ParticipantScreen::Page::Trial || !s.answering || held_) {
        event->accept(); // keys wait until answers are asked
        return;
    }
    const int key = event->key();
    const QString text = event->text();
    const auto& p = flow_->protocol();
    if (key == Qt::Key_Return || key == Qt::Key_Enter) {
        emit commitRequested();
    } else if ((key == Qt::Key_Space || (key == Qt::Key_R && !p.questions.asksSurface())) &&
               p.clips.enabled && p.clips.replay) {
        emit replayRequested();
    } else if (key == Qt::Key_Up || key == Qt::Key_Down) {
        flow_->setActive(flow_->activeSection() + (key == Qt::Key_Down ? 1 : -1));
        emit draftChanged();
    } else if (key == Qt::Key_Left || key == Qt::Key_Right) {
        flow_->adjust(key == Qt::Key_Right ? 1 : -1);
        emit draftChanged();
    } else if (text.size() == 1 && text.at(0).isLetter()) {
        flow_->chooseLetter(text.at(0).toLower().toLatin1());
        emit draftChanged();
    } else if (text.size() == 1 && text.at(0).isDigit()) {
        flow_->typeDigit(text.at(0).digitValue());
        emit draftChanged();
    } else {
        QWidget::keyPressEvent(event);
        return;
    }
    event->accept();
}

void ParticipantWindow::closeEvent(QCloseEvent* event) {
    emit closed();
    QWidget::closeEvent(event);
}

QStringList ParticipantWindow::visibleTexts() const {
    QStringList out;
    out << windowTitle();
    for (const QLabel* l : findChildren<QLabel*>())
        if (!l->isHidden()) out << l->text() << l->toolTip() << l->accessibleName();
    for (const QPushButton* b : findChildren<QPushButton*>())
        if (!b->isHidden()) out << b->text() << b->toolTip() << b->accessibleName();
    for (const QGroupBox* g : findChildren<QGroupBox*>()) out << g->title() << g->toolTip();
    out.removeAll(QString());
    return out;
}

} // namespace underfoot::gui
