// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Run view's start page: the registration form (pseudonymous code, demographics, the
/// balanced group or an override with its reason, the experimenter), the participants who have
/// not finished (an interrupted session named in a banner), and for listening tests the clips
/// every participant hears (checked against their manifest, rendered on a worker thread).
/// Registering and starting a session are the Run view's; this page only collects and shows.
#include "experiment/Store.h"

#include <QWidget>

#include <optional>

class QComboBox;
class QGroupBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QProgressBar;
class QPushButton;
class QSpinBox;

namespace underfoot::gui {

class StudyContext;

class RunStartPage : public QWidget {
    Q_OBJECT
  public:
    RunStartPage(StudyContext& context, QWidget* parent = nullptr);
    ~RunStartPage() override;

    /// Redraws the group choice, the list of participants to resume and the clip status.
    void refresh();
    /// The participant the form describes, or nullopt with what is missing in the message line
    /// (and the focus on that field).
    std::optional<experiment::NewParticipant> participantFromForm();
    /// Empties the form after a registration.
    void clearForm();
    /// The experimenter's name typed in the form ("" when none).
    QString experimenter() const;
    void setMessage(const QString& text);
    QString message() const;
    /// Fills the form (screenshots).
    void fillForm(const QString& code, int age, const QString& gender, const QString& shoes,
                  const QString& experimenter);

    // Listening-test clips.
    QString clipFolder() const { return clipDir_; }
    void setClipFolder(const QString& folder);
    QStringList clipProblems() const;
    /// Renders the protocol's clips into clipFolder() on a worker thread; false when already
    /// rendering, the protocol has no [clips] or this build has no engine wiring.
    bool renderClips();
    bool rendering() const { return rendering_; }
    QString clipStatus() const;

    QLineEdit* codeEdit() const { return code_; }
    QSpinBox* ageBox() const { return age_; }
    QComboBox* genderBox() const { return gender_; }
    QComboBox* groupBox() const { return group_; }
    QListWidget* resumeList() const { return resumeList_; }
    QLabel* resumeBanner() const { return resumeBanner_; }

  signals:
    void registerRequested();
    void resumeRequested(const QString& code);
    void participantWindowRequested();
    /// Asked to render the clips (the Run view refuses while a session runs).
    void renderRequested();

  private:
    void refreshClips();

    StudyContext& context_;
    QLineEdit* code_ = nullptr;
    QSpinBox* age_ = nullptr;
    QComboBox* gender_ = nullptr;
    QLineEdit* shoes_ = nullptr;
    QComboBox* hearing_ = nullptr;
    QComboBox* group_ = nullptr;
    QLineEdit* overrideReason_ = nullptr;
    QLineEdit* experimenter_ = nullptr;
    QListWidget* resumeList_ = nullptr;
    QLabel* resumeBanner_ = nullptr;
    QLabel* message_ = nullptr;
    QGroupBox* clipBox_ = nullptr;
    QLabel* clipStatus_ = nullptr;
    QProgressBar* clipProgress_ = nullptr;
    QPushButton* clipRender_ = nullptr;
    QString clipDir_;
    bool rendering_ = false;
};

} // namespace underfoot::gui
