// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The console set-up the GUI tests share: a private home (configuration and data folders in a
// temporary directory, so that no test reads or writes the user's), a main window without the
// demo study and without audio, shown offscreen, and the few steps every test takes through it.
#include "app/gui/MainWindow.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"
#include "app/gui/StudyView.h"

#include <QComboBox>
#include <QCoreApplication>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QTemporaryDir>
#include <QTest>

#include <memory>

namespace underfoot::gui_test {

/// The push button of `root` whose accessible name is `accessibleName` (nullptr when none).
inline QPushButton* button(QWidget* root, const QString& accessibleName) {
    for (auto* b : root->findChildren<QPushButton*>())
        if (b->accessibleName() == accessibleName) return b;
    return nullptr;
}

/// One test case's console: its temporary home and the windows opened in it.
class Console {
  public:
    /// Call from initTestCase(): points XDG_CONFIG_HOME and XDG_DATA_HOME into the home.
    bool prepare() {
        if (!home_.isValid()) return false;
        qputenv("XDG_CONFIG_HOME", home_.filePath("config").toUtf8());
        qputenv("XDG_DATA_HOME", home_.filePath("share").toUtf8());
        QCoreApplication::setApplicationName("underfoot-gui-test");
        return true;
    }

    /// A path inside the home.
    QString path(const QString& name) const { return home_.filePath(name); }

    /// A shown main window whose data folder is `dataDir` (inside the home), without the demo
    /// study and without opening the audio device.
    std::unique_ptr<gui::MainWindow> open(const QString& dataDir = "data") const {
        gui::MainWindow::Options o;
        o.dataDir = home_.filePath(dataDir);
        o.createDemo = false;
        o.startAudio = false;
        auto w = std::make_unique<gui::MainWindow>(o);
        w->show();
        return w;
    }

    /// Creates a study as the experimenter does: the Study view's protocol and file, then
    /// "Create study". True when the window then holds that study.
    static bool createByClicking(gui::MainWindow& w, const QString& protocol, const QString& file) {
        w.showView(0);
        w.studyView()->protocolBox()->setCurrentText(protocol);
        w.studyView()->fileEdit()->setText(file);
        QTest::mouseClick(button(w.studyView(), "Create study"), Qt::LeftButton);
        return w.context().hasStudy() && w.context().path() == file;
    }

  private:
    QTemporaryDir home_;
};

/// A shipped protocol's path (protocols/NAME).
inline QString shippedProtocol(const QString& name) {
    return QString(UNDERFOOT_SOURCE_DIR) + "/protocols/" + name;
}

} // namespace underfoot::gui_test
