// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The Sound palette: pick a surface, change its physical parameters (units, documented ranges
/// and help from the preset reader), measure the CPU cost of the current settings by rendering
/// a walk offline, render it to a WAV file, listen to it through the live engine, and save the
/// settings as a new preset (TOML) in the user's data folder. Below the parameters, the
/// "compare with a recording · fit" panel (PaletteCompare) follows every change.
#include "engine/control/VirtualWalker.h"

#include <QFutureWatcher>
#include <QTemporaryDir>
#include <QWidget>

#include <map>
#include <memory>
#include <string>

class QListWidget;
class QTableWidget;
class QLabel;
class QDoubleSpinBox;
class QPushButton;

namespace underfoot::gui {

class AudioOutput;
class PaletteCompare;

/// Offline cost of one surface setting.
struct CostMeasurement {
    QString error;
    double audioSeconds = 0;
    double cpuSeconds = 0;
    double percentOfCore = 0; ///< CPU time / audio time x 100 at 48 kHz, block 256
};

class PaletteView : public QWidget {
    Q_OBJECT
  public:
    PaletteView(const QString& dataDir, QWidget* parent = nullptr);

    /// Selects a surface by id (bundled) or preset path; false when it does not load.
    bool selectSurface(const QString& idOrPath);
    /// Sets one parameter (path as listed) and returns false when out of its range.
    bool setParameter(const QString& path, double value);
    /// The preset text with the current values (id and name as given).
    QString currentPresetText(const QString& id, const QString& name) const;
    /// Saves the current settings as `dataDir/presets/<id>.toml`; returns the path or "" and
    /// shows the problem.
    QString saveAs(const QString& id, const QString& name);
    /// Starts the cost measurement on a worker thread; emits costMeasured.
    void measureCost();
    /// Uses `output` for auditions (the Setup view's live engine).
    void setAudioOutput(AudioOutput* output) { audio_ = output; }
    QString costText() const;
    QString message() const;
    QTableWidget* parameterTable() const { return params_; }
    /// The "compare with a recording / fit" panel (PaletteCompare.h).
    PaletteCompare* compareView() const { return compare_; }
    /// Puts the parameter values of a preset of the same layout (e.g. the fit of the current
    /// settings) into the table. A preset of another layout (a fit seeded from recorded modes
    /// may have fewer modes) becomes a new, unsaved entry "<surface> (fitted)" of the list,
    /// selected. Returns "" or the problem (nothing is changed then).
    QString applyPresetText(const QString& text);
    /// The virtual walker set in the view.
    engine::WalkerParameters walkerParameters() const;

  signals:
    void costMeasured(const QString& text);

  private:
    void loadList();
    void showSurface();
    QString writeTemporaryPreset(QString* error) const;
    void audition();
    void renderToWav();
    void setMessage(const QString& text, bool error);
    QString showFittedPreset(const QString& text);

    QString dataDir_;
    QString currentFile_;
    QListWidget* list_;
    QLabel* info_;
    QTableWidget* params_;
    QDoubleSpinBox* cadence_;
    QDoubleSpinBox* mass_;
    QDoubleSpinBox* shoe_;
    QLabel* cost_;
    QLabel* message_;
    QPushButton* costButton_;
    QPushButton* auditionButton_;
    std::map<std::string, double> original_;
    QFutureWatcher<CostMeasurement>* costWatcher_;
    AudioOutput* audio_ = nullptr;
    PaletteCompare* compare_ = nullptr;
    std::unique_ptr<QTemporaryDir> fittedDir_; ///< unsaved fitted presets of another layout
};

} // namespace underfoot::gui
