// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/SetupView.h"
#include "app/gui/QtText.h"

#include "app/gui/AudioOutput.h"
#include "engine/control/StepDetector.h"
#include "engine/dsp/Random.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "engine/render/Renderer.h"
#include "engine/scene/TestTone.h"

#include <QChart>
#include <QChartView>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QProgressBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QShortcut>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>

#include <cmath>

namespace underfoot::gui {

namespace eng = underfoot::engine;

namespace {

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

SetupView::SetupView(AudioOutput& audio, const QString& dataDir, QWidget* parent)
    : QWidget(parent), audio_(audio), dataDir_(dataDir) {
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
    toneOutput_ = new QComboBox(audioBox);
    toneOutput_->addItems({tr("headphones left — 1 kHz"), tr("headphones right — 1 kHz"),
                           tr("left heel — 200 Hz"), tr("left toe — 200 Hz"),
                           tr("right heel — 200 Hz"), tr("right toe — 200 Hz")});
    toneOutput_->setAccessibleName(tr("Output for the test tone"));
    toneButton_ = new QPushButton(audioBox);
    toneButton_->setAccessibleName(tr("Play or stop the test tone"));
    auto* toneRow = new QHBoxLayout;
    toneRow->addWidget(toneOutput_);
    toneRow->addWidget(toneButton_, 1);
    auto* toneLabel = new QLabel(tr("Test to&ne (-20 dBFS):"), audioBox);
    toneLabel->setBuddy(toneOutput_);
    al->addRow(toneLabel, toneRow);
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

    auto* calBox = new QGroupBox(tr("FSR shoes and step calibration"), this);
    auto* cl = new QVBoxLayout(calBox);
    auto* form = new QGridLayout;
    port_ = new QComboBox(calBox);
    port_->setEditable(true);
    port_->setAccessibleName(tr("Serial port of the shoes"));
    port_->addItem(tr("simulated shoes (scripted walk)"), QString());
    try {
        for (const auto& p : eng::SerialSource::listPorts())
            port_->addItem(q(p.path + (p.description.empty() ? "" : "  — " + p.description)),
                           q(p.path));
    } catch (const std::exception&) {
        // No serial subsystem: only the simulator and typed paths.
    }
    seconds_ = new QSpinBox(calBox);
    seconds_->setRange(4, 120);
    seconds_->setValue(15);
    seconds_->setSuffix(" s");
    seconds_->setAccessibleName(tr("Length of the calibration recording"));
    participant_ = new QLineEdit(calBox);
    participant_->setPlaceholderText(tr("participant code"));
    participant_->setAccessibleName(tr("Participant whose thresholds are calibrated"));
    record_ = new QPushButton(tr("Record and cali&brate  (Ctrl+B)"), calBox);
    record_->setAccessibleName(tr("Record and calibrate the step thresholds"));
    auto* saveThr = new QPushButton(tr("Save t&hresholds"), calBox);
    saveThr->setAccessibleName(tr("Save the participant's step thresholds"));
    auto* portLabel = new QLabel(tr("Sh&oes:"), calBox);
    portLabel->setBuddy(port_);
    auto* secLabel = new QLabel(tr("Recordin&g:"), calBox);
    secLabel->setBuddy(seconds_);
    auto* partLabel = new QLabel(tr("Partici&pant:"), calBox);
    partLabel->setBuddy(participant_);
    form->addWidget(portLabel, 0, 0);
    form->addWidget(port_, 0, 1, 1, 3);
    form->addWidget(secLabel, 1, 0);
    form->addWidget(seconds_, 1, 1);
    form->addWidget(partLabel, 1, 2);
    form->addWidget(participant_, 1, 3);
    connectShoes_ = new QPushButton(tr("Connect shoes  (Ctrl+Shift+B)"), calBox);
    connectShoes_->setAccessibleName(tr("Connect the shoes for the sessions"));
    connectShoes_->setToolTip(tr("Keeps the shoes' port open: the Run view's FSR stimuli then "
                                 "follow the participant's steps"));
    auto* calButtons = new QHBoxLayout;
    calButtons->addWidget(connectShoes_);
    calButtons->addWidget(record_);
    calButtons->addWidget(saveThr);
    sensorStatus_ = new QLabel(tr("Shoes: not connected."), calBox);
    sensorStatus_->setWordWrap(true);
    sensorStatus_->setAccessibleName(tr("Sensor connection status"));
    calibration_ = new QLabel(calBox);
    calibration_->setWordWrap(true);
    calibration_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    calibration_->setAccessibleName(tr("Calibration result"));
    pressureChart_ = makeChart(tr("Pressure per sensor (raw 10-bit)"), tr("units"));
    derivativeChart_ =
        makeChart(tr("Pressure derivative and onset thresholds (positive changes fire a step)"),
                  tr("units/s"));
    auto* pView = new QChartView(pressureChart_, calBox);
    auto* dView = new QChartView(derivativeChart_, calBox);
    for (auto* v : {pView, dView}) {
        v->setRenderHint(QPainter::Antialiasing);
        v->setMinimumHeight(170);
    }
    pView->setAccessibleName(tr("Pressure plot"));
    dView->setAccessibleName(tr("Pressure derivative plot"));
    cl->addLayout(form);
    cl->addLayout(calButtons);
    cl->addWidget(sensorStatus_);
    // Thigh / shank gyroscopes over OSC (wading studies).
    auto* gyroRow = new QHBoxLayout;
    gyroPortBox_ = new QSpinBox(calBox);
    gyroPortBox_->setRange(0, 65535);
    gyroPortBox_->setValue(9000);
    gyroPortBox_->setSpecialValueText(tr("any free port"));
    gyroPortBox_->setAccessibleName(tr("OSC gyroscope UDP port"));
    auto* gyroLabel = new QLabel(tr("&Gyroscopes, OSC port:"), calBox);
    gyroLabel->setBuddy(gyroPortBox_);
    gyroListen_ = new QPushButton(tr("Listen  (Ctrl+G)"), calBox);
    gyroListen_->setAccessibleName(tr("Listen for the OSC gyroscopes"));
    gyroRow->addWidget(gyroLabel);
    gyroRow->addWidget(gyroPortBox_);
    gyroRow->addWidget(gyroListen_);
    gyroRow->addStretch();
    gyroStatus_ = new QLabel(tr("Gyroscopes: not listening."), calBox);
    gyroStatus_->setWordWrap(true);
    gyroStatus_->setAccessibleName(tr("Gyroscope connection status"));
    cl->addLayout(gyroRow);
    cl->addWidget(gyroStatus_);
    gyroTimer_ = new QTimer(this);
    gyroTimer_->setInterval(200);
    connect(gyroTimer_, &QTimer::timeout, this, &SetupView::pollGyro);
    connect(gyroListen_, &QPushButton::clicked, this, [this] {
        if (const QString e = toggleGyroListening(); !e.isEmpty()) gyroStatus_->setText(e);
    });
    auto* scG = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_G), this);
    scG->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scG, &QShortcut::activated, gyroListen_, &QPushButton::click);
    cl->addWidget(pView, 1);
    cl->addWidget(dView, 1);
    cl->addWidget(calibration_);
    sensorTimer_ = new QTimer(this);
    sensorTimer_->setInterval(100);
    connect(sensorTimer_, &QTimer::timeout, this, &SetupView::pollSerial);
    connect(connectShoes_, &QPushButton::clicked, this, [this] { toggleShoes(); });
    auto* scShoes = new QShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_B), this);
    scShoes->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scShoes, &QShortcut::activated, connectShoes_, &QPushButton::click);
    connect(record_, &QPushButton::clicked, this, [this] {
        if (!shoes_ && port_->currentData().toString().isEmpty() &&
            port_->currentText() == port_->itemText(0))
            calibrateSimulated();
        else
            toggleSerialRecording();
    });
    connect(saveThr, &QPushButton::clicked, this, &SetupView::saveThresholds);
    auto* scB = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_B), this);
    scB->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scB, &QShortcut::activated, record_, &QPushButton::click);

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
    connect(toneButton_, &QPushButton::clicked, this, [this] {
        if (const QString e = toggleTestTone(); !e.isEmpty()) setMessage(e, true);
    });
    auto* scT = new QShortcut(QKeySequence(Qt::CTRL | Qt::Key_T), this);
    scT->setContext(Qt::WidgetWithChildrenShortcut);
    connect(scT, &QShortcut::activated, this, [this] {
        if (const QString e = toggleTestTone(); !e.isEmpty()) setMessage(e, true);
    });
    connect(toneOutput_, &QComboBox::currentIndexChanged, this, [this] {
        if (tonePlaying_) {
            tonePlaying_ = false;
            if (const QString e = toggleTestTone(); !e.isEmpty()) setMessage(e, true);
        }
    });
    connect(&audio_, &AudioOutput::runningChanged, this, [this](bool running) {
        tonePlaying_ = false;
        refreshToneButton();
        startStop_->setText(running ? tr("S&top audio") : tr("S&tart audio"));
        if (running)
            meterTimer_->start();
        else
            meterTimer_->stop();
        updateMeters();
    });
    loadForm();
    refreshToneButton();
    if (!audio_.loadError().isEmpty()) setMessage(audio_.loadError(), true);
    updateMeters();
    calibrateSimulated();
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

void SetupView::refreshToneButton() {
    const bool running = audio_.running();
    toneButton_->setEnabled(running);
    toneButton_->setText(!running       ? tr("No device runs: Start audio first")
                         : tonePlaying_ ? tr("Stop test tone  (Ctrl+T)")
                                        : tr("Play test tone  (Ctrl+T)"));
}

QString SetupView::toggleTestTone() {
    if (tonePlaying_) {
        audio_.silence();
        tonePlaying_ = false;
        refreshToneButton();
        return {};
    }
    const auto& ch = audio_.settings().channels;
    const int item = toneOutput_->currentIndex();
    const int channel = item == 0   ? ch.headphonesLeft
                        : item == 1 ? ch.headphonesRight
                        : item < 4  ? (item == 2 ? ch.haptic[0].heel : ch.haptic[0].toe)
                                    : (item == 4 ? ch.haptic[1].heel : ch.haptic[1].toe);
    if (channel < 0)
        return tr("The %1 actuator has no output channel: map it above, save and restart the "
                  "audio.")
            .arg(toneOutput_->currentText().section(QString::fromUtf8(" —"), 0, 0));
    const auto tone = item < 2 ? eng::kHeadphoneTestTone : eng::kHapticTestTone;
    const QString e = audio_.playTestTone(channel, tone.frequencyHz, tone.levelDbfs);
    if (!e.isEmpty()) return e;
    tonePlaying_ = true;
    refreshToneButton();
    setMessage(tr("Test tone %1 Hz, %2 dBFS on output %3 (%4). Ctrl+T stops it.")
                   .arg(tone.frequencyHz)
                   .arg(tone.levelDbfs)
                   .arg(channel + 1)
                   .arg(toneOutput_->currentText()),
               false);
    return {};
}

QString SetupView::toggleGyroListening() {
    if (gyro_) {
        if (gyro_.use_count() > 1)
            return tr("Gyroscopes: the running session uses them; finish or abandon it in the "
                      "Run view before you stop listening.");
        gyroTimer_->stop();
        gyro_->stop();
        gyro_.reset();
        gyroListen_->setText(tr("Listen  (Ctrl+G)"));
        gyroStatus_->setText(tr("Gyroscopes: not listening."));
        return {};
    }
    eng::OscGyroConfig config;
    config.port = gyroPortBox_->value();
    auto receiver = std::make_shared<eng::OscGyroReceiver>(config);
    try {
        receiver->start();
    } catch (const std::exception& e) {
        return tr("Gyroscopes: %1\nChoose another port (or 0 for any free one) and listen "
                  "again.")
            .arg(q(e.what()));
    }
    gyro_ = std::move(receiver);
    gyroListen_->setText(tr("Stop listening  (Ctrl+G)"));
    gyroTimer_->start();
    pollGyro();
    return {};
}

int SetupView::gyroPort() const {
    return gyro_ ? gyro_->port() : 0;
}

QString SetupView::gyroStatusText() const {
    return gyroStatus_->text();
}

void SetupView::pollGyro() {
    if (!gyro_) return;
    // Status only here: the samples are drained so that the queue never reports drops, except
    // while a session holds the receiver (its water scenes are then the only reader).
    eng::GyroSample sample;
    if (gyro_.use_count() == 1)
        while (gyro_->popSample(sample)) {
        }
    const auto st = gyro_->status();
    QStringList limbs;
    for (std::size_t i = 0; i < eng::kLimbCount; ++i) {
        const auto limb = static_cast<eng::Limb>(i);
        const auto c = gyro_->limbCounters(limb);
        limbs << tr("%1 %2%3")
                     .arg(q(std::string(eng::limbName(limb))))
                     .arg(c.samples)
                     .arg(c.lost ? tr(" (%1 lost)").arg(c.lost) : QString());
    }
    gyroStatus_->setText(tr("Gyroscopes on UDP %1: %2 — %3 · %4 samples/s · %5 accepted, %6 "
                            "lost, %7 rejected packets · %8%9")
                             .arg(gyro_->port())
                             .arg(q(std::string(eng::sensorStateName(st.state))), q(st.message))
                             .arg(st.rateHz, 0, 'f', 0)
                             .arg(st.framesAccepted)
                             .arg(st.framesLost)
                             .arg(st.linesRejected)
                             .arg(limbs.join(", "))
                             .arg(st.lastRejection.empty()
                                      ? QString()
                                      : tr(" · last rejected: %1").arg(q(st.lastRejection))));
}

QString SetupView::calibrationText() const {
    return calibration_->text();
}

bool SetupView::calibrateSimulated() {
    const auto script = eng::defaultWalkScript(1);
    eng::Random random(2);
    std::vector<eng::ShoeFrame> frames;
    const auto n = static_cast<std::size_t>(script.durationMs());
    frames.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        eng::ShoeFrame f;
        f.index = i;
        f.deviceMs = static_cast<std::uint32_t>(i);
        f.timeS = static_cast<double>(i) * 1e-3;
        f.raw = script.sample(i, random);
        frames.push_back(f);
    }
    sensorStatus_->setText(tr("Shoes: simulated (the engine's scripted walk: standing, 8 steps, "
                              "weight shifts, 6 steps). Choose a serial port to use real shoes."));
    calibrate(frames, static_cast<int>(script.strikes().size()));
    return result_ != nullptr;
}

void SetupView::toggleSerialRecording() {
    if (recordingActive_) {
        recordingActive_ = false;
        record_->setText(tr("Record and cali&brate  (Ctrl+B)"));
        if (disconnectAfterRecording_) disconnectShoes();
        if (!recording_.empty()) calibrate(recording_, -1);
        return;
    }
    if (shoesInSession()) {
        sensorStatus_->setText(tr("The shoes are in use by the running session (its trials read "
                                  "their frames). Finish or abandon the session in the Run view, "
                                  "then record the calibration."));
        return;
    }
    disconnectAfterRecording_ = !shoes_;
    if (!shoes_ && !connectShoesNow().isEmpty()) return;
    eng::ShoeFrame f;
    while (shoes_->popFrame(f)) {
    }
    recording_.clear();
    recordUntilS_ = -1;
    recordingActive_ = true;
    record_->setText(tr("Stop and cali&brate  (Ctrl+B)"));
}

QString SetupView::connectShoesNow() {
    const bool simulated =
        port_->currentData().toString().isEmpty() && port_->currentText() == port_->itemText(0);
    if (simulated) {
        const QString e = tr("Choose the shoes' serial port first (Alt+O, e.g. /dev/ttyACM0).");
        sensorStatus_->setText(e);
        return e;
    }
    eng::SerialConfig config;
    config.path = (port_->currentData().toString().isEmpty() ? port_->currentText().trimmed()
                                                             : port_->currentData().toString())
                      .toStdString();
    auto shoes = std::make_shared<eng::SerialSource>(config);
    try {
        shoes->start();
    } catch (const std::exception& e) {
        const QString text = tr("%1\nCheck the cable and the port name (ls /dev/ttyACM*), and "
                                "that you may open it (group dialout).")
                                 .arg(q(e.what()));
        sensorStatus_->setText(text);
        return text;
    }
    shoes_ = std::move(shoes);
    sensorTimer_->start();
    pollSerial();
    return {};
}

void SetupView::disconnectShoes() {
    sensorTimer_->stop();
    if (shoes_) shoes_->stop();
    shoes_.reset();
    disconnectAfterRecording_ = false;
    connectShoes_->setText(tr("Connect shoes  (Ctrl+Shift+B)"));
    sensorStatus_->setText(tr("Shoes: not connected."));
}

QString SetupView::toggleShoes() {
    if (shoes_ && !disconnectAfterRecording_) {
        if (shoesInSession()) {
            const QString e = tr("The running session uses the shoes: finish or abandon it in the "
                                 "Run view before disconnecting them.");
            sensorStatus_->setText(e);
            return e;
        }
        if (recordingActive_) toggleSerialRecording();
        disconnectShoes();
        return {};
    }
    if (!shoes_) {
        if (const QString e = connectShoesNow(); !e.isEmpty()) return e;
    }
    disconnectAfterRecording_ = false; // a recording's port stays open as the connection
    connectShoes_->setText(tr("Disconnect shoes  (Ctrl+Shift+B)"));
    return {};
}

QString SetupView::thresholdsDir() const {
    return QDir(dataDir_).filePath("thresholds");
}

QString SetupView::sensorStatusText() const {
    return sensorStatus_->text();
}

void SetupView::pollSerial() {
    if (!shoes_) return;
    const bool inSession = shoesInSession();
    if (inSession && recordingActive_) {
        recordingActive_ = false;
        recording_.clear();
        record_->setText(tr("Record and cali&brate  (Ctrl+B)"));
        calibration_->setText(tr("Recording abandoned: a session took the shoes. Record again "
                                 "once it is over."));
    }
    if (!inSession) { // a session's player is then the only reader of the frames
        eng::ShoeFrame f;
        while (shoes_->popFrame(f)) {
            if (!recordingActive_) continue;
            if (recordUntilS_ < 0) recordUntilS_ = f.timeS + seconds_->value();
            recording_.push_back(f);
        }
    }
    const auto st = shoes_->status();
    sensorStatus_->setText(tr("Shoes on %1 (%2): %3 — %4 · %5 frames/s · %6 accepted, %7 lost, "
                              "%8 rejected lines%9%10")
                               .arg(q(shoes_->config().path), q(shoes_->backendName()),
                                    q(std::string(eng::sensorStateName(st.state))), q(st.message))
                               .arg(st.rateHz, 0, 'f', 0)
                               .arg(st.framesAccepted)
                               .arg(st.framesLost)
                               .arg(st.linesRejected)
                               .arg(st.lastRejection.empty()
                                        ? QString()
                                        : tr(" · last rejected: %1").arg(q(st.lastRejection)))
                               .arg(inSession          ? tr(" · in use by the running session")
                                    : recordingActive_ ? tr(" · recording")
                                                       : QString()));
    if (recordingActive_ && recordUntilS_ > 0 && !recording_.empty() &&
        recording_.back().timeS >= recordUntilS_)
        toggleSerialRecording();
}

void SetupView::calibrate(const std::vector<eng::ShoeFrame>& frames, int expectedSteps) {
    result_.reset();
    expectedSteps_ = expectedSteps;
    detectedSteps_ = 0;
    eng::StepCalibrationOptions options;
    options.participant = participant_->text().trimmed().toStdString();
    try {
        result_ =
            std::make_unique<eng::StepCalibrationResult>(eng::calibrateSteps(frames, options));
    } catch (const std::exception& e) {
        calibration_->setText(tr("Not calibrated: %1\nRecord again with the participant standing, "
                                 "then walking at least four steps on each sensor.")
                                  .arg(q(e.what())));
        return;
    }
    const auto& thr = result_->thresholds;
    eng::StepDetector detector(thr);
    eng::StepDetector::Events events;
    std::vector<std::pair<QString, QList<QPointF>>> pressure, derivative;
    for (std::size_t i = 0; i < eng::kShoeSensorCount; ++i) {
        pressure.push_back({q(std::string(eng::shoeSensorName(i))), {}});
        derivative.push_back({q(std::string(eng::shoeSensorName(i))), {}});
    }
    const double t0 = frames.empty() ? 0 : frames.front().timeS;
    double dMax = 1, tMax = 1;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        detectedSteps_ += static_cast<int>(detector.process(frames[k], events));
        const double t = frames[k].timeS - t0;
        tMax = t;
        if (k % 4 != 0) continue; // every 4th frame is plenty for the eye
        for (std::size_t i = 0; i < eng::kShoeSensorCount; ++i) {
            pressure[i].second.append({t, static_cast<double>(frames[k].raw[i])});
            const double d = detector.derivativePerS(i);
            derivative[i].second.append({t, d});
            dMax = std::max(dMax, d);
        }
    }
    for (std::size_t i = 0; i < eng::kShoeSensorCount; ++i) {
        const double onset = thr.sensors[i].onsetDerivativePerS;
        derivative.push_back({tr("%1 onset").arg(q(std::string(eng::shoeSensorName(i)))),
                              {{0, onset}, {tMax, onset}}});
    }
    setSeries(pressureChart_, pressure, tMax, 0, 1023);
    setSeries(derivativeChart_, derivative, tMax, -dMax * 0.1, dMax * 1.05);
    // Each sensor's threshold dashed, in that sensor's colour.
    const auto series = derivativeChart_->series();
    for (qsizetype j = static_cast<qsizetype>(eng::kShoeSensorCount); j < series.size(); ++j) {
        auto* line = static_cast<QLineSeries*>(series[j]);
        QPen pen(static_cast<QLineSeries*>(series[j - 4])->color());
        pen.setStyle(Qt::DashLine);
        pen.setWidthF(1.5);
        line->setPen(pen);
    }
    QString text = tr("Proposed onset thresholds (units/s): ");
    for (std::size_t i = 0; i < eng::kShoeSensorCount; ++i)
        text += tr("%1 %2%3")
                    .arg(q(std::string(eng::shoeSensorName(i))))
                    .arg(thr.sensors[i].onsetDerivativePerS, 0, 'f', 0)
                    .arg(i + 1 < eng::kShoeSensorCount ? ", " : ". ");
    text +=
        expectedSteps >= 0
            ? tr("With them the detector finds %1 of the %2 strikes in the "
                 "recording.")
                  .arg(detectedSteps_)
                  .arg(expectedSteps)
            : tr("With them the detector finds %1 strikes in the recording.").arg(detectedSteps_);
    for (const auto& w : result_->warnings) text += "\n" + tr("Warning: %1").arg(q(w));
    calibration_->setText(text);
}

QString SetupView::saveThresholds() {
    if (!result_) {
        calibration_->setText(tr("Record and calibrate first (Ctrl+B)."));
        return {};
    }
    const QString code = participant_->text().trimmed();
    if (!QRegularExpression("^[A-Za-z0-9_.-]{1,32}$").match(code).hasMatch()) {
        calibration_->setText(tr("Type the participant's code first (Alt+P): letters, digits, "
                                 "dot, dash, underscore."));
        return {};
    }
    auto thresholds = result_->thresholds;
    thresholds.participant = code.toStdString();
    const QString dir = QDir(dataDir_).filePath("thresholds");
    QDir().mkpath(dir);
    const QString path = QDir(dir).filePath(code + ".toml");
    try {
        eng::saveStepThresholds(path.toStdString(), thresholds, result_.get());
    } catch (const std::exception& e) {
        calibration_->setText(q(e.what()));
        return {};
    }
    calibration_->setText(calibration_->text() + "\n" + tr("Saved %1").arg(path));
    return path;
}

} // namespace underfoot::gui
