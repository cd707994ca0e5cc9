// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Study view: create a study from a protocol or open one; its groups against their
/// targets, participants and their progress, and the excluded trials (re-include with Ctrl+I).
#include <QWidget>

class QComboBox;
class QLineEdit;
class QSpinBox;
class QPushButton;
class QPlainTextEdit;
class QTableWidget;
class QLabel;

namespace underfoot::gui {

class StudyContext;

class StudyView : public QWidget {
    Q_OBJECT
  public:
    explicit StudyView(StudyContext& context, QWidget* parent = nullptr);

    /// Creates the study described by the form; returns false and shows the problem otherwise.
    bool createFromForm();
    /// Opens a study file; returns false and shows the problem otherwise.
    bool openFile(const QString& path);
    /// Marks a participant as dropped out (frees the group slot); false with the problem shown.
    bool dropParticipant(const QString& code, const QString& reason);
    /// Disables create/open while a session runs.
    void setStudySwitchingEnabled(bool enabled);

    // Form fields (exposed for tests and screenshots).
    QComboBox* protocolBox() const { return protocol_; }
    QLineEdit* fileEdit() const { return file_; }
    QLineEdit* codeEdit() const { return code_; }
    QPlainTextEdit* messages() const { return messages_; }
    QTableWidget* participantsTable() const { return participants_; }
    QTableWidget* groupsTable() const { return groups_; }
    QTableWidget* exclusionsTable() const { return exclusions_; }

  signals:
    /// The experimenter asked to run (or resume) the participant selected in the table.
    void runRequested();

  private:
    void refresh();
    void browseProtocol();
    void browseFile();
    void browseOpen();
    void reinclude();
    void askDrop();
    void showMessage(const QString& text, bool error);

    StudyContext& context_;
    QComboBox* protocol_;
    QLineEdit* file_;
    QLineEdit* code_;
    QLineEdit* site_;
    QSpinBox* seed_;
    QPushButton* create_;
    QPushButton* open_;
    QPushButton* drop_;
    QPlainTextEdit* messages_;
    QLabel* info_;
    QTableWidget* groups_;
    QTableWidget* participants_;
    QTableWidget* exclusions_;
};

} // namespace underfoot::gui
