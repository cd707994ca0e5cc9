// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/PalettePlots.h"

#include "engine/render/AudioFeatures.h"

#include <QImage>
#include <QPainter>

#include <algorithm>
#include <cmath>

namespace underfoot::gui {

namespace {
constexpr double kMinHz = 50;

/// An "inferno"-like colour map: dark (quiet) to bright yellow (the step's peak).
QColor colourAt(double level) {
    static const double stops[][3] = {
        {0, 0, 4}, {87, 16, 110}, {188, 55, 84}, {249, 142, 9}, {252, 255, 164}};
    level = std::isfinite(level) ? std::clamp(level, 0.0, 1.0) * 4.0 : 0.0;
    const int i = std::min(3, static_cast<int>(level));
    const double t = level - i;
    return QColor::fromRgb(static_cast<int>(stops[i][0] + t * (stops[i + 1][0] - stops[i][0])),
                           static_cast<int>(stops[i][1] + t * (stops[i + 1][1] - stops[i][1])),
                           static_cast<int>(stops[i][2] + t * (stops[i + 1][2] - stops[i][2])));
}

QString hzLabel(double f) {
    return f >= 1000 ? QString("%1k").arg(f / 1000, 0, 'g', 3) : QString::number(f, 'g', 3);
}
} // namespace

StepSpectrogram stepSpectrogram(const std::vector<float>& step, double rateHz, double maxHz) {
    StepSpectrogram s;
    s.rateHz = rateHz;
    s.maxHz = std::min(maxHz, 0.5 * rateHz);
    s.seconds = static_cast<double>(step.size()) / rateHz;
    engine::AudioBuffer a;
    a.sampleRateHz = rateHz;
    a.channels = 1;
    a.samples = step;
    a.samples.resize(std::max<std::size_t>(step.size(), static_cast<std::size_t>(s.fftSize)), 0.f);
    s.db = engine::spectrogramDb(a, s.fftSize, s.hop);
    s.peakDb = -300;
    for (const auto& frame : s.db)
        for (float v : frame) s.peakDb = std::max(s.peakDb, v);
    return s;
}

SpectrogramPlot::SpectrogramPlot(QWidget* parent) : QWidget(parent) {
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
}

void SpectrogramPlot::setSpectrogram(const StepSpectrogram& s, const QString& title) {
    data_ = s;
    title_ = title;
    setAccessibleDescription(
        tr("%1: spectrogram of one step, %2 ms").arg(title).arg(s.seconds * 1e3, 0, 'f', 0));
    update();
}

void SpectrogramPlot::clear(const QString& placeholder) {
    data_ = {};
    title_ = placeholder;
    update();
}

void SpectrogramPlot::setTimeSpan(double seconds) {
    span_ = seconds;
    update();
}

void SpectrogramPlot::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.fillRect(rect(), palette().base());
    const QFontMetrics fm = p.fontMetrics();
    const int left = fm.horizontalAdvance("10k Hz") + 6, right = 44, top = fm.height() + 4,
              bottom = 2 * fm.height() + 4;
    const QRect area(left, top, std::max(10, width() - left - right),
                     std::max(10, height() - top - bottom));
    p.setPen(palette().text().color());
    p.drawText(QRect(left, 0, width() - left, top), Qt::AlignLeft | Qt::AlignVCenter, title_);
    p.drawRect(area.adjusted(-1, -1, 0, 0));
    if (data_.empty()) return;

    const double frameSpan = static_cast<double>(data_.db.size()) * data_.hop / data_.rateHz;
    const double span = std::max({span_, data_.seconds, frameSpan});
    const double f0 = std::log2(kMinHz), f1 = std::log2(std::max(kMinHz * 2, data_.maxHz));
    // One image pixel per screen pixel: frames along x (up to the step's end), bands along y.
    QImage image(area.width(), area.height(), QImage::Format_RGB32);
    image.fill(colourAt(0));
    const int frames = static_cast<int>(data_.db.size());
    const int bins = static_cast<int>(data_.db.front().size());
    const double frameSeconds = data_.hop / data_.rateHz;
    for (int x = 0; x < area.width(); ++x) {
        const double t = span * (x + 0.5) / area.width();
        const int frame = static_cast<int>(t / frameSeconds);
        if (frame >= frames || t > data_.seconds) break;
        const auto& row = data_.db[static_cast<std::size_t>(frame)];
        for (int y = 0; y < area.height(); ++y) {
            const double fa = std::exp2(f0 + (f1 - f0) * (area.height() - y - 1) / area.height());
            const double fb = std::exp2(f0 + (f1 - f0) * (area.height() - y) / area.height());
            int ka = static_cast<int>(fa / data_.rateHz * data_.fftSize);
            int kb = static_cast<int>(std::ceil(fb / data_.rateHz * data_.fftSize));
            ka = std::clamp(ka, 0, bins - 1);
            kb = std::clamp(std::max(kb, ka + 1), 1, bins);
            float m = -300;
            for (int k = ka; k < kb; ++k) m = std::max(m, row[static_cast<std::size_t>(k)]);
            const double level = (m - (data_.peakDb - kRangeDb)) / kRangeDb;
            image.setPixel(x, y, colourAt(level).rgb());
        }
    }
    p.drawImage(area.topLeft(), image);

    // Frequency axis (Hz, log) and time axis (s).
    p.setPen(palette().text().color());
    for (double f : {100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0}) {
        if (f >= data_.maxHz) continue;
        const int y =
            area.bottom() - static_cast<int>((std::log2(f) - f0) / (f1 - f0) * area.height());
        p.drawLine(area.left() - 4, y, area.left() - 1, y);
        p.drawText(QRect(0, y - fm.height() / 2, left - 6, fm.height()),
                   Qt::AlignRight | Qt::AlignVCenter, hzLabel(f));
    }
    p.save();
    p.translate(fm.height() / 2 + 1, area.center().y());
    p.rotate(-90);
    p.drawText(QRect(-40, -fm.height() / 2, 80, fm.height()), Qt::AlignCenter, tr("Hz"));
    p.restore();
    const double tick = span > 0.6 ? 0.2 : 0.1;
    for (double t = 0; t <= span + 1e-9; t += tick) {
        const int x = area.left() + static_cast<int>(t / span * area.width());
        p.drawLine(x, area.bottom() + 1, x, area.bottom() + 4);
        p.drawText(QRect(x - 20, area.bottom() + 4, 40, fm.height()), Qt::AlignCenter,
                   QString::number(t, 'f', 1));
    }
    p.drawText(QRect(area.left(), area.bottom() + 4 + fm.height(), area.width(), fm.height()),
               Qt::AlignCenter, tr("time (s)"));

    // The colour scale, shared by every plot: dB re the step's peak.
    const QRect bar(area.right() + 8, area.top(), 8, area.height());
    for (int y = 0; y < bar.height(); ++y) {
        p.setPen(colourAt(1.0 - double(y) / bar.height()));
        p.drawLine(bar.left(), bar.top() + y, bar.right(), bar.top() + y);
    }
    p.setPen(palette().text().color());
    p.drawText(QRect(bar.right() + 2, bar.top() - 2, right - 18, fm.height()), Qt::AlignLeft,
               tr("0"));
    p.drawText(QRect(bar.right() + 2, bar.bottom() - fm.height() + 2, right - 18, fm.height()),
               Qt::AlignLeft, QString::number(-kRangeDb, 'f', 0));
    p.drawText(QRect(bar.left() - 6, area.bottom() + 4 + fm.height(), right, fm.height()),
               Qt::AlignLeft, tr("dB"));
}

BandBars::BandBars(QWidget* parent) : QWidget(parent) {
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
}

void BandBars::setBands(const QStringList& labels, const std::vector<double>& recorded,
                        const std::vector<double>& synthetic) {
    labels_ = labels;
    recorded_ = recorded;
    synthetic_ = synthetic;
    update();
}

void BandBars::clear() {
    labels_.clear();
    recorded_.clear();
    synthetic_.clear();
    update();
}

void BandBars::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.fillRect(rect(), palette().base());
    const QFontMetrics fm = p.fontMetrics();
    const int left = fm.horizontalAdvance("-40 dB") + 8, right = 6, top = 2 * fm.height() + 6,
              bottom = fm.height() + 6;
    const QRect area(left, top, std::max(10, width() - left - right),
                     std::max(10, height() - top - bottom));
    p.setPen(palette().text().color());
    p.drawText(QRect(0, 0, width(), fm.height() + 2), Qt::AlignLeft | Qt::AlignVCenter,
               tr("Band energy re whole band (median step)"));
    const QColor recColour(31, 119, 180), synColour(214, 39, 40);
    const int lx = left;
    const int ly = fm.height() + 4;
    p.fillRect(lx, ly + 2, 10, fm.height() - 4, recColour);
    p.drawText(lx + 14, ly + fm.ascent(), tr("recorded"));
    const int sx = lx + 20 + fm.horizontalAdvance(tr("recorded"));
    p.fillRect(sx, ly + 2, 10, fm.height() - 4, synColour);
    p.drawText(sx + 14, ly + fm.ascent(), tr("current settings"));
    if (labels_.isEmpty()) {
        p.drawRect(area);
        return;
    }
    double lo = -30;
    for (const auto* v : {&recorded_, &synthetic_})
        for (double x : *v)
            if (std::isfinite(x)) lo = std::min(lo, std::floor(x / 10.0) * 10.0);
    lo = std::max(lo, -80.0);
    auto Y = [&](double v) {
        return area.top() + static_cast<int>(std::clamp(v, lo, 0.0) / lo * area.height());
    };
    p.setPen(QColor(200, 200, 200));
    for (double v = 0; v >= lo; v -= 10) {
        p.drawLine(area.left(), Y(v), area.right(), Y(v));
    }
    p.setPen(palette().text().color());
    for (double v = 0; v >= lo; v -= 10)
        p.drawText(QRect(0, Y(v) - fm.height() / 2, left - 4, fm.height()),
                   Qt::AlignRight | Qt::AlignVCenter, QString("%1 dB").arg(v, 0, 'f', 0));
    const int n = static_cast<int>(labels_.size());
    const double group = double(area.width()) / n;
    for (int i = 0; i < n; ++i) {
        const int gx = area.left() + static_cast<int>(group * i);
        const int barW = std::max(4, static_cast<int>(group * 0.35));
        const auto bar = [&](double v, int x, const QColor& c) {
            if (!std::isfinite(v)) return;
            const int y = Y(v);
            p.fillRect(QRect(x, area.top(), barW, y - area.top()).normalized(), c);
            p.drawText(QRect(x - 10, y + 1, barW + 20, fm.height()), Qt::AlignCenter,
                       QString::number(v, 'f', 1));
        };
        const int x0 = gx + static_cast<int>(group * 0.12);
        if (i < static_cast<int>(recorded_.size())) bar(recorded_[std::size_t(i)], x0, recColour);
        if (i < static_cast<int>(synthetic_.size()))
            bar(synthetic_[std::size_t(i)], x0 + barW + 2, synColour);
        p.drawText(QRect(gx, area.bottom() + 3, static_cast<int>(group), fm.height()),
                   Qt::AlignCenter, labels_[i]);
    }
    p.drawLine(area.left(), area.top(), area.right(), area.top());
}

} // namespace underfoot::gui
