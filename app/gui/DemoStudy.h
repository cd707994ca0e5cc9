// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The bundled defaults of a fresh machine: a demo study (virtual walker, three groups, a few
/// simulated participants) created on first start in the user's data folder.
#include <QString>

namespace underfoot::gui {

/// The folder of the bundled data (demo protocol, confusion matrices).
QString bundledDataDir();
/// The user's data folder (QStandardPaths::AppDataLocation unless `overrideDir` is given);
/// created when missing.
QString userDataDir(const QString& overrideDir = {});
/// Path of the demo study in `dataDir`.
QString demoStudyPath(const QString& dataDir);

/// Creates the demo study in `dataDir` when it does not exist yet, with `simulated` synthetic
/// participants (seeded: the same on every machine). Returns an empty string on success (or
/// when it already exists), otherwise what went wrong.
QString ensureDemoStudy(const QString& dataDir, int simulated = 6);

} // namespace underfoot::gui
