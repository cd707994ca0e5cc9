// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/RunStartPage.h"
#include "app/gui/QtText.h"
#include "app/gui/StudyContext.h"

#include "experiment/Clips.h"
#ifdef UNDERFOOT_HAVE_WIRING
#include "app/wiring/ClipPlayer.h"
#endif

#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QFutureWatcher>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProgressBar>
#include <QPromise>
#include <QPushButton>
#include <QRegularExpressionValidator>
#include <QShortcut>
#include <QSpinBox>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <memory>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

RunStartPage::RunStartPage(StudyContext& context, QWidget* parent)
    : QWidget(parent), context_(context) {
    auto* reg = new QGroupBox(tr("Register a participant"), this);
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

    auto* resume = new QGroupBox(tr("Resume or continue a participant"), this);
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

    message_ = new QLabel(this);
    message_->setWordWrap(true);
    message_->setAccessibleName(tr("Message"));
    message_->setTextInteractionFlags(Qt::TextSelectableByMouse);

    // Listening tests: the pre-rendered clips every participant hears.
    clipBox_ = new QGroupBox(tr("Listening-test clips"), this);
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
    connect(clipRender_, &QPushButton::clicked, this, &RunStartPage::renderRequested);
    connect(clipPick, &QPushButton::clicked, this, [this] {
        const QString dir = QFileDialog::getExistingDirectory(this, tr("Clip folder"), clipDir_);
        if (!dir.isEmpty()) setClipFolder(dir);
    });
    auto* scC = new QShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_C), this);
    scC->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scC, &QShortcut::activated, this, &RunStartPage::renderRequested);

    auto* top = new QHBoxLayout;
    top->addWidget(reg, 1);
    top->addWidget(resume, 1);
    auto* pl = new QVBoxLayout(this);
    pl->addLayout(top, 1);
    pl->addWidget(clipBox_);
    auto* participantButton =
        new QPushButton(tr("Participant window (second screen when there is one)  (F11)"), this);
    participantButton->setAccessibleName(tr("Open or close the participant window"));
    participantButton->setToolTip(
        tr("Shows the participant only the briefing, the questions, the answers, the scales and "
           "progress; never the stimulus, the plan or your notes."));
    connect(participantButton, &QPushButton::clicked, this,
            &RunStartPage::participantWindowRequested);
    auto* participantRow = new QHBoxLayout;
    participantRow->addWidget(participantButton);
    participantRow->addStretch();
    pl->addLayout(participantRow);
    pl->addWidget(message_);

    connect(registerButton, &QPushButton::clicked, this, &RunStartPage::registerRequested);
    for (auto key : {Qt::Key_Return, Qt::Key_Enter}) {
        auto* sc = new QShortcut(QKeySequence(Qt::CTRL | key), this);
        sc->setContext(Qt::WidgetWithChildrenShortcut);
        connect(sc, &QShortcut::activated, this, &RunStartPage::registerRequested);
    }
    const auto resumeSelected = [this] {
        auto* item = resumeList_->currentItem();
        if (!item || item->data(Qt::UserRole).toString().isEmpty()) {
            setMessage(tr("Select a participant in the list first (Up/Down)."));
            return;
        }
        emit resumeRequested(item->data(Qt::UserRole).toString());
    };
    connect(resumeButton, &QPushButton::clicked, this, resumeSelected);
    connect(resumeList_, &QListWidget::itemActivated, this, resumeSelected);
    auto* scR = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_R), this);
    scR->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scR, &QShortcut::activated, this, resumeSelected);
}

RunStartPage::~RunStartPage() {
    // A clip render in flight stops before its next clip; wait for it (it holds no page data).
    for (auto* w : findChildren<QFutureWatcher<QString>*>()) {
        w->disconnect(this);
        w->cancel();
        w->waitForFinished();
    }
}

void RunStartPage::refresh() {
    resumeList_->clear();
    group_->clear();
    resumeBanner_->hide();
    refreshClips();
    if (!context_.hasStudy()) {
        setMessage(tr("No study open: create or open one in the Study view (Ctrl+1)."));
        return;
    }
    message_->clear();
    const auto& store = context_.store();
    const auto people = store.participants();
    try {
        const QString next = q(store.nextGroup(static_cast<int>(people.size())));
        group_->addItem(tr("balanced assignment (next: %1)").arg(next), QString());
    } catch (const std::exception& e) {
        group_->addItem(tr("balanced assignment"), QString());
        setMessage(q(e.what()));
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

std::optional<exp::NewParticipant> RunStartPage::participantFromForm() {
    exp::NewParticipant np;
    np.code = code_->text().trimmed().toStdString();
    if (np.code.empty()) {
        setMessage(tr("Type the participant's pseudonymous code first (Alt+C)."));
        code_->setFocus();
        return std::nullopt;
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
            setMessage(tr("A group chosen by hand needs a reason (Alt+E), or choose balanced "
                          "assignment."));
            overrideReason_->setFocus();
            return std::nullopt;
        }
    }
    return np;
}

void RunStartPage::clearForm() {
    code_->clear();
    age_->setValue(0);
    overrideReason_->clear();
}

void RunStartPage::fillForm(const QString& code, int age, const QString& gender,
                            const QString& shoes, const QString& experimenter) {
    code_->setText(code);
    age_->setValue(age);
    gender_->setCurrentText(gender);
    shoes_->setText(shoes);
    experimenter_->setText(experimenter);
}

QString RunStartPage::experimenter() const {
    return experimenter_->text().trimmed();
}

void RunStartPage::setMessage(const QString& text) {
    message_->setText(text);
}

QString RunStartPage::message() const {
    return message_->text();
}

void RunStartPage::refreshClips() {
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
            ? tr("%1 ready in %2 (manifest checked: every file as rendered).")
                  .arg(counted(static_cast<long long>(
                                   exp::readClipManifest(clipDir_.toStdString()).size()),
                               tr("clip"), tr("clips")),
                       clipDir_)
            : tr("Clips not ready in %1 — %2%3. Render them (Ctrl+Shift+C) or choose the folder "
                 "that holds them.")
                  .arg(clipDir_, problems.front())
                  .arg(problems.size() > 1 ? tr(" (and %1 more)").arg(problems.size() - 1)
                                           : QString()));
    clipStatus_->setStyleSheet(problems.isEmpty() ? "color: #0a5c0a;" : "color: #8a1c00;");
}

void RunStartPage::setClipFolder(const QString& folder) {
    clipDir_ = folder;
    refreshClips();
}

QStringList RunStartPage::clipProblems() const {
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

QString RunStartPage::clipStatus() const {
    return clipStatus_->text();
}

bool RunStartPage::renderClips() {
    if (rendering_ || !context_.hasStudy() || !context_.store().protocol().clips.enabled)
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
    // Progress goes through the promise (thread-safe); a cancelled future (page closing) stops
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

} // namespace underfoot::gui
