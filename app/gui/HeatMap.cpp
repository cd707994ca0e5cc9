// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/HeatMap.h"

#include "app/gui/Figures.h"
#include "app/gui/QtText.h"

#include <QHelpEvent>
#include <QPainter>
#include <QToolTip>

#include <cmath>

namespace underfoot::gui {

HeatMap::HeatMap(QWidget* parent) : QWidget(parent) {
    setAccessibleName(tr("Confusion matrix heat map"));
    setMinimumHeight(260);
    setBackgroundRole(QPalette::Base);
    setAutoFillBackground(true);
}

void HeatMap::setMatrix(const analysis::ConfusionMatrix& matrix) {
    matrix_ = matrix;
    setAccessibleDescription(
        tr("%1 by %2, %3 in total")
            .arg(
                counted(static_cast<long long>(matrix_.rows.size()), tr("stimulus"), tr("stimuli")),
                counted(static_cast<long long>(matrix_.columns.options.size()), tr("answer"),
                        tr("answers")),
                counted(std::llround(total()), tr("answer"), tr("answers"))));
    update();
}

double HeatMap::total() const {
    double sum = 0;
    for (const auto& row : matrix_.counts)
        for (double v : row) sum += v;
    return sum;
}

QString HeatMap::rowLabel(std::size_t row) const {
    const auto& k = matrix_.rows[row];
    QString s = surfaceLabel(k.surfaceId);
    if (!k.soundscapeId.empty()) s += " + " + soundscapeLabel(k.soundscapeId);
    return s;
}

QString HeatMap::columnLabel(std::size_t column) const {
    const auto& o = matrix_.columns.options[column];
    return QString::fromStdString(o.label.empty() ? o.id : o.label);
}

namespace {
constexpr double kAxisTitle = 22; // room for an axis title
}

HeatMap::Geometry HeatMap::geometry(const QSizeF& size) const {
    Geometry g;
    const QFontMetrics fm(font());
    double labelW = 0;
    for (std::size_t r = 0; r < matrix_.rows.size(); ++r)
        labelW = std::max(labelW, static_cast<double>(fm.horizontalAdvance(rowLabel(r))));
    double headerH = 0;
    for (std::size_t c = 0; c < matrix_.columns.options.size(); ++c)
        headerH = std::max(headerH, static_cast<double>(fm.horizontalAdvance(columnLabel(c))));
    g.left = kAxisTitle + labelW + 12;
    g.top = kAxisTitle + std::min(headerH, 160.0) + 12;
    const double cols = std::max<double>(1, static_cast<double>(matrix_.columns.options.size()));
    const double rows = std::max<double>(1, static_cast<double>(matrix_.rows.size()));
    g.cellW = std::max(30.0, (size.width() - g.left - 8) / cols);
    g.cellH = std::max(28.0, std::min(40.0, (size.height() - g.top - 8) / rows));
    return g;
}

void HeatMap::paintEvent(QPaintEvent*) {
    QPainter p(this);
    paintFigure(p, QSizeF(size()));
}

QString HeatMap::save(const QString& path) const {
    if (matrix_.rows.empty()) return tr("%1: no answers yet, nothing to draw").arg(path);
    const Geometry g = geometry(QSizeF(900, 420));
    const QSizeF size(g.left + g.cellW * static_cast<double>(matrix_.columns.options.size()) + 8,
                      g.top + g.cellH * static_cast<double>(matrix_.rows.size()) + 8);
    return saveFigure([this](QPainter& p, const QSizeF& s) { paintFigure(p, s); }, size, path,
                      tr("Confusion matrix, group %1").arg(QString::fromStdString(matrix_.group)));
}

void HeatMap::paintFigure(QPainter& p, const QSizeF& size) const {
    p.setRenderHint(QPainter::Antialiasing, false);
    p.setFont(font());
    p.fillRect(QRectF(QPointF(0, 0), size), Qt::white);
    p.setPen(Qt::black);
    if (matrix_.rows.empty() || matrix_.columns.options.empty()) {
        p.drawText(QRectF(QPointF(0, 0), size), Qt::AlignCenter,
                   tr("No answered trials yet: the matrix fills in as answers are committed."));
        return;
    }
    const Geometry g = geometry(size);
    const QFontMetrics fm(font());
    const double gridW = g.cellW * static_cast<double>(matrix_.columns.options.size());
    const double gridH = g.cellH * static_cast<double>(matrix_.rows.size());
    // Axis titles.
    QFont bold = font();
    bold.setBold(true);
    p.setFont(bold);
    p.drawText(QRectF(g.left, 0, gridW, kAxisTitle), Qt::AlignCenter,
               tr("Answer given (cell: count and row %)"));
    p.save();
    p.translate(0, g.top + gridH / 2);
    p.rotate(-90);
    p.drawText(QRectF(-gridH / 2, 0, gridH, kAxisTitle), Qt::AlignCenter, tr("Surface presented"));
    p.restore();
    p.setFont(font());
    // Column headers, rotated.
    for (std::size_t c = 0; c < matrix_.columns.options.size(); ++c) {
        p.save();
        p.translate(g.left + (static_cast<double>(c) + 0.5) * g.cellW + fm.ascent() / 2.0,
                    g.top - 6);
        p.rotate(-90);
        p.drawText(0, 0, columnLabel(c));
        p.restore();
    }
    QFont small = font();
    small.setPointSizeF(small.pointSizeF() * 0.8);
    for (std::size_t r = 0; r < matrix_.rows.size(); ++r) {
        const double y = g.top + static_cast<double>(r) * g.cellH;
        p.setPen(Qt::black);
        p.drawText(QRectF(kAxisTitle, y, g.left - kAxisTitle - 6, g.cellH),
                   Qt::AlignRight | Qt::AlignVCenter, rowLabel(r));
        for (std::size_t c = 0; c < matrix_.columns.options.size(); ++c) {
            const double pct = matrix_.rowPercent(r, c);
            const double v = std::isfinite(pct) ? pct / 100.0 : 0.0;
            // White to deep blue (sequential, readable in grey scale).
            const QColor fill = QColor::fromRgbF(static_cast<float>(1.0 - 0.88 * v),
                                                 static_cast<float>(1.0 - 0.62 * v),
                                                 static_cast<float>(1.0 - 0.25 * v));
            const QRectF cell(g.left + static_cast<double>(c) * g.cellW, y, g.cellW, g.cellH);
            p.fillRect(cell, fill);
            p.setPen(QColor(200, 200, 200));
            p.drawRect(cell);
            const double count = matrix_.counts[r][c];
            if (count > 0) {
                p.setPen(v > 0.5 ? Qt::white : Qt::black);
                p.setFont(font());
                p.drawText(cell.adjusted(0, 1, 0, -cell.height() / 2), Qt::AlignCenter,
                           QString::number(count, 'g', 4));
                p.setFont(small);
                p.drawText(cell.adjusted(0, cell.height() / 2, 0, -1), Qt::AlignCenter,
                           QString("%1 %").arg(pct, 0, 'f', 0));
                p.setFont(font());
            }
        }
    }
}

bool HeatMap::event(QEvent* e) {
    if (e->type() == QEvent::ToolTip && !matrix_.rows.empty()) {
        auto* help = static_cast<QHelpEvent*>(e);
        const Geometry g = geometry(QSizeF(size()));
        const double x = (help->pos().x() - g.left) / g.cellW;
        const double y = (help->pos().y() - g.top) / g.cellH;
        if (x >= 0 && y >= 0 && x < static_cast<double>(matrix_.columns.options.size()) &&
            y < static_cast<double>(matrix_.rows.size())) {
            const auto r = static_cast<std::size_t>(y), c = static_cast<std::size_t>(x);
            QToolTip::showText(help->globalPos(),
                               tr("%1 answered %2: %3 of %4 (%5 %)")
                                   .arg(rowLabel(r), columnLabel(c))
                                   .arg(matrix_.counts[r][c])
                                   .arg(matrix_.rowTotal(r))
                                   .arg(matrix_.rowPercent(r, c), 0, 'f', 1),
                               this);
        } else {
            QToolTip::hideText();
        }
        return true;
    }
    return QWidget::event(e);
}

} // namespace underfoot::gui
