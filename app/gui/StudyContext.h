// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The study the console works on: owns the open StudyStore and tells every view when the study
/// or its data changed (a new answer, a registration, an exclusion).
#include "experiment/Store.h"

#include <QObject>
#include <QString>

#include <memory>

namespace underfoot::gui {

class StudyContext : public QObject {
    Q_OBJECT
  public:
    explicit StudyContext(QObject* parent = nullptr);
    ~StudyContext() override;

    /// Whether a study is open.
    bool hasStudy() const { return store_ != nullptr; }
    /// The open study (only when hasStudy()).
    experiment::StudyStore& store() { return *store_; }
    const experiment::StudyStore& store() const { return *store_; }
    /// Path of the open study file (empty when none).
    QString path() const { return path_; }

    /// Opens a study file. Returns an empty string on success, otherwise a message saying what
    /// went wrong and what to do next (the open study stays open).
    QString openStudy(const QString& path);
    /// Creates a study file from a protocol file and opens it. Same error convention; a bad
    /// protocol lists every problem as file:line:column: message.
    QString createStudy(const QString& path, const QString& protocolPath,
                        const experiment::StudySettings& settings);
    /// Closes the study (views show their empty state).
    void closeStudy();
    /// Tells every view that the study's data changed.
    void notifyDataChanged() { emit dataChanged(); }

  signals:
    /// Another study was opened or the study was closed.
    void studyChanged();
    /// Participants, trials, answers or exclusions changed.
    void dataChanged();
    /// A session started (true) or ended (false) in the Run view.
    void sessionActiveChanged(bool active);

  private:
    std::unique_ptr<experiment::StudyStore> store_;
    QString path_;
};

/// A protocol loader error as text: every problem on its own line, then what to do next.
QString describeProtocolError(const std::exception& error, const QString& protocolPath);

} // namespace underfoot::gui
