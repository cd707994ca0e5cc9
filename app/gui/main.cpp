// SPDX-License-Identifier: GPL-3.0-or-later
// underfoot-gui: the experimenter's console.
#include "app/gui/MainWindow.h"
#include "base/Version.h"
#include "engine/dsp/Simd.h"

#include <QApplication>
#include <QCommandLineParser>

#include <cstdio>
#include <string_view>

namespace {
/// --help or --version only print text: they must work without a display (over ssh, in a
/// package's build, for the man page), so they run on Qt's offscreen platform.
bool onlyPrintsText(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        if (a == "-h" || a == "--help" || a == "--help-all" || a == "-?" || a == "-v" ||
            a == "--version")
            return true;
    }
    return false;
}
} // namespace

int main(int argc, char** argv) {
    if (onlyPrintsText(argc, argv) && qEnvironmentVariableIsEmpty("QT_QPA_PLATFORM"))
        qputenv("QT_QPA_PLATFORM", "offscreen");
    if (!underfoot::engine::simdEnvironmentValid()) {
        std::fprintf(stderr, "underfoot-gui: the environment variable UNDERFOOT_SIMD is set to an "
                             "unknown value; expected sse2 or avx (or unset: the CPU's best)\n");
        return 2;
    }
    QApplication app(argc, argv);
    QApplication::setApplicationName("underfoot");
    QApplication::setOrganizationName("underfoot");
    QApplication::setApplicationVersion(underfoot::base::versionLine());
    QCommandLineParser parser;
    parser.setApplicationDescription("Underfoot — the experimenter's console");
    parser.addHelpOption();
    parser.addVersionOption();
    QCommandLineOption studyOption("study", "Open this study file (.db).", "file");
    QCommandLineOption dataOption("data-dir",
                                  "Folder of the demo study and saved presets (default: the "
                                  "user's application data folder).",
                                  "dir");
    QCommandLineOption shotOption("screenshot",
                                  "Render every main view at 1280x800 into DIR as PNG files and "
                                  "exit.",
                                  "dir");
    parser.addOption(studyOption);
    parser.addOption(dataOption);
    parser.addOption(shotOption);
    parser.process(app);

    underfoot::gui::MainWindow::Options options;
    options.studyPath = parser.value(studyOption);
    options.dataDir = parser.value(dataOption);
    options.startAudio = !parser.isSet(shotOption);
    underfoot::gui::MainWindow window(options);
    if (parser.isSet(shotOption)) {
        window.resize(1280, 800);
        window.show();
        const int failures = window.saveScreenshots(parser.value(shotOption));
        return failures == 0 ? 0 : 1;
    }
    window.show();
    return QApplication::exec();
}
