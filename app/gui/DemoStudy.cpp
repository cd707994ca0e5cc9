// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/DemoStudy.h"
#include "base/Version.h"

#include "base/DataDir.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <QDir>
#include <QFileInfo>
#include <QStandardPaths>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

QString bundledDataDir() {
    return QString::fromStdString(base::dataDirectory(base::DataKind::GuiDemo));
}

QString userDataDir(const QString& overrideDir) {
    QString dir = overrideDir;
    if (dir.isEmpty()) dir = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
    if (dir.isEmpty()) dir = QDir::home().filePath(".local/share/underfoot");
    QDir().mkpath(dir);
    return dir;
}

QString demoStudyPath(const QString& dataDir) {
    return QDir(dataDir).filePath("demo_study.db");
}

QString ensureDemoStudy(const QString& dataDir, int simulated) {
    const QString path = demoStudyPath(dataDir);
    if (QFileInfo::exists(path)) return {};
    const QString partial = path + ".partial";
    QFile::remove(partial);
    QFile::remove(partial + "-wal");
    QFile::remove(partial + "-shm");
    try {
        const QString data = bundledDataDir();
        const auto protocol =
            exp::loadProtocol(QDir(data).filePath("demo_walker.toml").toStdString());
        {
            exp::StudySettings settings;
            settings.code = "demo";
            settings.site = "underfoot-gui demo";
            settings.seed = 20111;
            settings.appVersion = underfoot::base::version();
            auto store = exp::StudyStore::create(partial.toStdString(), protocol, settings);
            if (simulated > 0) {
                exp::MatrixByGroup matrices;
                const auto load = [&](const char* file) {
                    return exp::loadConfusionMatrix(QDir(data).filePath(file).toStdString());
                };
                matrices["none"] = load("tvcg2011_exp2_cond1_no_soundscape_confusion.csv");
                matrices["coherent"] = load("tvcg2011_exp2_cond2_coherent_confusion.csv");
                matrices["incoherent"] = load("tvcg2011_exp2_cond3_incoherent_confusion.csv");
                exp::simulateStudy(store, matrices, simulated, {}, "SIM");
            }
        }
        // Only a complete demo study gets its final name (a crash midway leaves no half study).
        if (!QFile::rename(partial, path))
            return QObject::tr("could not rename %1 to %2").arg(partial, path);
        QFile::remove(partial + "-wal");
        QFile::remove(partial + "-shm");
    } catch (const std::exception& e) {
        return QObject::tr("The demo study could not be created: %1")
            .arg(QString::fromStdString(e.what()));
    }
    return {};
}

} // namespace underfoot::gui
