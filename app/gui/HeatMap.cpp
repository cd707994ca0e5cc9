// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/HeatMap.h"

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
    setAccessibleDescription(tr("%1 stimuli by %2 answers, %3 answers in total")
                                 .arg(matrix_.rows.size())
                                 .arg(matrix_.columns.options.size())
                                 .arg(total()));
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
    QString s = QString::fromStdString(k.surfaceId);
    if (!k.soundscapeId.empty()) s += " + " + QString::fromStdString(k.soundscapeId);
    return s;
}

HeatMap::Geometry HeatMap::geometry() const {
    Geometry g;
    const QFontMetrics fm(font());
    double labelW = 0;
    for (std::size_t r = 0; r < matrix_.rows.size(); ++r)
        labelW = std::max(labelW, static_cast<double>(fm.horizontalAdvance(rowLabel(r))));
    double headerH = 0;
    for (const auto& c : matrix_.columns.options)
        headerH = std::max(headerH,
                           static_cast<double>(fm.horizontalAdvance(QString::fromStdString(c.id))));
    g.left = labelW + 12;
    g.top = std::min(headerH, 140.0) + 12;
    const double cols = std::max<double>(1, static_cast<double>(matrix_.columns.options.size()));
    const double rows = std::max<double>(1, static_cast<double>(matrix_.rows.size()));
    g.cellW = std::max(18.0, (width() - g.left - 8) / cols);
    g.cellH = std::max(16.0, std::min(34.0, (height() - g.top - 8) / rows));
    return g;
}

void HeatMap::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing, false);
    if (matrix_.rows.empty() || matrix_.columns.options.empty()) {
        p.drawText(rect(), Qt::AlignCenter,
                   tr("No answered trials yet: the matrix fills in as answers are committed."));
        return;
    }
    const Geometry g = geometry();
    const QFontMetrics fm(font());
    // Column headers, rotated.
    for (std::size_t c = 0; c < matrix_.columns.options.size(); ++c) {
        p.save();
        p.translate(g.left + (static_cast<double>(c) + 0.5) * g.cellW + fm.ascent() / 2.0,
                    g.top - 6);
        p.rotate(-90);
        p.drawText(0, 0, QString::fromStdString(matrix_.columns.options[c].id));
        p.restore();
    }
    for (std::size_t r = 0; r < matrix_.rows.size(); ++r) {
        const double y = g.top + static_cast<double>(r) * g.cellH;
        p.setPen(palette().color(QPalette::Text));
        p.drawText(QRectF(0, y, g.left - 6, g.cellH), Qt::AlignRight | Qt::AlignVCenter,
                   rowLabel(r));
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
                p.drawText(cell, Qt::AlignCenter, QString::number(count, 'g', 4));
            }
        }
    }
}

bool HeatMap::event(QEvent* e) {
    if (e->type() == QEvent::ToolTip && !matrix_.rows.empty()) {
        auto* help = static_cast<QHelpEvent*>(e);
        const Geometry g = geometry();
        const double x = (help->pos().x() - g.left) / g.cellW;
        const double y = (help->pos().y() - g.top) / g.cellH;
        if (x >= 0 && y >= 0 && x < static_cast<double>(matrix_.columns.options.size()) &&
            y < static_cast<double>(matrix_.rows.size())) {
            const auto r = static_cast<std::size_t>(y), c = static_cast<std::size_t>(x);
            QToolTip::showText(
                help->globalPos(),
                tr("%1 answered %2: %3 of %4 (%5 %)")
                    .arg(rowLabel(r), QString::fromStdString(matrix_.columns.options[c].label))
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
