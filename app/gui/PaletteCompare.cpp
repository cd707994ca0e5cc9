// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/PaletteCompare.h"
#include "app/gui/QtText.h"

#include "engine/surfaces/Surface.h"
#include "realism/Distance.h"
#include "realism/Recordings.h"

#include <fmt/core.h>

#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrent>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>

namespace underfoot::gui {

namespace {
namespace fs = std::filesystem;

constexpr double kRenderRateHz = 48000;
constexpr std::uint64_t kRenderSeed = 11; // as `underfoot fit`

/// The middle step of a buffer (as realism::compareAudio's pictures), at the analysis rate.
std::vector<float> typicalStep(const engine::AudioBuffer& audio,
                               const realism::AnalysisOptions& o) {
    const auto x = realism::analysisSignal(audio, o);
    const auto spans = realism::segmentSteps(x, o.analysisRateHz, o);
    if (spans.empty()) return {};
    const auto& s = spans[spans.size() / 2];
    return {x.begin() + static_cast<long>(s.begin), x.begin() + static_cast<long>(s.end)};
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::trunc);
    out << text;
    if (!out) throw std::runtime_error(path + ": cannot write the palette's preset");
}

QString stemOf(const QString& file) {
    return QFileInfo(file).completeBaseName();
}

QString valueText(double v, const char* unit) {
    const QString u = QString::fromLatin1(unit);
    if (u == "s") return QString("%1 ms").arg(v * 1e3, 0, 'f', v < 0.01 ? 1 : 0);
    if (u == "Hz") return QString("%1 Hz").arg(v, 0, 'f', 0);
    if (u == "dB") return QString("%1 dB").arg(v, 0, 'f', 1);
    return QString("%1 %2").arg(v, 0, 'g', 3).arg(u);
}
} // namespace

PaletteCompare::PaletteCompare(PaletteHooks hooks, QWidget* parent)
    : QWidget(parent), hooks_(std::move(hooks)),
      cacheDir_(QString::fromStdString(realism::defaultRecordingsDir())) {
    // Renders, descriptors and spectrograms plan FFTs on worker threads while the other views
    // may do the same: every plan in Underfoot is made under engine::fftwPlannerMutex()
    // (engine/dsp/RealFft.h), so no FFTW thread support is needed.
    auto* useMaterial = new QPushButton(tr("Recordings of this &material:"), this);
    useMaterial->setAccessibleName(tr("Compare with the cached recordings of the chosen material"));
    material_ = new QComboBox(this);
    material_->setAccessibleName(tr("Material of the reference recordings"));
    for (const auto& m : realism::knownMaterials()) material_->addItem(q(m));
    auto* fileButton = new QPushButton(tr("Reference &file…"), this);
    fileButton->setAccessibleName(tr("Compare with recorded audio files"));
    auto* folderButton = new QPushButton(tr("Reference f&older…"), this);
    folderButton->setAccessibleName(tr("Compare with every audio file below a folder"));
    auto* cacheButton = new QPushButton(tr("Recordings cache…"), this);
    cacheButton->setAccessibleName(tr("Choose the recordings cache (folder with manifest.csv)"));
    referenceLabel_ = new QLabel(this);
    referenceLabel_->setWordWrap(true);
    referenceLabel_->setText(
        tr("No reference recording chosen. Cache: %1").arg(QDir::toNativeSeparators(cacheDir_)));

    synPlot_ = new SpectrogramPlot(this);
    synPlot_->setAccessibleName(tr("Spectrogram of a step of the current settings"));
    synPlot_->clear(tr("Current settings"));
    refPlot_ = new SpectrogramPlot(this);
    refPlot_->setAccessibleName(tr("Spectrogram of a step of the reference recording"));
    refPlot_->clear(tr("Reference recording"));
    bands_ = new BandBars(this);
    bands_->setAccessibleName(tr("Band energies of the current settings and the reference"));

    distance_ = new QLabel(tr("Distance: choose a reference recording first."), this);
    distance_->setAccessibleName(tr("Realism distance"));
    distance_->setWordWrap(true);
    contributors_ = new QLabel(this);
    contributors_->setWordWrap(true);
    contributors_->setAccessibleName(tr("Descriptors contributing most to the distance"));
    contributors_->setTextInteractionFlags(Qt::TextSelectableByMouse);

    fitButton_ = new QPushButton(tr("Fi&t to recording"), this);
    fitButton_->setAccessibleName(
        tr("Fit the current settings to the reference recordings on a worker thread"));
    budget_ = new QSpinBox(this);
    budget_->setRange(1, 500);
    budget_->setValue(40);
    budget_->setSuffix(tr(" evaluations"));
    budget_->setAccessibleName(tr("Evaluation budget of the fit"));
    cancelButton_ = new QPushButton(tr("Cancel fit"), this);
    cancelButton_->setEnabled(false);
    progress_ = new QProgressBar(this);
    progress_->setAccessibleName(tr("Fit progress"));
    progress_->setRange(0, 1);
    progress_->setValue(0);
    progress_->setFormat(tr("no fit running"));
    applyButton_ = new QPushButton(tr("&Apply fitted values"), this);
    applyButton_->setEnabled(false);
    saveButton_ = new QPushButton(tr("Save fitted preset…"), this);
    saveButton_->setEnabled(false);
    fitLabel_ = new QLabel(this);
    fitLabel_->setWordWrap(true);
    fitLabel_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    message_ = new QLabel(this);
    message_->setWordWrap(true);
    message_->setTextInteractionFlags(Qt::TextSelectableByMouse);

    auto* refRow = new QHBoxLayout;
    refRow->addWidget(useMaterial);
    refRow->addWidget(material_);
    refRow->addWidget(fileButton);
    refRow->addWidget(folderButton);
    refRow->addWidget(cacheButton);
    refRow->addStretch(1);
    auto* plots = new QHBoxLayout;
    plots->addWidget(synPlot_, 1);
    plots->addWidget(refPlot_, 1);
    plots->addWidget(bands_, 1);
    auto* fitRow = new QHBoxLayout;
    fitRow->addWidget(fitButton_);
    fitRow->addWidget(budget_);
    fitRow->addWidget(cancelButton_);
    fitRow->addWidget(progress_, 1);
    fitRow->addWidget(applyButton_);
    fitRow->addWidget(saveButton_);
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addLayout(refRow);
    layout->addWidget(referenceLabel_);
    layout->addLayout(plots, 1);
    layout->addWidget(distance_);
    layout->addWidget(contributors_);
    layout->addLayout(fitRow);
    layout->addWidget(fitLabel_);
    layout->addWidget(message_);

    debounce_ = new QTimer(this);
    debounce_->setSingleShot(true);
    debounce_->setInterval(300);
    connect(debounce_, &QTimer::timeout, this, &PaletteCompare::compareNow);
    connect(useMaterial, &QPushButton::clicked, this,
            [this] { this->useMaterial(material_->currentText()); });
    connect(fileButton, &QPushButton::clicked, this, &PaletteCompare::chooseFiles);
    connect(folderButton, &QPushButton::clicked, this, &PaletteCompare::chooseFolder);
    connect(cacheButton, &QPushButton::clicked, this, &PaletteCompare::chooseCache);
    connect(fitButton_, &QPushButton::clicked, this, [this] { startFit(budget_->value()); });
    connect(cancelButton_, &QPushButton::clicked, this, &PaletteCompare::cancelFit);
    connect(applyButton_, &QPushButton::clicked, this, &PaletteCompare::applyFit);
    connect(saveButton_, &QPushButton::clicked, this, &PaletteCompare::saveFitAs);
}

PaletteCompare::~PaletteCompare() {
    // The jobs post their results to this object: let them finish first (a fit stops after the
    // evaluation under way).
    if (cancel_) cancel_->store(true);
    referenceJob_.waitForFinished();
    compareJob_.waitForFinished();
    fitJob_.waitForFinished();
}

void PaletteCompare::setMessage(const QString& text, bool error) {
    message_->setText(text);
    message_->setStyleSheet(error ? "QLabel { color: #a00; }" : "QLabel { color: #176f2c; }");
}

QString PaletteCompare::message() const {
    return message_->text();
}
QString PaletteCompare::distanceText() const {
    return distance_->text();
}
double PaletteCompare::distance() const {
    return last_ && last_->error.isEmpty() ? last_->comparison.distance
                                           : std::numeric_limits<double>::quiet_NaN();
}
bool PaletteCompare::fitRunning() const {
    return fitRunning_;
}

realism::RenderSpec PaletteCompare::renderSpec() const {
    realism::RenderSpec spec;
    spec.walker = hooks_.walker ? hooks_.walker().toString() : "cadence=100";
    spec.seconds = renderSeconds_;
    spec.seed = kRenderSeed;
    spec.rateHz = kRenderRateHz;
    return spec;
}

void PaletteCompare::setRecordingsCache(const QString& dir) {
    cacheDir_ = dir;
    if (!reference_)
        referenceLabel_->setText(tr("No reference recording chosen. Cache: %1")
                                     .arg(QDir::toNativeSeparators(cacheDir_)));
}

bool PaletteCompare::useMaterial(const QString& material) {
    std::vector<realism::Recording> all;
    try {
        all = realism::loadManifest(cacheDir_.toStdString());
    } catch (const std::exception& e) {
        setMessage(tr("No recordings to compare with: %1. Or choose a cache folder, a reference "
                      "file or a folder of recordings.")
                       .arg(q(e.what())),
                   true);
        return false;
    }
    std::vector<realism::Recording> chosen;
    QStringList sources;
    for (const auto& r : all)
        if (q(r.material) == material) {
            chosen.push_back(r);
            if (!sources.contains(q(r.source))) sources << q(r.source);
        }
    if (chosen.empty()) {
        setMessage(tr("The recordings cache %1 holds no recording of %2 (manifest.csv). Choose "
                      "another material, a reference file or a folder.")
                       .arg(QDir::toNativeSeparators(cacheDir_), material),
                   true);
        return false;
    }
    const auto missing = std::find_if(chosen.begin(), chosen.end(),
                                      [](const auto& r) { return !fs::exists(r.path); });
    if (missing != chosen.end()) {
        setMessage(tr("%1: listed in the manifest but missing; re-create the cache with `bash "
                      "scripts/fetch-recordings.sh %2`.")
                       .arg(q(missing->path), QDir::toNativeSeparators(cacheDir_)),
                   true);
        return false;
    }
    referenceMaterial_ = material;
    material_->setCurrentText(material);
    const QString label =
        tr("%1 of %2 from %3 (%4)")
            .arg(counted(static_cast<long long>(chosen.size()), tr("recording"), tr("recordings")),
                 material, sources.join(", "), QDir::toNativeSeparators(cacheDir_));
    startReference(std::move(chosen), label);
    return true;
}

bool PaletteCompare::useFiles(const QStringList& paths) {
    if (paths.isEmpty()) {
        setMessage(tr("No reference recording chosen."), true);
        return false;
    }
    std::vector<std::string> list;
    for (const auto& p : paths) list.push_back(p.toStdString());
    std::vector<realism::Recording> recordings;
    try {
        recordings = realism::collectRecordings(list);
    } catch (const std::exception& e) {
        setMessage(tr("Reference not usable: %1").arg(q(e.what())), true);
        return false;
    }
    referenceMaterial_.clear();
    const QString label = recordings.size() == 1
                              ? QDir::toNativeSeparators(q(recordings.front().path))
                              : tr("%1 files from %2").arg(recordings.size()).arg(paths.join(", "));
    startReference(std::move(recordings), label);
    return true;
}

std::shared_ptr<const std::vector<realism::StepDescriptors>>
PaletteReference::stepsInRoom(const engine::ReverbSpec& room) const {
    const auto key = fmt::format("{}|{}|{}", room.impulseResponse, room.wetDb, room.dryDb);
    std::lock_guard lock(roomedMutex_);
    if (auto it = roomed_.find(key); it != roomed_.end()) return it->second;
    auto described = std::make_shared<std::vector<realism::StepDescriptors>>(
        realism::describeRecordings(recordings, options, room));
    if (described->empty())
        throw std::runtime_error(
            "the reference heard through the settings' room holds no footstep");
    roomed_[key] = described;
    return described;
}

void PaletteCompare::startReference(std::vector<realism::Recording> recordings,
                                    const QString& label) {
    const quint64 generation = ++referenceGeneration_;
    referenceLabel_->setText(tr("Reference: %1 — reading the recordings…").arg(label));
    setMessage(QString(), false);
    referenceJob_ =
        QtConcurrent::run([this, generation, recordings = std::move(recordings), label] {
            auto ref = std::make_shared<PaletteReference>();
            QString error;
            try {
                ref->label = label;
                ref->recordings = recordings;
                ref->options.maxHz = realism::sharedMaxHz(recordings, kRenderRateHz);
                for (const auto& r : recordings) {
                    const auto audio = engine::readAudioFile(r.path);
                    const auto steps = realism::describeSteps(audio, ref->options);
                    ref->steps.insert(ref->steps.end(), steps.begin(), steps.end());
                    if (ref->example.empty() && !steps.empty())
                        ref->example =
                            stepSpectrogram(typicalStep(audio, ref->options),
                                            ref->options.analysisRateHz, ref->options.maxHz);
                }
                if (ref->steps.empty())
                    error = tr("No footstep found in the reference (%1): every file is silent or "
                               "holds no onset %2 dB above its quietest part. Choose other "
                               "recordings.")
                                .arg(label)
                                .arg(ref->options.stepThresholdDb);
            } catch (const std::exception& e) {
                error = tr("Reference not usable: %1").arg(q(e.what()));
            }
            QMetaObject::invokeMethod(
                this, [this, generation, ref, error] { referenceDone(generation, ref, error); },
                Qt::QueuedConnection);
        });
}

void PaletteCompare::referenceDone(quint64 generation, std::shared_ptr<PaletteReference> ref,
                                   const QString& error) {
    if (generation != referenceGeneration_) return; // another reference was chosen since
    if (!error.isEmpty()) {
        reference_.reset();
        last_.reset();
        referenceLabel_->setText(tr("No usable reference."));
        refPlot_->clear(tr("Reference recording"));
        bands_->clear();
        distance_->setText(tr("Distance: no reference."));
        contributors_->clear();
        setMessage(error, true);
        emit referenceFailed(error);
        return;
    }
    reference_ = ref;
    referenceLabel_->setText(
        tr("Reference: %1 — %2; compared on %3 Hz – %4 kHz (the band render and recordings "
           "share)")
            .arg(ref->label)
            .arg(counted(static_cast<long long>(ref->steps.size()), tr("step"), tr("steps")))
            .arg(ref->options.minHz, 0, 'f', 0)
            .arg(ref->options.maxHz / 1000, 0, 'f', 2));
    refPlot_->setSpectrogram(ref->example, tr("Reference: a typical recorded step"));
    emit referenceReady();
    compareNow();
}

void PaletteCompare::surfaceChanged() {
    const QString file = hooks_.surfaceFile ? hooks_.surfaceFile() : QString();
    const QString material = q(realism::materialOfSurface(stemOf(file).toStdString()));
    if (!material.isEmpty()) material_->setCurrentText(material);
    if (!referenceMaterial_.isEmpty() && !material.isEmpty() && material != referenceMaterial_)
        useMaterial(material); // the reference follows the surface's material
    else
        settingsChanged();
}

void PaletteCompare::settingsChanged() {
    if (!reference_) return;
    ++generation_; // a comparison under way is of the old settings: its result will be dropped
    debounce_->start();
}

void PaletteCompare::compareNow() {
    debounce_->stop();
    if (!reference_) return;
    if (busy_ || fitRunning_) {
        pending_ = true; // compared again when the job under way (or the fit) is done
        return;
    }
    const QString file = hooks_.surfaceFile ? hooks_.surfaceFile() : QString();
    if (file.isEmpty()) {
        distance_->setText(tr("Distance: pick a surface first."));
        return;
    }
    std::string text;
    try {
        const QString id = stemOf(file) + "_palette";
        text = hooks_.presetText(id, id).toStdString();
    } catch (const std::exception& e) {
        const QString error = tr("The current settings do not make a preset: %1").arg(q(e.what()));
        distance_->setText(tr("Distance: not computed."));
        setMessage(error, true);
        emit compareFailed(error);
        return;
    }
    const quint64 generation = ++generation_;
    busy_ = true;
    distance_->setText(distance_->text().startsWith(tr("Distance to the reference"))
                           ? distance_->text()
                           : tr("Distance: computing…"));
    const std::string path =
        QDir(scratch_.path()).filePath(QString("compare_%1.toml").arg(generation)).toStdString();
    compareJob_ =
        QtConcurrent::run([this, generation, text, path, spec = renderSpec(), ref = reference_] {
            PaletteComparison c;
            c.generation = generation;
            try {
                writeText(path, text);
                const auto audio = realism::renderForComparison(path, spec);
                const auto steps = realism::describeSteps(audio, ref->options);
                if (steps.empty())
                    throw std::runtime_error("the render of the current settings holds no footstep "
                                             "(silent? raise the gains or the walker's mass)");
                // Settings with a room ([reverb]): the reference is heard through the same
                // room, as `underfoot compare` does (the recordings are dry).
                if (const auto room = realism::roomOfSurface(path)) {
                    c.comparison = realism::compareSteps(steps, *ref->stepsInRoom(*room));
                    c.room = QString::fromStdString(room->impulseResponse);
                } else {
                    c.comparison = realism::compareSteps(steps, ref->steps);
                }
                c.example = stepSpectrogram(typicalStep(audio, ref->options),
                                            ref->options.analysisRateHz, ref->options.maxHz);
            } catch (const std::exception& e) {
                c.error = q(e.what());
            }
            std::error_code ec;
            fs::remove(path, ec);
            QMetaObject::invokeMethod(
                this, [this, c] { comparisonDone(c); }, Qt::QueuedConnection);
        });
}

void PaletteCompare::comparisonDone(const PaletteComparison& c) {
    busy_ = false;
    if (pending_) { // the settings changed while it ran: this result is stale
        pending_ = false;
        compareNow();
        return;
    }
    if (c.generation != generation_) return;
    showComparison(c);
}

void PaletteCompare::showComparison(const PaletteComparison& c) {
    last_ = c;
    if (!c.error.isEmpty()) {
        distance_->setText(tr("Distance: not computed."));
        contributors_->clear();
        synPlot_->clear(tr("Current settings"));
        const QString text = tr("Comparison failed: %1").arg(c.error);
        setMessage(text, true);
        emit compareFailed(text);
        return;
    }
    const auto& cmp = c.comparison;
    distance_->setText(
        tr("<b>Distance to the reference: %1</b> (mean robust z over %2 descriptors: 0 = on the "
           "recorded medians, about 1 = one recorded spread away; level-invariant) · %3 steps "
           "rendered (%4), %5 recorded%6")
            .arg(cmp.distance, 0, 'f', 2)
            .arg(static_cast<int>(realism::kDescriptorCount))
            .arg(cmp.syntheticSteps)
            .arg(q(renderSpec().walker))
            .arg(cmp.realSteps)
            .arg(c.room.isEmpty()
                     ? QString()
                     : tr(", heard through the settings' room (%1) like the render").arg(c.room)));
    std::vector<int> order(realism::kDescriptorCount);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return cmp.d[std::size_t(a)].z > cmp.d[std::size_t(b)].z;
    });
    QStringList top;
    for (int i = 0; i < 3; ++i) {
        const int d = order[std::size_t(i)];
        const auto& x = cmp.d[std::size_t(d)];
        const auto& info = realism::descriptorInfo(d);
        top << tr("%1: %2 here, recorded %3 (IQR %4 – %5), z = %6")
                   .arg(QString::fromLatin1(info.name), valueText(x.synthetic, info.unit),
                        valueText(x.realMedian, info.unit), valueText(x.realQ1, info.unit),
                        valueText(x.realQ3, info.unit))
                   .arg(x.z, 0, 'f', 2);
    }
    contributors_->setText(tr("Largest differences: %1").arg(top.join("; ")));
    synPlot_->setSpectrogram(c.example, tr("Current settings: a typical rendered step"));
    const double span = std::max(c.example.seconds, reference_ ? reference_->example.seconds : 0);
    synPlot_->setTimeSpan(span);
    refPlot_->setTimeSpan(span);
    const int bandIds[] = {realism::kBandLow, realism::kBandLowMid, realism::kBandMid,
                           realism::kBandHigh};
    std::vector<double> rec, syn;
    for (int b : bandIds) {
        rec.push_back(cmp.d[std::size_t(b)].realMedian);
        syn.push_back(cmp.d[std::size_t(b)].synthetic);
    }
    const double top4 = reference_ ? reference_->options.maxHz : 16000;
    bands_->setBands({tr("20–250 Hz"), tr("0.25–1 kHz"), tr("1–4 kHz"),
                      tr("4–%1 kHz").arg(std::min(16000.0, top4) / 1000, 0, 'g', 3)},
                     rec, syn);
    if (message_->styleSheet().contains("#a00") && !fitRunning_) setMessage(QString(), false);
    emit compared(cmp.distance);
}

bool PaletteCompare::startFit(int maxEvaluations) {
    if (fitRunning_) return false;
    if (!reference_) {
        setMessage(tr("Choose reference recordings first (recordings of this material, a file or "
                      "a folder): the fit needs recorded steps to fit to."),
                   true);
        return false;
    }
    const QString file = hooks_.surfaceFile ? hooks_.surfaceFile() : QString();
    if (file.isEmpty()) {
        setMessage(tr("Pick a surface first."), true);
        return false;
    }
    const QString id = stemOf(file) + "_fitted";
    std::string text;
    try {
        text = hooks_.presetText(id, id).toStdString();
    } catch (const std::exception& e) {
        setMessage(tr("The current settings do not make a preset: %1").arg(q(e.what())), true);
        return false;
    }
    const std::string path = QDir(scratch_.path()).filePath(id + ".toml").toStdString();
    realism::FitOptions options;
    options.spec = renderSpec();
    options.maxEvaluations = maxEvaluations;
    fitBudget_ = maxEvaluations;
    budget_->setValue(maxEvaluations);
    cancel_ = std::make_shared<std::atomic<bool>>(false);
    fitRunning_ = true;
    fit_.reset();
    fitButton_->setEnabled(false);
    cancelButton_->setEnabled(true);
    applyButton_->setEnabled(false);
    saveButton_->setEnabled(false);
    progress_->setRange(0, maxEvaluations);
    progress_->setValue(0);
    progress_->setFormat(
        tr("evaluation 0 of %1 · rendering the current settings").arg(maxEvaluations));
    fitLabel_->setText(tr("Fitting %1 to %2…").arg(stemOf(file), reference_->label));
    setMessage(QString(), false);
    options.progress = [this, cancel = cancel_](int k, int budget, double d, double best) {
        QMetaObject::invokeMethod(
            this, [this, k, budget, d, best] { fitEvaluated(k, budget, d, best); },
            Qt::QueuedConnection);
        return !cancel->load();
    };
    fitJob_ = QtConcurrent::run(
        [this, path, text, options, recordings = reference_->recordings, cancel = cancel_] {
            PaletteFitOutcome out;
            try {
                writeText(path, text);
                out.result = realism::fitSurface(path, recordings, options);
            } catch (const std::exception& e) {
                out.error = q(e.what());
            }
            out.cancelled = cancel->load();
            std::error_code ec;
            fs::remove(path, ec);
            QMetaObject::invokeMethod(
                this, [this, out] { fitDone(out); }, Qt::QueuedConnection);
        });
    return true;
}

void PaletteCompare::cancelFit() {
    if (!fitRunning_ || !cancel_) return;
    cancel_->store(true);
    cancelButton_->setEnabled(false);
    progress_->setFormat(progress_->format() + tr(" · cancelling after this evaluation"));
}

void PaletteCompare::fitEvaluated(int evaluation, int budget, double distance, double best) {
    if (!fitRunning_) return;
    if (budget != fitBudget_) { // a solid is refined from two starting points (Fit.h)
        fitBudget_ = budget;
        progress_->setRange(0, budget);
    }
    progress_->setValue(std::min(evaluation, fitBudget_));
    progress_->setFormat(tr("evaluation %1 of %2 · this one %3 · best distance so far %4")
                             .arg(evaluation)
                             .arg(fitBudget_)
                             .arg(distance, 0, 'f', 3)
                             .arg(best, 0, 'f', 3));
    emit fitProgress(evaluation, fitBudget_, best);
}

void PaletteCompare::fitDone(const PaletteFitOutcome& outcome) {
    fitRunning_ = false;
    fit_ = outcome;
    fitButton_->setEnabled(true);
    cancelButton_->setEnabled(false);
    const auto& r = outcome.result;
    if (!outcome.error.isEmpty()) {
        progress_->setFormat(tr("fit failed"));
        fitLabel_->clear();
        setMessage(tr("Fit failed: %1").arg(outcome.error), true);
    } else {
        QStringList knobs;
        for (const auto& k : r.knobs)
            knobs << QString("%1 %2").arg(q(k.name)).arg(k.value, 0, 'f', 2);
        progress_->setFormat(
            outcome.cancelled
                ? tr("cancelled after evaluation %1 of %2").arg(r.evaluations).arg(fitBudget_)
                : tr("done: %1").arg(counted(r.evaluations, tr("evaluation"), tr("evaluations"))));
        fitLabel_->setText(
            tr("%1 Distance before %2 → after %3 (%4 evaluations, %5 s, %6; knobs: %7). Apply "
               "puts the fitted values into the palette; Save writes the fitted preset with its "
               "[provenance].")
                .arg(outcome.cancelled ? tr("Fit cancelled: best settings found so far.")
                                       : tr("Fit done."))
                .arg(r.distanceBefore, 0, 'f', 3)
                .arg(r.distanceAfter, 0, 'f', 3)
                .arg(r.evaluations)
                .arg(r.seconds, 0, 'f', 1)
                .arg(q(r.optimiser), knobs.join(", ")));
        applyButton_->setEnabled(true);
        saveButton_->setEnabled(true);
    }
    emit fitFinished(outcome.error.isEmpty());
    if (pending_) {
        pending_ = false;
        compareNow();
    }
}

bool PaletteCompare::applyFit() {
    if (!fit_ || !fit_->error.isEmpty() || !hooks_.apply) {
        setMessage(tr("No fitted preset to apply: run a fit first."), true);
        return false;
    }
    const QString error = hooks_.apply(q(fit_->result.presetText));
    if (!error.isEmpty()) {
        setMessage(tr("Fitted values not applied: %1").arg(error), true);
        return false;
    }
    setMessage(tr("Fitted values applied to the palette (distance after the fit: %1). Save them "
                  "as a preset with Ctrl+S or Save fitted preset…")
                   .arg(fit_->result.distanceAfter, 0, 'f', 3),
               false);
    return true;
}

bool PaletteCompare::saveFit(const QString& path) {
    if (!fit_ || !fit_->error.isEmpty()) {
        setMessage(tr("No fitted preset to save: run a fit first."), true);
        return false;
    }
    try {
        engine::loadSurfaceFromString(fit_->result.presetText, path.toStdString()); // validates
        QDir().mkpath(QFileInfo(path).absolutePath());
        QFile f(path);
        if (!f.open(QIODevice::WriteOnly | QIODevice::Truncate))
            throw std::runtime_error(path.toStdString() + ": cannot write");
        f.write(QByteArray::fromStdString(fit_->result.presetText));
    } catch (const std::exception& e) {
        setMessage(tr("Fitted preset not saved: %1").arg(q(e.what())), true);
        return false;
    }
    setMessage(tr("Saved the fitted preset with its [provenance] to %1.")
                   .arg(QDir::toNativeSeparators(path)),
               false);
    return true;
}

void PaletteCompare::saveFitAs() {
    const QString file = hooks_.surfaceFile ? hooks_.surfaceFile() : QString();
    const QString dir = hooks_.presetsDir.isEmpty() ? QDir::homePath() : hooks_.presetsDir;
    const QString out = QFileDialog::getSaveFileName(
        this, tr("Save the fitted preset"), QDir(dir).filePath(stemOf(file) + "_fitted.toml"),
        tr("Surface preset (*.toml)"));
    if (!out.isEmpty()) saveFit(out);
}

void PaletteCompare::chooseFiles() {
    const QStringList files = QFileDialog::getOpenFileNames(
        this, tr("Reference recordings"), cacheDir_, tr("Audio (*.wav *.ogg *.flac *.aiff *.aif)"));
    if (!files.isEmpty()) useFiles(files);
}

void PaletteCompare::chooseFolder() {
    const QString dir =
        QFileDialog::getExistingDirectory(this, tr("Folder of reference recordings"), cacheDir_);
    if (!dir.isEmpty()) useFiles({dir});
}

void PaletteCompare::chooseCache() {
    const QString dir = QFileDialog::getExistingDirectory(
        this, tr("Recordings cache (folder with manifest.csv)"), cacheDir_);
    if (dir.isEmpty()) return;
    setRecordingsCache(dir);
    useMaterial(material_->currentText());
}

} // namespace underfoot::gui
