// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/SetupView.h"

#include "app/gui/AudioOutput.h"
#include "engine/render/Renderer.h"

#include <QChart>
#include <QChartView>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineSeries>
#include <QProgressBar>
#include <QPushButton>
#include <QShortcut>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>

#include <cmath>

namespace underfoot::gui {

namespace eng = underfoot::engine;

namespace {
QString q(const std::string& s) {
    return QString::fromStdString(s);
}

QChart* makeChart(const QString& title, const QString& yTitle) {
    auto* chart = new QChart;
    chart->setTitle(title);
    chart->legend()->setAlignment(Qt::AlignBottom);
    auto* x = new QValueAxis;
    x->setTitleText(QObject::tr("time (s)"));
    auto* y = new QValueAxis;
    y->setTitleText(yTitle);
    chart->addAxis(x, Qt::AlignBottom);
    chart->addAxis(y, Qt::AlignLeft);
    chart->setMargins(QMargins(4, 4, 4, 4));
    return chart;
}

void setSeries(QChart* chart, const std::vector<std::pair<QString, QList<QPointF>>>& series,
               double xMax, double yMin, double yMax) {
    chart->removeAllSeries();
    const auto axes = chart->axes();
    for (const auto& [name, points] : series) {
        auto* s = new QLineSeries;
        s->setName(name);
        s->replace(points);
        chart->addSeries(s);
        for (auto* a : axes) s->attachAxis(a);
    }
    chart->axes(Qt::Horizontal).front()->setRange(0, xMax);
    auto* y = static_cast<QValueAxis*>(chart->axes(Qt::Vertical).front());
    y->setRange(yMin, yMax);
    y->applyNiceNumbers();
}
} // namespace

SetupView::SetupView(AudioOutput& audio, QWidget* parent) : QWidget(parent), audio_(audio) {
    auto* audioBox = new QGroupBox(tr("Audio output"), this);
    auto* al = new QFormLayout(audioBox);
    api_ = new QComboBox(audioBox);
    api_->addItem(tr("first that works"), QString());
    for (const auto& a : eng::compiledAudioApis()) api_->addItem(q(a), q(a));
    api_->setAccessibleName(tr("Audio API"));
    device_ = new QComboBox(audioBox);
    device_->setEditable(true);
    device_->setAccessibleName(tr("Audio device"));
    auto* refresh = new QPushButton(tr("Re&fresh"), audioBox);
    refresh->setAccessibleName(tr("Refresh the device list"));
    auto* devRow = new QHBoxLayout;
    devRow->addWidget(device_, 1);
    devRow->addWidget(refresh);
    rate_ = new QComboBox(audioBox);
    for (int r : {44100, 48000, 88200, 96000}) rate_->addItem(QString::number(r), r);
    rate_->setAccessibleName(tr("Sample rate in hertz"));
    block_ = new QComboBox(audioBox);
    for (int b : {32, 64, 128, 256, 512, 1024}) block_->addItem(QString::number(b), b);
    block_->setAccessibleName(tr("Block size in frames"));
    headL_ = new QSpinBox(audioBox);
    headR_ = new QSpinBox(audioBox);
    for (auto* s : {headL_, headR_}) s->setRange(1, 64);
    headL_->setAccessibleName(tr("Headphones left output channel"));
    headR_->setAccessibleName(tr("Headphones right output channel"));
    auto* headRow = new QHBoxLayout;
    headRow->addWidget(new QLabel(tr("L"), audioBox));
    headRow->addWidget(headL_);
    headRow->addWidget(new QLabel(tr("R"), audioBox));
    headRow->addWidget(headR_);
    headRow->addStretch();
    auto* hapticRow = new QGridLayout;
    const char* hapticNames[] = {"left heel", "left toe", "right heel", "right toe"};
    for (int i = 0; i < 4; ++i) {
        haptic_[i] = new QSpinBox(audioBox);
        haptic_[i]->setRange(0, 64);
        haptic_[i]->setSpecialValueText(tr("none"));
        haptic_[i]->setMinimumWidth(70);
        haptic_[i]->setAccessibleName(tr("Haptic actuator output, %1").arg(tr(hapticNames[i])));
        hapticRow->addWidget(new QLabel(tr(hapticNames[i]), audioBox), i / 2, (i % 2) * 2);
        hapticRow->addWidget(haptic_[i], i / 2, (i % 2) * 2 + 1);
    }
    al->addRow(tr("A&PI:"), api_);
    auto* deviceLabel = new QLabel(tr("&Device:"), audioBox);
    deviceLabel->setBuddy(device_);
    al->addRow(deviceLabel, devRow);
    al->addRow(tr("Sample &rate (Hz):"), rate_);
    al->addRow(tr("&Block (frames):"), block_);
    auto* headLabel = new QLabel(tr("&Headphones (outputs, from 1):"), audioBox);
    headLabel->setBuddy(headL_);
    al->addRow(headLabel, headRow);
    al->addRow(tr("Haptic actuators (outputs):"), hapticRow);
    auto* save = new QPushButton(tr("&Save settings  (Ctrl+S)"), audioBox);
    save->setAccessibleName(tr("Save the audio settings"));
    startStop_ = new QPushButton(tr("S&tart audio"), audioBox);
    startStop_->setAccessibleName(tr("Start or stop the live audio engine"));
    auto* buttons = new QHBoxLayout;
    buttons->addWidget(save);
    buttons->addWidget(startStop_);
    al->addRow(buttons);
    meterText_ = new QLabel(audioBox);
    meterText_->setWordWrap(true);
    meterText_->setAccessibleName(tr("Audio engine meters"));
    al->addRow(meterText_);
    auto* meterGrid = new QGridLayout;
    for (int i = 0; i < 8; ++i) {
        outputMeters_[i] = new QProgressBar(audioBox);
        outputMeters_[i]->setRange(0, 60);
        outputMeters_[i]->setFormat(tr("out %1").arg(i + 1));
        outputMeters_[i]->setAccessibleName(tr("Output %1 peak level").arg(i + 1));
        meterGrid->addWidget(outputMeters_[i], i / 4, i % 4);
    }
    al->addRow(meterGrid);
    message_ = new QLabel(audioBox);
    message_->setWordWrap(true);
    message_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    al->addRow(message_);

    auto* calBox = new QGroupBox(tr("Step calibration (virtual walker while no shoes are "
                                    "connected)"),
                                 this);
    auto* cl = new QVBoxLayout(calBox);
    auto* form = new QHBoxLayout;
    massKg_ = new QDoubleSpinBox(calBox);
    massKg_->setRange(eng::WalkerParameters::kMinMassKg, eng::WalkerParameters::kMaxMassKg);
    massKg_->setValue(70);
    massKg_->setSuffix(" kg");
    massKg_->setAccessibleName(tr("Participant body mass"));
    cadence_ = new QDoubleSpinBox(calBox);
    cadence_->setRange(eng::WalkerParameters::kMinCadence, eng::WalkerParameters::kMaxCadence);
    cadence_->setValue(100);
    cadence_->setSuffix(tr(" steps/min"));
    cadence_->setAccessibleName(tr("Cadence"));
    threshold_ = new QDoubleSpinBox(calBox);
    threshold_->setRange(100, 100000);
    threshold_->setValue(4000);
    threshold_->setSingleStep(250);
    threshold_->setSuffix(" N/s");
    threshold_->setAccessibleName(tr("Onset threshold on the force derivative"));
    stepsLabel_ = new QLabel(calBox);
    stepsLabel_->setAccessibleName(tr("Steps detected"));
    auto* ml = new QLabel(tr("M&ass:"), calBox);
    ml->setBuddy(massKg_);
    auto* cdl = new QLabel(tr("Ca&dence:"), calBox);
    cdl->setBuddy(cadence_);
    auto* tl = new QLabel(tr("Onset t&hreshold:"), calBox);
    tl->setBuddy(threshold_);
    for (QWidget* w :
         std::initializer_list<QWidget*>{ml, massKg_, cdl, cadence_, tl, threshold_, stepsLabel_})
        form->addWidget(w);
    form->addStretch();
    grfChart_ = makeChart(tr("Vertical force under each foot"), tr("N"));
    derivativeChart_ = makeChart(tr("Force derivative (positive changes fire a step)"), tr("N/s"));
    auto* grfView = new QChartView(grfChart_, calBox);
    auto* derView = new QChartView(derivativeChart_, calBox);
    for (auto* v : {grfView, derView}) {
        v->setRenderHint(QPainter::Antialiasing);
        v->setMinimumHeight(180);
    }
    grfView->setAccessibleName(tr("Force plot"));
    derView->setAccessibleName(tr("Force derivative plot"));
    cl->addLayout(form);
    cl->addWidget(grfView, 1);
    cl->addWidget(derView, 1);

    auto* layout = new QHBoxLayout(this);
    layout->addWidget(audioBox, 2);
    layout->addWidget(calBox, 3);

    meterTimer_ = new QTimer(this);
    meterTimer_->setInterval(100);
    connect(meterTimer_, &QTimer::timeout, this, &SetupView::updateMeters);
    connect(refresh, &QPushButton::clicked, this, &SetupView::fillDevices);
    connect(api_, &QComboBox::currentIndexChanged, this, &SetupView::fillDevices);
    connect(save, &QPushButton::clicked, this, [this] {
        if (const QString e = applyForm(); !e.isEmpty()) return setMessage(e, true);
        const QString e = audio_.save();
        setMessage(e.isEmpty() ? tr("Saved %1").arg(audio_.settingsPath()) : e, !e.isEmpty());
    });
    auto* sc = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_S), this);
    sc->setContext(Qt::WidgetWithChildrenShortcut);
    connect(sc, &QShortcut::activated, save, &QPushButton::click);
    connect(startStop_, &QPushButton::clicked, this, [this] {
        if (audio_.running()) {
            audio_.stop();
            return;
        }
        if (const QString e = applyForm(); !e.isEmpty()) return setMessage(e, true);
        const QString e = audio_.start();
        setMessage(e.isEmpty() ? tr("Running: %1").arg(audio_.description()) : e, !e.isEmpty());
    });
    connect(&audio_, &AudioOutput::runningChanged, this, [this](bool running) {
        startStop_->setText(running ? tr("S&top audio") : tr("S&tart audio"));
        if (running)
            meterTimer_->start();
        else
            meterTimer_->stop();
        updateMeters();
    });
    for (auto* s : {massKg_, cadence_, threshold_})
        connect(s, &QDoubleSpinBox::valueChanged, this, &SetupView::updateCalibrationPlot);
    loadForm();
    if (!audio_.loadError().isEmpty()) setMessage(audio_.loadError(), true);
    updateMeters();
    updateCalibrationPlot();
}

void SetupView::setMessage(const QString& text, bool error) {
    message_->setText(text);
    message_->setStyleSheet(error ? "QLabel { color: #a00; }" : "QLabel { color: #176f2c; }");
}

void SetupView::fillDevices() {
    const QString keep = device_->currentText();
    device_->clear();
    device_->addItem(QString());
    try {
        for (const auto& d : eng::listAudioDevices(api_->currentData().toString().toStdString()))
            if (d.outputChannels > 0) device_->addItem(q(d.name), q(d.name));
    } catch (const std::exception& e) {
        setMessage(q(e.what()), true);
    }
    device_->setCurrentText(keep);
}

void SetupView::loadForm() {
    const auto& s = audio_.settings();
    api_->setCurrentIndex(std::max(0, api_->findData(q(s.api))));
    fillDevices();
    device_->setCurrentText(q(s.device));
    if (rate_->findData(s.sampleRateHz) < 0)
        rate_->addItem(QString::number(s.sampleRateHz), s.sampleRateHz);
    rate_->setCurrentIndex(rate_->findData(s.sampleRateHz));
    if (block_->findData(s.blockSize) < 0)
        block_->addItem(QString::number(s.blockSize), s.blockSize);
    block_->setCurrentIndex(block_->findData(s.blockSize));
    headL_->setValue(s.channels.headphonesLeft + 1);
    headR_->setValue(s.channels.headphonesRight + 1);
    const int hap[4] = {s.channels.haptic[0].heel, s.channels.haptic[0].toe,
                        s.channels.haptic[1].heel, s.channels.haptic[1].toe};
    for (int i = 0; i < 4; ++i) haptic_[i]->setValue(hap[i] + 1);
}

QString SetupView::applyForm() {
    eng::AudioSettings s = audio_.settings();
    s.api = api_->currentData().toString().toStdString();
    s.device = device_->currentText().trimmed().toStdString();
    s.sampleRateHz = rate_->currentData().toInt();
    s.blockSize = block_->currentData().toInt();
    s.channels.headphonesLeft = headL_->value() - 1;
    s.channels.headphonesRight = headR_->value() - 1;
    s.channels.haptic[0].heel = haptic_[0]->value() - 1;
    s.channels.haptic[0].toe = haptic_[1]->value() - 1;
    s.channels.haptic[1].heel = haptic_[2]->value() - 1;
    s.channels.haptic[1].toe = haptic_[3]->value() - 1;
    return audio_.setSettings(s);
}

void SetupView::updateMeters() {
    if (!audio_.running()) {
        meterText_->setText(tr("Audio engine not running. Start it to see levels, xruns and the "
                               "callback load."));
        for (auto* m : outputMeters_) m->setValue(0);
        return;
    }
    const auto m = audio_.meters();
    meterText_->setText(tr("%1 · xruns %2 · callback load %3 % (worst %4 %) · %5 blocks")
                            .arg(audio_.description())
                            .arg(m.xruns)
                            .arg(m.loadPercent, 0, 'f', 1)
                            .arg(m.maxLoadPercent, 0, 'f', 1)
                            .arg(m.blocks));
    for (int i = 0; i < 8; ++i) {
        const float peak = i < m.outputChannels ? m.outputPeak[static_cast<std::size_t>(i)] : 0.f;
        const double db = peak > 0 ? 20 * std::log10(static_cast<double>(peak)) : -60.0;
        outputMeters_[i]->setValue(static_cast<int>(std::clamp(db + 60.0, 0.0, 60.0)));
    }
}

void SetupView::updateCalibrationPlot() {
    eng::WalkerParameters w;
    w.massKg = massKg_->value();
    w.cadenceStepsPerMin = cadence_->value();
    const double rate = 500.0, seconds = 4.0;
    eng::GrfSignal grf;
    try {
        grf = eng::walkerGrf(w, seconds, rate, 7);
    } catch (const std::exception& e) {
        stepsLabel_->setText(q(e.what()));
        return;
    }
    const double threshold = threshold_->value();
    std::vector<std::pair<QString, QList<QPointF>>> force, derivative;
    const char* names[] = {"left", "right"};
    double fMax = 1, dMax = threshold * 1.2;
    detectedSteps_ = 0;
    for (std::size_t c = 0; c < std::min<std::size_t>(grf.channels.size(), 2); ++c) {
        QList<QPointF> f, d;
        bool armed = true;
        double previous = 0;
        for (std::size_t i = 0; i < grf.frames(); ++i) {
            const double t = static_cast<double>(i) / rate;
            if (t > seconds) break;
            const double v = grf.channels[c][i];
            const double dv = i == 0 ? 0 : (v - previous) * rate;
            previous = v;
            f.append({t, v});
            d.append({t, std::max(0.0, dv)});
            fMax = std::max(fMax, v);
            dMax = std::max(dMax, dv);
            // Positive changes only; re-armed once the foot has left the ground.
            if (armed && dv > threshold) {
                ++detectedSteps_;
                armed = false;
            }
            if (v <= 1.0) armed = true;
        }
        force.push_back({tr("%1 foot").arg(tr(names[c])), f});
        derivative.push_back({tr("%1 foot").arg(tr(names[c])), d});
    }
    derivative.push_back({tr("threshold"), {{0, threshold}, {seconds, threshold}}});
    setSeries(grfChart_, force, seconds, 0, fMax * 1.1);
    setSeries(derivativeChart_, derivative, seconds, 0, dMax * 1.1);
    const double expected = seconds * w.cadenceStepsPerMin / 60.0;
    stepsLabel_->setText(tr("%1 steps detected in %2 s (the walker took about %3)")
                             .arg(detectedSteps_)
                             .arg(seconds)
                             .arg(expected, 0, 'f', 0));
}

} // namespace underfoot::gui
