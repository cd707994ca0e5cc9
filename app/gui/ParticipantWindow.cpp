// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/ParticipantWindow.h"
#include "app/gui/AnswerPanel.h"
#include "app/gui/QtText.h"

#include "experiment/TrialFlow.h"

#include <QCloseEvent>
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

ParticipantWindow::ParticipantWindow(QWidget* parent) : QWidget(parent, Qt::Window) {
    setWindowTitle(tr("Underfoot — participant"));
    setAccessibleName(tr("Participant window"));
    setFocusPolicy(Qt::StrongFocus);
    heading_ = new QLabel(this);
    heading_->setFont(scaledFont(this, 1.8));
    heading_->setAlignment(Qt::AlignCenter);
    heading_->setAccessibleName(tr("Progress"));
    progress_ = new QProgressBar(this);
    progress_->setTextVisible(false);
    progress_->setMaximumHeight(8);
    progress_->setAccessibleName(tr("Trials answered"));
    text_ = new QLabel(this);
    text_->setWordWrap(true);
    text_->setFont(scaledFont(this, 1.3));
    text_->setAlignment(Qt::AlignCenter);
    text_->setAccessibleName(tr("Instructions"));
    notice_ = new QLabel(this);
    notice_->setWordWrap(true);
    notice_->setFont(scaledFont(this, 1.3));
    notice_->setAlignment(Qt::AlignCenter);
    notice_->setStyleSheet("QLabel { background: #fdecea; color: #8a1010; padding: 6px; "
                           "border: 2px solid #c62828; border-radius: 6px; }");
    notice_->setAccessibleName(tr("Why the answer was not given"));
    notice_->hide();

    AnswerPanelStyle style;
    style.fontFactor = 1.3;
    style.optionHeight = 40;
    style.valueButton = {52, 40};
    style.columns = 2; // scale questions side by side: four and more fit at 1280x800
    answers_ = new AnswerPanel(style, this);
    connect(answers_, &AnswerPanel::edited, this, [this] {
        emit draftChanged();
        setFocus();
    });
    scroll_ = new QScrollArea(this);
    scroll_->setWidget(answers_);
    scroll_->setWidgetResizable(true);
    scroll_->setFrameShape(QFrame::NoFrame);
    scroll_->setFocusPolicy(Qt::NoFocus);

    replay_ = new QPushButton(tr("Listen again  (Space)"), this);
    replay_->setFont(scaledFont(this, 1.3));
    replay_->setMinimumHeight(52);
    replay_->setFocusPolicy(Qt::NoFocus);
    replay_->setAccessibleName(tr("Listen again"));
    done_ = new QPushButton(tr("Done  (Enter)"), this);
    done_->setFont(scaledFont(this, 1.5));
    done_->setMinimumHeight(56);
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
    layout->setContentsMargins(40, 20, 40, 20);
    layout->setSpacing(8);
    layout->addWidget(heading_);
    layout->addWidget(progress_);
    layout->addWidget(text_);
    layout->addWidget(scroll_, 1);
    layout->addWidget(notice_);
    layout->addLayout(buttons);
    refresh();
}

void ParticipantWindow::setFlow(exp::TrialFlow* flow) {
    flow_ = flow;
    refresh();
}

QString ParticipantWindow::heading() const {
    return heading_->text();
}

QString ParticipantWindow::notice() const {
    return notice_->isHidden() ? QString() : notice_->text();
}

void ParticipantWindow::refresh() {
    exp::ParticipantScreen s;
    if (flow_) {
        s = flow_->participantScreen();
    } else {
        s.heading = tr("Welcome").toStdString();
        s.text = tr("Please wait: the experimenter prepares the session.").toStdString();
    }
    const bool trial = s.page == exp::ParticipantScreen::Page::Trial;
    heading_->setText(q(s.heading));
    text_->setText(q(s.text));
    progress_->setVisible(s.total > 0);
    progress_->setRange(0, std::max(1, s.total));
    progress_->setValue(s.answered);
    notice_->setText(q(s.notice));
    notice_->setVisible(!s.notice.empty());
    const QString key = QString("%1|%2|%3|%4")
                            .arg(static_cast<int>(s.page))
                            .arg(q(s.heading))
                            .arg(flow_ && flow_->revising() ? *flow_->revising() : -1)
                            .arg(s.sections.size());
    if (key != shownKey_) {
        shownKey_ = key;
        answers_->rebuild(trial ? flow_ : nullptr);
    }
    scroll_->setVisible(trial);
    answers_->setEnabled(s.answering);
    answers_->render(s.unanswered);
    done_->setVisible(trial);
    done_->setEnabled(s.answering);
    replay_->setVisible(s.replayOffered);
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
    const exp::ParticipantScreen screen = flow_->participantScreen();
    if (!screen.answering) {
        event->accept(); // keys wait until answers are asked
        return;
    }
    const int key = event->key();
    const QString text = event->text();
    if (key == Qt::Key_Return || key == Qt::Key_Enter) {
        emit commitRequested();
    } else if (screen.replayOffered &&
               (key == Qt::Key_Space ||
                (key == Qt::Key_R && !flow_->protocol().questions.asksSurface()))) {
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
    out << windowTitle() << accessibleName();
    for (const QWidget* w : findChildren<QWidget*>()) {
        if (!w->isVisibleTo(this)) continue;
        if (const auto* l = qobject_cast<const QLabel*>(w)) out << l->text();
        if (const auto* b = qobject_cast<const QPushButton*>(w)) out << b->text();
        out << w->toolTip() << w->accessibleName() << w->accessibleDescription();
    }
    out.removeAll(QString());
    return out;
}

} // namespace underfoot::gui
