// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/Figures.h"

#include "experiment/Catalogue.h"

#include <QFileInfo>
#include <QImage>
#include <QPainter>
#include <QSvgGenerator>

#include <cmath>

namespace underfoot::gui {

QString saveFigure(const FigurePainter& paint, const QSizeF& size, const QString& path,
                   const QString& title) {
    const QString suffix = QFileInfo(path).suffix().toLower();
    if (size.width() <= 0 || size.height() <= 0)
        return QObject::tr("%1: the figure is empty").arg(path);
    if (suffix == "svg") {
        QSvgGenerator svg;
        svg.setFileName(path);
        svg.setSize(size.toSize());
        svg.setViewBox(QRectF(QPointF(0, 0), size));
        svg.setResolution(72);
        svg.setTitle(title);
        svg.setDescription(QObject::tr("Underfoot console figure"));
        QPainter p;
        if (!p.begin(&svg)) return QObject::tr("%1: cannot write the SVG file").arg(path);
        paint(p, size);
        p.end();
        return QFileInfo(path).size() > 0 ? QString()
                                          : QObject::tr("%1: the SVG file is empty").arg(path);
    }
    if (suffix == "png") {
        const double scale = kPrintDpi / 96.0;
        QImage image((size * scale).toSize(), QImage::Format_ARGB32);
        image.fill(Qt::white);
        const int dpm = static_cast<int>(std::lround(kPrintDpi / 0.0254));
        image.setDotsPerMeterX(dpm);
        image.setDotsPerMeterY(dpm);
        QPainter p(&image);
        p.setRenderHint(QPainter::Antialiasing);
        p.setRenderHint(QPainter::TextAntialiasing);
        p.scale(scale, scale);
        paint(p, size);
        p.end();
        if (!image.save(path, "PNG")) return QObject::tr("%1: cannot write the PNG file").arg(path);
        return {};
    }
    return QObject::tr("%1: unknown figure format '%2'; use .svg or .png").arg(path, suffix);
}

namespace {
QString number(double v) {
    return QString::number(v, 'f', 2);
}
QString degrees(double df) {
    return std::fabs(df - std::round(df)) < 1e-9 ? QString::number(std::llround(df))
                                                 : QString::number(df, 'f', 1);
}
} // namespace

QString testInWords(const analysis::TestResult& test) {
    if (!test.ok()) return QString::fromStdString(test.error);
    QString name = QString::fromStdString(test.statisticName);
    if (name == "X-squared") name = QString::fromUtf8("\u03c7\u00b2");
    QString df;
    for (double d : test.df) df += (df.isEmpty() ? "" : ", ") + degrees(d);
    QString out;
    if (std::isfinite(test.statistic))
        out = QString("%1%2 = %3, ")
                  .arg(name, df.isEmpty() ? QString() : "(" + df + ")", number(test.statistic));
    if (!std::isfinite(test.p)) return out + "p = —";
    if (test.p < 0.001) return out + "p < 0.001";
    return out + "p = " + QString::number(test.p, 'f', 3);
}

QString surfaceLabel(const std::string& id) {
    if (const auto* e = experiment::defaultCatalogue().surface(id))
        return QString::fromStdString(e->label);
    return QString::fromStdString(id);
}

QString soundscapeLabel(const std::string& id) {
    if (const auto* e = experiment::defaultCatalogue().soundscape(id))
        return QString::fromStdString(e->label);
    return QString::fromStdString(id);
}

} // namespace underfoot::gui
