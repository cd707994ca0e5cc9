// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/StudyView.h"
#include "app/gui/QtText.h"
#include "base/Version.h"

#include "app/gui/DemoStudy.h"
#include "app/gui/StudyContext.h"
#include "experiment/Progress.h"

#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QFileDialog>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QShortcut>
#include <QSpinBox>
#include <QSplitter>
#include <QTableWidget>
#include <QVBoxLayout>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

namespace {

QTableWidget* makeTable(const QStringList& headers, const QString& name, QWidget* parent) {
    auto* t = new QTableWidget(0, static_cast<int>(headers.size()), parent);
    t->setHorizontalHeaderLabels(headers);
    t->setEditTriggers(QAbstractItemView::NoEditTriggers);
    t->setSelectionBehavior(QAbstractItemView::SelectRows);
    t->setSelectionMode(QAbstractItemView::SingleSelection);
    t->verticalHeader()->setVisible(false);
    t->horizontalHeader()->setStretchLastSection(true);
    t->setAccessibleName(name);
    t->setAlternatingRowColors(true);
    return t;
}

void setRow(QTableWidget* t, int row, const QStringList& cells) {
    for (int c = 0; c < cells.size(); ++c) t->setItem(row, c, new QTableWidgetItem(cells[c]));
}

} // namespace

StudyView::StudyView(StudyContext& context, QWidget* parent) : QWidget(parent), context_(context) {
    auto* form = new QGroupBox(tr("New study from a protocol"), this);
    auto* fl = new QFormLayout(form);
    protocol_ = new QComboBox(form);
    protocol_->setEditable(true);
    protocol_->setAccessibleName(tr("Protocol file"));
    protocol_->setAccessibleDescription(
        tr("A protocol TOML file; the shipped protocols are listed, or type a path"));
    const QDir shipped(q(exp::shippedProtocolDir()));
    for (const QString& f : shipped.entryList({"*.toml"}, QDir::Files, QDir::Name))
        protocol_->addItem(shipped.filePath(f));
    protocol_->addItem(QDir(bundledDataDir()).filePath("demo_walker.toml"));
    auto* browseP = new QPushButton(tr("Browse…"), form);
    browseP->setAccessibleName(tr("Browse for a protocol file"));
    auto* prow = new QHBoxLayout;
    prow->addWidget(protocol_, 1);
    prow->addWidget(browseP);
    auto* plabel = new QLabel(tr("P&rotocol:"), form);
    plabel->setBuddy(protocol_);
    fl->addRow(plabel, prow);

    file_ = new QLineEdit(form);
    file_->setPlaceholderText(tr("where the study file (.db) is written"));
    file_->setAccessibleName(tr("Study file"));
    auto* browseF = new QPushButton(tr("Browse…"), form);
    browseF->setAccessibleName(tr("Choose where to write the study file"));
    auto* frow = new QHBoxLayout;
    frow->addWidget(file_, 1);
    frow->addWidget(browseF);
    auto* flabel = new QLabel(tr("Study &file:"), form);
    flabel->setBuddy(file_);
    fl->addRow(flabel, frow);

    code_ = new QLineEdit(form);
    code_->setAccessibleName(tr("Study code"));
    code_->setPlaceholderText(tr("e.g. exp2-2026"));
    auto* clabel = new QLabel(tr("Study &code:"), form);
    clabel->setBuddy(code_);
    fl->addRow(clabel, code_);
    site_ = new QLineEdit(form);
    site_->setAccessibleName(tr("Site"));
    site_->setPlaceholderText(tr("lab or room"));
    auto* slabel = new QLabel(tr("S&ite:"), form);
    slabel->setBuddy(site_);
    fl->addRow(slabel, site_);
    seed_ = new QSpinBox(form);
    seed_->setRange(1, 2147483647);
    seed_->setValue(static_cast<int>(QDateTime::currentSecsSinceEpoch() % 1000000) + 1);
    seed_->setAccessibleName(tr("Study seed"));
    seed_->setToolTip(tr("Seeds every participant's trial order; stored with the study"));
    auto* seedLabel = new QLabel(tr("S&eed:"), form);
    seedLabel->setBuddy(seed_);
    fl->addRow(seedLabel, seed_);
    create_ = new QPushButton(tr("&Create study  (Ctrl+N)"), form);
    create_->setAccessibleName(tr("Create study"));
    open_ = new QPushButton(tr("&Open study…  (Ctrl+O)"), form);
    open_->setAccessibleName(tr("Open study"));
    auto* demo = new QPushButton(tr("Open the &demo study"), form);
    demo->setAccessibleName(tr("Open the demo study"));
    auto* brow = new QHBoxLayout;
    brow->addWidget(create_);
    brow->addWidget(open_);
    brow->addWidget(demo);
    fl->addRow(brow);

    messages_ = new QPlainTextEdit(this);
    messages_->setReadOnly(true);
    messages_->setMaximumHeight(80);
    messages_->setAccessibleName(tr("Messages"));
    messages_->setPlaceholderText(tr("Problems with a protocol or a study file are shown here, "
                                     "with file:line:column."));

    info_ = new QLabel(this);
    info_->setWordWrap(true);
    info_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    info_->setAccessibleName(tr("Study information"));

    groups_ = makeTable({tr("Group"), tr("Label"), tr("Active"), tr("Done"), tr("Dropped"),
                         tr("Target"), tr("Trials"), tr("Minutes")},
                        tr("Groups"), this);
    participants_ =
        makeTable({tr("Participant"), tr("Group"), tr("Status"), tr("Answered"), tr("Registered")},
                  tr("Participants"), this);
    exclusions_ = makeTable({tr("Participant"), tr("Trial"), tr("Stimulus"), tr("Reason")},
                            tr("Excluded trials"), this);
    auto* reincludeButton = new QPushButton(tr("Re-&include selected trial  (Ctrl+I)"), this);
    reincludeButton->setAccessibleName(tr("Re-include the selected excluded trial"));

    auto* left = new QVBoxLayout;
    left->addWidget(form);
    left->addWidget(messages_);
    auto* infoBox = new QGroupBox(tr("Study"), this);
    (new QVBoxLayout(infoBox))->addWidget(info_);
    left->addWidget(infoBox);
    auto* gbox = new QGroupBox(tr("Groups and plan"), this);
    (new QVBoxLayout(gbox))->addWidget(groups_);
    left->addWidget(gbox, 1);

    drop_ = new QPushButton(tr("Mark selected as &dropped out…  (Ctrl+D)"), this);
    drop_->setAccessibleName(tr("Mark the selected participant as dropped out"));
    auto* right = new QVBoxLayout;
    auto* pbox = new QGroupBox(tr("Participants (double-click or Enter: run / resume)"), this);
    auto* pl = new QVBoxLayout(pbox);
    pl->addWidget(participants_);
    pl->addWidget(drop_);
    right->addWidget(pbox, 3);
    auto* ebox = new QGroupBox(tr("Excluded trials"), this);
    auto* el = new QVBoxLayout(ebox);
    el->addWidget(exclusions_);
    el->addWidget(reincludeButton);
    right->addWidget(ebox, 2);

    auto* layout = new QHBoxLayout(this);
    layout->addLayout(left, 1);
    layout->addLayout(right, 1);

    connect(browseP, &QPushButton::clicked, this, &StudyView::browseProtocol);
    connect(browseF, &QPushButton::clicked, this, &StudyView::browseFile);
    connect(create_, &QPushButton::clicked, this, &StudyView::createFromForm);
    connect(open_, &QPushButton::clicked, this, &StudyView::browseOpen);
    connect(demo, &QPushButton::clicked, this, [this] {
        const QString dir = userDataDir();
        const QString error = ensureDemoStudy(dir);
        if (!error.isEmpty()) return showMessage(error, true);
        openFile(demoStudyPath(dir));
    });
    connect(reincludeButton, &QPushButton::clicked, this, &StudyView::reinclude);
    connect(drop_, &QPushButton::clicked, this, &StudyView::askDrop);
    auto* scDrop = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_D), this);
    connect(scDrop, &QShortcut::activated, this, &StudyView::askDrop);
    auto* scNew = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_N), this);
    connect(scNew, &QShortcut::activated, this, &StudyView::createFromForm);
    auto* scOpen = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_O), this);
    connect(scOpen, &QShortcut::activated, this, &StudyView::browseOpen);
    auto* scInc = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_I), this);
    connect(scInc, &QShortcut::activated, this, &StudyView::reinclude);
    connect(participants_, &QTableWidget::cellActivated, this, [this] { emit runRequested(); });
    connect(&context_, &StudyContext::dataChanged, this, &StudyView::refresh);
    setTabOrder(protocol_, file_);
    setTabOrder(file_, code_);
    setTabOrder(code_, site_);
    setTabOrder(site_, seed_);
    setTabOrder(seed_, create_);
    refresh();
}

void StudyView::showMessage(const QString& text, bool error) {
    messages_->setPlainText(text);
    QPalette pal = messages_->palette();
    pal.setColor(QPalette::Text, error ? QColor(170, 0, 0) : palette().color(QPalette::Text));
    messages_->setPalette(pal);
}

void StudyView::setStudySwitchingEnabled(bool enabled) {
    create_->setEnabled(enabled);
    open_->setEnabled(enabled);
    drop_->setEnabled(enabled);
}

bool StudyView::dropParticipant(const QString& code, const QString& reason) {
    if (!context_.hasStudy() || !drop_->isEnabled()) return false;
    if (reason.trimmed().isEmpty()) {
        showMessage(tr("A dropout needs a reason (it is journaled with the study)."), true);
        return false;
    }
    try {
        context_.store().dropParticipant(code.toStdString(), reason.trimmed().toStdString());
    } catch (const std::exception& e) {
        showMessage(q(e.what()), true);
        return false;
    }
    showMessage(tr("%1 marked as dropped out; the group's slot is free again. Their answers stay "
                   "in the file.")
                    .arg(code),
                false);
    context_.notifyDataChanged();
    return true;
}

void StudyView::askDrop() {
    const int row = participants_->currentRow();
    if (!context_.hasStudy() || row < 0) {
        showMessage(tr("Select a participant in the list first."), true);
        return;
    }
    const QString code = participants_->item(row, 0)->text();
    bool ok = false;
    const QString reason = QInputDialog::getText(this, tr("Participant dropped out"),
                                                 tr("Why did %1 drop out?").arg(code),
                                                 QLineEdit::Normal, QString(), &ok);
    if (ok) dropParticipant(code, reason);
}

bool StudyView::createFromForm() {
    if (!create_->isEnabled()) return false;
    const QString protocol = protocol_->currentText().trimmed();
    QString file = file_->text().trimmed();
    if (protocol.isEmpty()) {
        showMessage(tr("Choose a protocol file first (Alt+R)."), true);
        return false;
    }
    if (file.isEmpty()) {
        showMessage(tr("Give the study file to write (Alt+F), e.g. %1")
                        .arg(QDir(userDataDir()).filePath("my_study.db")),
                    true);
        return false;
    }
    if (!file.endsWith(".db")) file += ".db";
    exp::StudySettings settings;
    settings.code = code_->text().trimmed().toStdString();
    if (settings.code.empty()) settings.code = QFileInfo(file).completeBaseName().toStdString();
    settings.site = site_->text().trimmed().toStdString();
    settings.seed = static_cast<std::uint64_t>(seed_->value());
    settings.appVersion = underfoot::base::version();
    const QString error = context_.createStudy(file, protocol, settings);
    if (!error.isEmpty()) {
        showMessage(error, true);
        return false;
    }
    showMessage(tr("Created %1. Register the first participant in the Run view (Ctrl+2).")
                    .arg(QDir::toNativeSeparators(file)),
                false);
    return true;
}

bool StudyView::openFile(const QString& path) {
    const QString error = context_.openStudy(path);
    if (!error.isEmpty()) {
        showMessage(error, true);
        return false;
    }
    showMessage(tr("Opened %1.").arg(QDir::toNativeSeparators(path)), false);
    return true;
}

void StudyView::browseProtocol() {
    const QString f = QFileDialog::getOpenFileName(
        this, tr("Protocol file"), q(exp::shippedProtocolDir()), tr("Protocols (*.toml)"));
    if (!f.isEmpty()) protocol_->setCurrentText(f);
}

void StudyView::browseFile() {
    const QString f = QFileDialog::getSaveFileName(this, tr("New study file"), userDataDir(),
                                                   tr("Study files (*.db)"));
    if (!f.isEmpty()) file_->setText(f);
}

void StudyView::browseOpen() {
    if (!open_->isEnabled()) return;
    const QString f = QFileDialog::getOpenFileName(this, tr("Open study"), userDataDir(),
                                                   tr("Study files (*.db)"));
    if (!f.isEmpty()) openFile(f);
}

void StudyView::reinclude() {
    const int row = exclusions_->currentRow();
    if (!context_.hasStudy() || row < 0) {
        showMessage(tr("Select an excluded trial in the list first."), true);
        return;
    }
    const std::string code = exclusions_->item(row, 0)->text().toStdString();
    const int index = exclusions_->item(row, 1)->data(Qt::UserRole).toInt();
    try {
        context_.store().setExcluded(code, index, false, "");
    } catch (const std::exception& e) {
        showMessage(q(e.what()), true);
        return;
    }
    context_.notifyDataChanged();
}

void StudyView::refresh() {
    groups_->setRowCount(0);
    participants_->setRowCount(0);
    exclusions_->setRowCount(0);
    if (!context_.hasStudy()) {
        info_->setText(tr("No study open. Create one from a protocol (Ctrl+N) or open a study "
                          "file (Ctrl+O)."));
        return;
    }
    const auto& store = context_.store();
    const auto& p = store.protocol();
    exp::StudyProgress progress;
    try {
        progress = exp::studyProgress(store);
    } catch (const std::exception& e) {
        showMessage(q(e.what()), true);
        return;
    }
    const auto& info = progress.info;
    info_->setText(
        tr("<b>%1</b><br>%2<br>Protocol <tt>%3</tt> v%4 · %5 design · answers lock %6 "
           "· seed %7 · created %8 · %9 participants")
            .arg(q(p.title).toHtmlEscaped(), q(p.reference).toHtmlEscaped(), q(info.protocolId))
            .arg(info.protocolVersion)
            .arg(q(exp::toString(p.design)), p.lock == exp::LockRule::OnAnswer
                                                 ? tr("once given")
                                                 : tr("when the next trial starts"))
            .arg(info.seed)
            .arg(q(info.createdAt))
            .arg(progress.participants.size()));
    groups_->setRowCount(static_cast<int>(progress.groups.size()));
    for (std::size_t i = 0; i < progress.groups.size(); ++i) {
        const auto& g = progress.groups[i];
        const exp::Group* group = p.group(g.groupId);
        QString trials, minutes;
        for (const auto& s : progress.plan.groups)
            if (s.groupId == g.groupId) {
                trials =
                    tr("%1 + %2 pr., %3 br.").arg(s.mainTrials).arg(s.practiceTrials).arg(s.breaks);
                minutes = QString::number(s.estimatedDurationS / 60.0, 'f', 0);
            }
        setRow(groups_, static_cast<int>(i),
               {q(g.groupId), group ? q(group->label) : QString(), QString::number(g.active),
                QString::number(g.completed), QString::number(g.dropped),
                g.target > 0 ? QString::number(g.target) : tr("—"), trials, minutes});
    }
    groups_->resizeColumnsToContents();
    // The label gives way (elided, full text in its tooltip) so that the counts stay visible.
    groups_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    groups_->horizontalHeader()->setSectionResizeMode(1, QHeaderView::Stretch);
    for (int r = 0; r < groups_->rowCount(); ++r)
        if (auto* item = groups_->item(r, 1)) item->setToolTip(item->text());
    participants_->setRowCount(static_cast<int>(progress.participants.size()));
    const auto people = store.participants();
    for (std::size_t i = 0; i < progress.participants.size(); ++i) {
        const auto& pp = progress.participants[i];
        QString registered;
        bool simulated = false;
        for (const auto& person : people)
            if (person.code == pp.code) {
                registered = q(person.registeredAt);
                simulated = person.simulated;
            }
        // Simulated participants are marked as such: their answers are synthetic and `analyze`
        // leaves them out unless asked (--include-simulated).
        const QString status = simulated ? tr("%1 (simulated)").arg(q(exp::toString(pp.status)))
                                         : q(exp::toString(pp.status));
        setRow(participants_, static_cast<int>(i),
               {q(pp.code), q(pp.groupId), status, tr("%1 / %2").arg(pp.answered).arg(pp.planned),
                registered});
    }
    participants_->resizeColumnsToContents();
    int row = 0;
    for (const auto& person : people)
        for (const auto& t : store.trials(person.code)) {
            if (!t.excluded) continue;
            exclusions_->insertRow(row);
            setRow(exclusions_, row,
                   {q(person.code), QString::number(t.index + 1), q(t.stimulus.id),
                    q(t.exclusionReason)});
            exclusions_->item(row, 1)->setData(Qt::UserRole, t.index);
            ++row;
        }
    exclusions_->resizeColumnsToContents();
}

} // namespace underfoot::gui
