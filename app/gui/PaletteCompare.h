// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The sound palette's "compare with a recording" panel: the current settings'
/// render beside chosen reference recordings — a typical step's spectrogram of each (same colour
/// scale), their band energies, the realism distance of realism/Distance.h with its top
/// contributing descriptors — recomputed on a worker thread (debounced, stale results dropped)
/// whenever a parameter changes; and "Fit to recording" (realism::fitSurface on a worker thread,
/// progress, cancel, apply to the palette, save with its [provenance]).
///
/// Level-invariant like `underfoot compare`: every descriptor is, and each spectrogram is shown
/// in dB re its own step's peak.
#include "app/gui/PalettePlots.h"
#include "engine/control/VirtualWalker.h"
#include "realism/Compare.h"
#include "realism/Fit.h"

#include <QFuture>
#include <QPointer>
#include <QTemporaryDir>
#include <QWidget>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

class QComboBox;
class QLabel;
class QPushButton;
class QProgressBar;
class QSpinBox;
class QTimer;

namespace underfoot::gui {

/// What the panel needs from the palette (PaletteView sets these).
struct PaletteHooks {
    /// The preset file being edited ("" when none).
    std::function<QString()> surfaceFile;
    /// The current settings as a self-contained preset text with this id and name; throws on a
    /// preset that cannot be written.
    std::function<QString(const QString& id, const QString& name)> presetText;
    /// The virtual walker of the palette.
    std::function<engine::WalkerParameters()> walker;
    /// Puts a preset's parameter values into the palette; returns "" or the problem.
    std::function<QString(const QString& presetText)> apply;
    /// Where "Save fitted preset…" proposes to write (the palette's presets folder).
    QString presetsDir;
};

/// Reference recordings with their steps described (computed on a worker thread).
struct PaletteReference {
    QString label; ///< what was chosen, for people
    std::vector<realism::Recording> recordings;
    realism::AnalysisOptions options; ///< band limited to what the recordings and render share
    std::vector<realism::StepDescriptors> steps;
    StepSpectrogram example; ///< a typical recorded step

    /// The recordings' steps heard through a room (realism::throughRoom), computed by the first
    /// comparison in that room and reused by the next ones (comparison jobs share the reference).
    /// Throws std::runtime_error when the recordings hold no step in the room.
    std::shared_ptr<const std::vector<realism::StepDescriptors>>
    stepsInRoom(const engine::ReverbSpec& room) const;

  private:
    mutable std::mutex roomedMutex_;
    mutable std::map<std::string, std::shared_ptr<const std::vector<realism::StepDescriptors>>>
        roomed_; ///< by impulse response, wet and dry level
};

/// The outcome of one comparison request.
struct PaletteComparison {
    quint64 generation = 0;
    QString error;
    realism::Comparison comparison;
    StepSpectrogram example; ///< a typical step of the render
    QString room;            ///< the settings' room the reference was heard through (empty: none)
};

/// The outcome of a fit.
struct PaletteFitOutcome {
    QString error;
    bool cancelled = false;
    realism::FitResult result;
};

class PaletteCompare : public QWidget {
    Q_OBJECT
  public:
    PaletteCompare(PaletteHooks hooks, QWidget* parent = nullptr);
    ~PaletteCompare() override;

    /// Folder of the recordings cache (manifest.csv): $UNDERFOOT_RECORDINGS or build/recordings
    /// by default.
    void setRecordingsCache(const QString& dir);
    QString recordingsCache() const { return cacheDir_; }
    /// Reference = the cache's recordings of `material`; false (and a message) when the cache or
    /// such recordings are missing. Loading runs on a worker thread (referenceReady).
    bool useMaterial(const QString& material);
    /// Reference = these files and folders (audio below the folders); false when one is missing.
    bool useFiles(const QStringList& paths);
    bool hasReference() const { return reference_ != nullptr; }
    /// The surface changed: the material choice follows it.
    void surfaceChanged();
    /// A parameter or the walker changed: recompare after a short pause (debounced).
    void settingsChanged();
    /// Recompare now (on the worker thread).
    void compareNow();

    /// Length of the rendered walk compared (default 6 s, as `underfoot fit`).
    void setRenderSeconds(double seconds) { renderSeconds_ = seconds; }
    /// The render compared: the palette's walker, renderSeconds, seed 11, 48 kHz.
    realism::RenderSpec renderSpec() const;

    /// Latest distance (NaN before the first comparison or after a failed one).
    double distance() const;
    const std::optional<PaletteComparison>& lastComparison() const { return last_; }
    QString distanceText() const;
    QString message() const;
    const PaletteReference* reference() const { return reference_.get(); }
    const SpectrogramPlot* syntheticPlot() const { return synPlot_; }
    const SpectrogramPlot* referencePlot() const { return refPlot_; }

    /// Starts realism::fitSurface on the current settings against the reference; false (and a
    /// message) when it cannot start.
    bool startFit(int maxEvaluations);
    /// Stops the running fit after the evaluation under way.
    void cancelFit();
    bool fitRunning() const;
    const std::optional<PaletteFitOutcome>& lastFit() const { return fit_; }
    /// Puts the fitted parameters into the palette; false (and a message) otherwise.
    bool applyFit();
    /// Writes the fitted preset (with its [provenance]) to `path`; false (and a message).
    bool saveFit(const QString& path);

  signals:
    void referenceReady();
    void referenceFailed(const QString& message);
    void compared(double distance);
    void compareFailed(const QString& message);
    void fitProgress(int evaluation, int budget, double best);
    void fitFinished(bool ok);

  private:
    void setMessage(const QString& text, bool error);
    void startReference(std::vector<realism::Recording> recordings, const QString& label);
    void referenceDone(quint64 generation, std::shared_ptr<PaletteReference> ref,
                       const QString& error);
    void comparisonDone(const PaletteComparison& c);
    void fitEvaluated(int evaluation, int budget, double distance, double best);
    void fitDone(const PaletteFitOutcome& outcome);
    void showComparison(const PaletteComparison& c);
    void chooseFiles();
    void chooseFolder();
    void chooseCache();
    void saveFitAs();

    PaletteHooks hooks_;
    QString cacheDir_;
    QTemporaryDir scratch_;
    double renderSeconds_ = 6.0;
    std::shared_ptr<const PaletteReference> reference_;
    quint64 referenceGeneration_ = 0, generation_ = 0;
    QString referenceMaterial_; ///< "" when the reference is files chosen by the user
    bool busy_ = false, pending_ = false, fitRunning_ = false;
    std::optional<PaletteComparison> last_;
    std::optional<PaletteFitOutcome> fit_;
    int fitBudget_ = 0;
    std::shared_ptr<std::atomic<bool>> cancel_;
    QFuture<void> referenceJob_, compareJob_, fitJob_;

    QComboBox* material_;
    QLabel* referenceLabel_;
    QLabel* distance_;
    QLabel* contributors_;
    QLabel* message_;
    SpectrogramPlot* synPlot_;
    SpectrogramPlot* refPlot_;
    BandBars* bands_;
    QTimer* debounce_;
    QSpinBox* budget_;
    QPushButton* fitButton_;
    QPushButton* cancelButton_;
    QPushButton* applyButton_;
    QPushButton* saveButton_;
    QProgressBar* progress_;
    QLabel* fitLabel_;
};

} // namespace underfoot::gui
