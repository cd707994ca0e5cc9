// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/PaletteView.h"
#include "app/gui/QtText.h"

#include <cstring>

#include "app/gui/AudioOutput.h"
#include "app/gui/PaletteCompare.h"
#include "app/gui/PresetEdit.h"
#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"

#include <QDir>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileDialog>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QInputDialog>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QRegularExpression>
#include <QShortcut>
#include <QSplitter>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrent>

#include <cmath>
#include <fstream>

namespace underfoot::gui {

namespace eng = underfoot::engine;

namespace {
enum Column { PathCol, ValueCol, UnitCol, RangeCol };

/// A parameter as people read it, from its declared path: "layer[1].modes[3].freq_hz" ->
/// "Layer 1 · mode 3 · frequency" (the unit has its own column, the help is the tooltip).
QString parameterLabel(const std::string& path) {
    static const std::pair<const char*, const char*> words[] = {
        {"freq", "frequency"}, {"t60", "T60 decay time"},
        {"db", "dB"},          {"q", "Q"},
        {"hp", "high-pass"},   {"lp", "low-pass"},
        {"bw", "bandwidth"},   {"min", "minimum"},
        {"max", "maximum"},    {"rms", "RMS"},
        {"lfo", "LFO"},        {"kn", "kN"}};
    static const char* unitSuffixes[] = {"_hz", "_s",  "_ms", "_kg", "_db",    "_m",
                                         "_n",  "_pa", "_mm", "_cm", "_per_s", "_percent"};
    QStringList parts;
    for (const QString& part : QString::fromStdString(path).split('.', Qt::SkipEmptyParts)) {
        QString name = part;
        QString index;
        if (const auto open = part.indexOf('['); open >= 0 && part.endsWith(']')) {
            name = part.left(open);
            index = part.mid(open + 1, part.size() - open - 2);
            if (name.endsWith("s") && name != "layers") name.chop(1); // modes[3] -> mode 3
            if (name == "layers") name = "layer";
        }
        for (const char* suffix : unitSuffixes)
            if (name.endsWith(suffix) && name.size() > static_cast<int>(std::strlen(suffix))) {
                name.chop(static_cast<int>(std::strlen(suffix)));
                break;
            }
        QStringList out;
        for (const QString& w : name.split('_', Qt::SkipEmptyParts)) {
            QString word = w;
            for (const auto& [from, to] : words)
                if (w == from) word = to;
            out << word;
        }
        QString text = out.join(' ');
        if (!index.isEmpty()) text += ' ' + index;
        parts << text;
    }
    QString label = parts.join(QString::fromUtf8(" \u00b7 "));
    if (!label.isEmpty()) label[0] = label[0].toUpper();
    return label;
}

CostMeasurement measure(const QString& presetPath, eng::WalkerParameters walker) {
    CostMeasurement m;
    try {
        const double rate = 48000.0;
        const auto grf = eng::walkerGrf(walker, 4.0, rate, 1);
        eng::RenderOptions options;
        options.sampleRateHz = rate;
        options.blockSize = 256;
        options.seed = 1;
        // The fastest of three renders (as `underfoot render` reports cost on a shared machine).
        double best = 1e300;
        for (int i = 0; i < 3; ++i) {
            const auto r = eng::renderSurface(presetPath.toStdString(), grf, options);
            best = std::min(best, r.cpuSeconds);
            m.audioSeconds = static_cast<double>(r.audio.frames()) / rate;
        }
        m.cpuSeconds = best;
        m.percentOfCore = m.audioSeconds > 0 ? 100.0 * best / m.audioSeconds : 0;
    } catch (const std::exception& e) {
        m.error = q(e.what());
    }
    return m;
}

/// Decimals that show a value exactly (the spin box rounds to its decimals, and the palette
/// must not change a parameter nobody touched): at least 4 (2 for wide ranges), at most 10.
int decimalsFor(double value, double minValue, double maxValue) {
    int d = maxValue - minValue < 10 ? 4 : 2;
    if (!std::isfinite(value) || value == 0) return d;
    for (; d < 10; ++d) {
        const double scale = std::pow(10.0, d);
        if (std::abs(std::round(value * scale) / scale - value) <= 1e-12 * std::abs(value)) break;
    }
    return d;
}
} // namespace

PaletteView::PaletteView(const QString& dataDir, QWidget* parent)
    : QWidget(parent), dataDir_(dataDir) {
    list_ = new QListWidget(this);
    list_->setAccessibleName(tr("Surfaces"));
    list_->setMaximumWidth(260);
    auto* listLabel = new QLabel(tr("S&urfaces:"), this);
    listLabel->setBuddy(list_);
    info_ = new QLabel(this);
    info_->setWordWrap(true);
    info_->setAccessibleName(tr("Surface description"));
    params_ = new QTableWidget(0, 4, this);
    params_->setHorizontalHeaderLabels(
        {tr("Parameter"), tr("Value"), tr("Unit"), tr("Documented range")});
    params_->verticalHeader()->setVisible(false);
    params_->horizontalHeader()->setStretchLastSection(true);
    params_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    params_->setAccessibleName(tr("Physical parameters"));
    params_->setAlternatingRowColors(true);

    auto* walkerBox = new QGroupBox(tr("Virtual walker"), this);
    auto* wl = new QFormLayout(walkerBox);
    cadence_ = new QDoubleSpinBox(walkerBox);
    cadence_->setRange(eng::WalkerParameters::kMinCadence, eng::WalkerParameters::kMaxCadence);
    cadence_->setValue(100);
    cadence_->setSuffix(tr(" steps/min"));
    cadence_->setAccessibleName(tr("Cadence"));
    mass_ = new QDoubleSpinBox(walkerBox);
    mass_->setRange(eng::WalkerParameters::kMinMassKg, eng::WalkerParameters::kMaxMassKg);
    mass_->setValue(70);
    mass_->setSuffix(tr(" kg"));
    mass_->setAccessibleName(tr("Body mass"));
    shoe_ = new QDoubleSpinBox(walkerBox);
    shoe_->setRange(0, 1);
    shoe_->setSingleStep(0.1);
    shoe_->setValue(0.5);
    shoe_->setAccessibleName(tr("Shoe hardness, 0 soft to 1 hard"));
    wl->addRow(tr("Ca&dence:"), cadence_);
    wl->addRow(tr("&Mass:"), mass_);
    wl->addRow(tr("S&hoe hardness:"), shoe_);

    costButton_ = new QPushButton(tr("Measure CPU &cost  (Ctrl+M)"), this);
    costButton_->setAccessibleName(tr("Measure the CPU cost of the current settings"));
    auditionButton_ = new QPushButton(tr("&Listen (live engine)  (Ctrl+L)"), this);
    auditionButton_->setAccessibleName(tr("Listen through the live audio engine"));
    auto* wavButton = new QPushButton(tr("Render to &WAV…"), this);
    wavButton->setAccessibleName(tr("Render four seconds of walking to a WAV file"));
    auto* saveButton = new QPushButton(tr("&Save as new preset…  (Ctrl+S)"), this);
    saveButton->setAccessibleName(tr("Save as a new preset"));
    auto* resetButton = new QPushButton(tr("&Reset values"), this);
    cost_ = new QLabel(tr("CPU cost: not measured yet (Ctrl+M)"), this);
    cost_->setAccessibleName(tr("CPU cost"));
    message_ = new QLabel(this);
    message_->setWordWrap(true);
    message_->setTextInteractionFlags(Qt::TextSelectableByMouse);

    auto* left = new QVBoxLayout;
    left->addWidget(listLabel);
    left->addWidget(list_, 1);
    left->addWidget(walkerBox);
    auto* buttons = new QHBoxLayout;
    for (auto* b : {costButton_, auditionButton_, wavButton, saveButton, resetButton})
        buttons->addWidget(b);
    PaletteHooks hooks;
    hooks.surfaceFile = [this] { return currentFile_; };
    hooks.presetText = [this](const QString& id, const QString& name) {
        return currentPresetText(id, name);
    };
    hooks.walker = [this] { return walkerParameters(); };
    hooks.apply = [this](const QString& text) { return applyPresetText(text); };
    hooks.presetsDir = QDir(dataDir_).filePath("presets");
    compare_ = new PaletteCompare(std::move(hooks), this);
    compare_->setAccessibleName(tr("Compare with a recording"));
    auto* compareBox = new QGroupBox(tr("Compare with a recording · fit"), this);
    auto* cl = new QVBoxLayout(compareBox);
    cl->addWidget(compare_);
    auto* split = new QSplitter(Qt::Vertical, this);
    split->addWidget(params_);
    split->addWidget(compareBox);
    split->setStretchFactor(0, 1);
    split->setStretchFactor(1, 1);
    split->setChildrenCollapsible(false);
    auto* right = new QVBoxLayout;
    right->addWidget(info_);
    right->addWidget(split, 1);
    right->addLayout(buttons);
    right->addWidget(cost_);
    right->addWidget(message_);
    auto* layout = new QHBoxLayout(this);
    layout->addLayout(left);
    layout->addLayout(right, 1);

    costWatcher_ = new QFutureWatcher<CostMeasurement>(this);
    connect(costWatcher_, &QFutureWatcher<CostMeasurement>::finished, this, [this] {
        const auto m = costWatcher_->result();
        costButton_->setEnabled(true);
        const QString text =
            m.error.isEmpty()
                ? tr("CPU cost: %1 % of one core at 48 kHz, block 256 (%2 ms CPU for %3 s of "
                     "walking, fastest of 3 renders; real-time factor %4)")
                      .arg(m.percentOfCore, 0, 'f', 2)
                      .arg(m.cpuSeconds * 1e3, 0, 'f', 1)
                      .arg(m.audioSeconds, 0, 'f', 1)
                      .arg(m.cpuSeconds > 0 ? m.audioSeconds / m.cpuSeconds : 0.0, 0, 'f', 0)
                : tr("CPU cost not measured: %1").arg(m.error);
        cost_->setText(text);
        emit costMeasured(text);
    });
    connect(list_, &QListWidget::currentRowChanged, this, &PaletteView::showSurface);
    connect(costButton_, &QPushButton::clicked, this, &PaletteView::measureCost);
    connect(auditionButton_, &QPushButton::clicked, this, &PaletteView::audition);
    connect(wavButton, &QPushButton::clicked, this, &PaletteView::renderToWav);
    connect(resetButton, &QPushButton::clicked, this, &PaletteView::showSurface);
    for (auto* spin : {cadence_, mass_, shoe_})
        connect(spin, &QDoubleSpinBox::valueChanged, compare_, &PaletteCompare::settingsChanged);
    connect(saveButton, &QPushButton::clicked, this, [this] {
        bool ok = false;
        const QString id = QInputDialog::getText(
            this, tr("Save as new preset"),
            tr("Id of the new preset (letters, digits, underscore):"), QLineEdit::Normal,
            QFileInfo(currentFile_).completeBaseName() + "_custom", &ok);
        if (ok) saveAs(id, id);
    });
    const auto shortcut = [this](QKeySequence seq, auto fn) {
        auto* sc = new QShortcut(seq, this);
        sc->setContext(Qt::WidgetWithChildrenShortcut);
        connect(sc, &QShortcut::activated, this, fn);
    };
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_M), [this] { measureCost(); });
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_L), [this] { audition(); });
    shortcut(QKeySequence(Qt::CTRL | Qt::Key_S), [saveButton] { saveButton->click(); });
    loadList();
}

QString PaletteView::costText() const {
    return cost_->text();
}
QString PaletteView::message() const {
    return message_->text();
}

void PaletteView::setMessage(const QString& text, bool error) {
    message_->setText(text);
    message_->setStyleSheet(error ? "QLabel { color: #a00; }" : "QLabel { color: #176f2c; }");
}

void PaletteView::loadList() {
    list_->clear();
    try {
        for (const auto& s : eng::listSurfaces()) {
            auto* item = new QListWidgetItem(q(s.name), list_);
            item->setData(Qt::UserRole, q(s.file));
            item->setToolTip(q(s.description));
        }
    } catch (const std::exception& e) {
        setMessage(q(e.what()), true);
    }
    const QDir user(QDir(dataDir_).filePath("presets"));
    for (const QString& f : user.entryList({"*.toml"}, QDir::Files, QDir::Name)) {
        auto* item =
            new QListWidgetItem(tr("%1 (saved)").arg(QFileInfo(f).completeBaseName()), list_);
        item->setData(Qt::UserRole, user.filePath(f));
    }
    if (list_->count() > 0) list_->setCurrentRow(0);
}

bool PaletteView::selectSurface(const QString& idOrPath) {
    for (int i = 0; i < list_->count(); ++i) {
        const QString file = list_->item(i)->data(Qt::UserRole).toString();
        if (file == idOrPath || QFileInfo(file).completeBaseName() == idOrPath) {
            list_->setCurrentRow(i);
            return currentFile_ == file;
        }
    }
    return false;
}

void PaletteView::showSurface() {
    params_->setRowCount(0);
    original_.clear();
    auto* item = list_->currentItem();
    if (!item) return;
    const QString file = item->data(Qt::UserRole).toString();
    std::unique_ptr<eng::Surface> surface;
    try {
        surface = eng::Surface::load(file.toStdString());
    } catch (const std::exception& e) {
        currentFile_.clear();
        info_->clear();
        setMessage(tr("%1\nFix the preset file at that place, then pick the surface again.")
                       .arg(q(e.what())),
                   true);
        return;
    }
    currentFile_ = file;
    const auto& info = surface->info();
    QString layers;
    for (const auto& l : info.layerPurposes) layers += "<li>" + q(l).toHtmlEscaped() + "</li>";
    info_->setText(tr("<b>%1</b> (%2) — %3<ul>%4</ul>")
                       .arg(q(info.name).toHtmlEscaped(), q(eng::toString(info.category)),
                            q(info.description).toHtmlEscaped(), layers));
    const auto& ps = surface->parameters();
    params_->setRowCount(static_cast<int>(ps.size()));
    for (std::size_t i = 0; i < ps.size(); ++i) {
        const auto& p = ps[i];
        const int row = static_cast<int>(i);
        original_[p.path] = p.value;
        auto* name = new QTableWidgetItem(parameterLabel(p.path));
        name->setData(Qt::UserRole, q(p.path));
        name->setToolTip(tr("%1\n(preset key %2)").arg(q(p.help), q(p.path)));
        params_->setItem(row, PathCol, name);
        auto* spin = new QDoubleSpinBox(params_);
        spin->setDecimals(decimalsFor(p.value, p.minValue, p.maxValue));
        spin->setRange(p.minValue, p.maxValue);
        spin->setStepType(QAbstractSpinBox::AdaptiveDecimalStepType);
        spin->setValue(p.value);
        spin->setAccessibleName(parameterLabel(p.path));
        spin->setAccessibleDescription(q(p.help));
        spin->setToolTip(q(p.help));
        params_->setCellWidget(row, ValueCol, spin);
        connect(spin, &QDoubleSpinBox::valueChanged, compare_, &PaletteCompare::settingsChanged);
        params_->setItem(row, UnitCol, new QTableWidgetItem(q(p.unit)));
        params_->setItem(row, RangeCol,
                         new QTableWidgetItem(QString("%1 … %2%3")
                                                  .arg(p.minValue, 0, 'g', 6)
                                                  .arg(p.maxValue, 0, 'g', 6)
                                                  .arg(p.logScale ? tr(" (log)") : QString())));
    }
    params_->resizeColumnsToContents();
    cost_->setText(tr("CPU cost: not measured yet (Ctrl+M)"));
    message_->clear();
    compare_->surfaceChanged();
}

eng::WalkerParameters PaletteView::walkerParameters() const {
    eng::WalkerParameters w;
    w.cadenceStepsPerMin = cadence_->value();
    w.massKg = mass_->value();
    w.shoeHardness = shoe_->value();
    return w;
}

QString PaletteView::applyPresetText(const QString& text) {
    std::unique_ptr<eng::Surface> surface;
    try {
        surface = eng::loadSurfaceFromString(text.toStdString(), "fitted preset");
    } catch (const std::exception& e) {
        return q(e.what());
    }
    // The fit is of the palette's own (self-contained) preset: the same parameters in the same
    // order; a base preset's prefix ("wood:.") and layer numbering may differ, the key may not.
    const auto& ps = surface->parameters();
    if (static_cast<int>(ps.size()) != params_->rowCount()) return showFittedPreset(text);
    const auto key = [](const std::string& path) { return path.substr(path.rfind('.') + 1); };
    for (int r = 0; r < params_->rowCount(); ++r) {
        const std::string path =
            params_->item(r, PathCol)->data(Qt::UserRole).toString().toStdString();
        const auto& p = ps[static_cast<std::size_t>(r)];
        auto* spin = static_cast<QDoubleSpinBox*>(params_->cellWidget(r, ValueCol));
        if (key(path) != key(p.path)) return showFittedPreset(text);
        if (p.value < spin->minimum() || p.value > spin->maximum())
            return tr("%1 = %2 is outside its range %3 … %4")
                .arg(q(path))
                .arg(p.value)
                .arg(spin->minimum())
                .arg(spin->maximum());
    }
    for (int r = 0; r < params_->rowCount(); ++r) {
        const auto& p = ps[static_cast<std::size_t>(r)];
        auto* spin = static_cast<QDoubleSpinBox*>(params_->cellWidget(r, ValueCol));
        spin->setDecimals(std::max(spin->decimals(), decimalsFor(p.value, 0, 0)));
        spin->setValue(p.value); // each change restarts the comparison's debounce: one compare
    }
    return {};
}

QString PaletteView::showFittedPreset(const QString& text) {
    if (currentFile_.isEmpty()) return tr("no surface is selected");
    if (!fittedDir_) fittedDir_ = std::make_unique<QTemporaryDir>();
    if (!fittedDir_->isValid()) return tr("no temporary folder for the fitted preset");
    QString base = QFileInfo(currentFile_).completeBaseName();
    if (base.endsWith("_fitted")) base.chop(7);
    const QString path = fittedDir_->filePath(base + "_fitted.toml");
    {
        QFile f(path);
        if (!f.open(QIODevice::WriteOnly | QIODevice::Truncate) ||
            f.write(text.toUtf8()) != text.toUtf8().size())
            return tr("cannot write %1").arg(path);
    }
    QListWidgetItem* item = nullptr;
    for (int i = 0; i < list_->count(); ++i)
        if (list_->item(i)->data(Qt::UserRole).toString() == path) item = list_->item(i);
    if (!item) {
        item = new QListWidgetItem(tr("%1 (fitted, not saved)").arg(base), list_);
        item->setData(Qt::UserRole, path);
        item->setToolTip(tr("The fitted preset has another layout than %1 (e.g. fewer modes); "
                            "save it to keep it.")
                             .arg(base));
    }
    if (list_->currentItem() == item)
        showSurface(); // same entry, new text
    else
        list_->setCurrentItem(item);
    return currentFile_ == path ? QString() : tr("the fitted preset could not be shown");
}

bool PaletteView::setParameter(const QString& path, double value) {
    for (int r = 0; r < params_->rowCount(); ++r)
        if (params_->item(r, PathCol)->data(Qt::UserRole).toString() == path) {
            auto* spin = static_cast<QDoubleSpinBox*>(params_->cellWidget(r, ValueCol));
            if (value < spin->minimum() || value > spin->maximum()) return false;
            spin->setValue(value);
            return true;
        }
    return false;
}

QString PaletteView::currentPresetText(const QString& id, const QString& name) const {
    ParamValues values;
    for (int r = 0; r < params_->rowCount(); ++r) {
        const std::string path =
            params_->item(r, PathCol)->data(Qt::UserRole).toString().toStdString();
        const double v = static_cast<QDoubleSpinBox*>(params_->cellWidget(r, ValueCol))->value();
        const auto it = original_.find(path);
        if (it == original_.end() || std::abs(it->second - v) > 1e-12 * std::abs(v))
            values[path] = v;
    }
    return q(
        derivePresetToml(currentFile_.toStdString(), values, id.toStdString(), name.toStdString()));
}

QString PaletteView::writeTemporaryPreset(QString* error) const {
    if (currentFile_.isEmpty()) {
        *error = tr("Pick a surface first.");
        return {};
    }
    const QString id = QFileInfo(currentFile_).completeBaseName() + "_palette";
    const QString dir = QDir(QDir::tempPath()).filePath("underfoot_palette");
    QDir().mkpath(dir);
    const QString path = QDir(dir).filePath(id + ".toml");
    try {
        const QString text = currentPresetText(id, id);
        eng::loadSurfaceFromString(text.toStdString(), path.toStdString()); // validates
        QFile f(path);
        if (!f.open(QIODevice::WriteOnly | QIODevice::Truncate)) {
            *error = tr("%1: cannot write").arg(path);
            return {};
        }
        f.write(text.toUtf8());
    } catch (const std::exception& e) {
        *error = q(e.what());
        return {};
    }
    return path;
}

void PaletteView::measureCost() {
    if (costWatcher_->isRunning()) return;
    QString error;
    const QString path = writeTemporaryPreset(&error);
    if (path.isEmpty()) return setMessage(error, true);
    eng::WalkerParameters w;
    w.cadenceStepsPerMin = cadence_->value();
    w.massKg = mass_->value();
    w.shoeHardness = shoe_->value();
    costButton_->setEnabled(false);
    cost_->setText(tr("Measuring the CPU cost (three renders of 4 s of walking)…"));
    costWatcher_->setFuture(QtConcurrent::run([path, w] { return measure(path, w); }));
}

void PaletteView::audition() {
    QString error;
    const QString path = writeTemporaryPreset(&error);
    if (path.isEmpty()) return setMessage(error, true);
    if (!audio_) return setMessage(tr("No audio output is set up."), true);
    eng::WalkerParameters w;
    w.cadenceStepsPerMin = cadence_->value();
    w.massKg = mass_->value();
    w.shoeHardness = shoe_->value();
    const QString result = audio_->playWalker(path, w);
    if (result.isEmpty())
        setMessage(tr("Playing %1 through %2. Stop in the Setup view (Ctrl+5).")
                       .arg(QFileInfo(currentFile_).completeBaseName(), audio_->description()),
                   false);
    else
        setMessage(result, true);
}

void PaletteView::renderToWav() {
    QString error;
    const QString path = writeTemporaryPreset(&error);
    if (path.isEmpty()) return setMessage(error, true);
    const QString out = QFileDialog::getSaveFileName(
        this, tr("Render to"),
        QDir(dataDir_).filePath(QFileInfo(currentFile_).completeBaseName() + ".wav"),
        tr("WAV (*.wav)"));
    if (out.isEmpty()) return;
    try {
        eng::WalkerParameters w;
        w.cadenceStepsPerMin = cadence_->value();
        w.massKg = mass_->value();
        w.shoeHardness = shoe_->value();
        eng::RenderOptions options;
        options.tailSeconds = 1.0;
        const auto r = eng::renderSurface(path.toStdString(),
                                          eng::walkerGrf(w, 4.0, options.sampleRateHz, 1), options);
        eng::writeAudioFile(out.toStdString(), r.audio, eng::SampleFormat::Float32);
        setMessage(tr("Wrote %1").arg(QDir::toNativeSeparators(out)), false);
    } catch (const std::exception& e) {
        setMessage(q(e.what()), true);
    }
}

QString PaletteView::saveAs(const QString& id, const QString& name) {
    if (currentFile_.isEmpty()) {
        setMessage(tr("Pick a surface first."), true);
        return {};
    }
    if (!QRegularExpression("^[a-z0-9_]{1,48}$").match(id).hasMatch()) {
        setMessage(tr("'%1' is not a usable preset id: use lower-case letters, digits and "
                      "underscores (e.g. gravel_wet).")
                       .arg(id),
                   true);
        return {};
    }
    const QDir dir(QDir(dataDir_).filePath("presets"));
    QDir().mkpath(dir.path());
    const QString path = dir.filePath(id + ".toml");
    if (QFile::exists(path)) {
        setMessage(tr("%1 exists already; choose another id.").arg(path), true);
        return {};
    }
    try {
        const QString text = currentPresetText(id, name);
        eng::loadSurfaceFromString(text.toStdString(), path.toStdString());
        QFile f(path);
        if (!f.open(QIODevice::WriteOnly)) throw std::runtime_error("cannot write the file");
        f.write(text.toUtf8());
    } catch (const std::exception& e) {
        setMessage(tr("Not saved: %1").arg(q(e.what())), true);
        return {};
    }
    setMessage(tr("Saved %1. Protocols can name it by path.").arg(QDir::toNativeSeparators(path)),
               false);
    const QString keep = path;
    loadList();
    selectSurface(keep);
    return path;
}

} // namespace underfoot::gui
