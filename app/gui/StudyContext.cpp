// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/StudyContext.h"

#include "experiment/Protocol.h"

#include <QFileInfo>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

StudyContext::StudyContext(QObject* parent) : QObject(parent) {}
StudyContext::~StudyContext() = default;

QString describeProtocolError(const std::exception& error, const QString& protocolPath) {
    QString text;
    if (const auto* pe = dynamic_cast<const exp::ProtocolError*>(&error)) {
        for (const auto& p : pe->problems()) text += QString::fromStdString(p.toString()) + "\n";
    } else {
        text = QString::fromStdString(error.what()) + "\n";
    }
    text += QObject::tr("Fix %1 at the place named above (line:column), then choose it again.")
                .arg(protocolPath);
    return text;
}

QString StudyContext::openStudy(const QString& path) {
    if (!QFileInfo::exists(path))
        return QObject::tr("%1: no such study file. Choose an existing .db file, or create a new "
                           "study from a protocol.")
            .arg(path);
    try {
        auto store = std::make_unique<exp::StudyStore>(exp::StudyStore::open(path.toStdString()));
        store_ = std::move(store);
        path_ = path;
    } catch (const std::exception& e) {
        return QObject::tr("%1\nThe study was not opened. Check that the file is an Underfoot "
                           "study (.db) written by this or an older version.")
            .arg(QString::fromStdString(e.what()));
    }
    emit studyChanged();
    emit dataChanged();
    return {};
}

QString StudyContext::createStudy(const QString& path, const QString& protocolPath,
                                  const exp::StudySettings& settings) {
    exp::Protocol protocol;
    try {
        protocol = exp::loadProtocol(protocolPath.toStdString());
    } catch (const std::exception& e) {
        return describeProtocolError(e, protocolPath);
    }
    if (QFileInfo::exists(path))
        return QObject::tr("%1 already exists. Open it instead, or choose another file name for "
                           "the new study.")
            .arg(path);
    try {
        auto store = std::make_unique<exp::StudyStore>(
            exp::StudyStore::create(path.toStdString(), protocol, settings));
        store_ = std::move(store);
        path_ = path;
    } catch (const std::exception& e) {
        return QObject::tr("%1\nThe study was not created. Check that the folder is writable.")
            .arg(QString::fromStdString(e.what()));
    }
    emit studyChanged();
    emit dataChanged();
    return {};
}

void StudyContext::closeStudy() {
    store_.reset();
    path_.clear();
    emit studyChanged();
    emit dataChanged();
}

} // namespace underfoot::gui
