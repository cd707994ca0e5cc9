// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/RatingsPlot.h"

#include "analysis/stats/Tests.h"
#include "app/gui/Figures.h"
#include "app/gui/QtText.h"

#include <QPainter>
#include <QPainterPath>

#include <cmath>
#include <limits>
#include <map>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

QString stimulusLabel(const exp::Stimulus& s) {
    QString out = s.label.empty() ? surfaceLabel(s.surface) : QString::fromStdString(s.label);
    if (s.label.empty() && s.soundscape) out += " + " + soundscapeLabel(*s.soundscape);
    if (!s.factors.empty()) {
        QStringList f;
        for (const auto& [name, level] : s.factors)
            f << QString("%1 %2").arg(QString::fromStdString(name), QString::fromStdString(level));
        out += " (" + f.join(", ") + ")";
    }
    return out;
}

RatingSeries ratingSeries(const exp::StudyStore& store, const std::string& scaleId) {
    RatingSeries series;
    series.scaleId = scaleId;
    const exp::Protocol& p = store.protocol();
    const exp::Scale* scale = p.questions.scale(scaleId);
    if (!scale) return series;
    series.min = scale->min;
    series.max = scale->max;
    QStringList anchors;
    for (const auto& [value, wording] : scale->anchors)
        anchors << QString("%1 = %2").arg(value).arg(QString::fromStdString(wording));
    if (anchors.isEmpty() && !scale->minLabel.empty())
        anchors << QString("%1 = %2").arg(scale->min).arg(QString::fromStdString(scale->minLabel))
                << QString("%1 = %2").arg(scale->max).arg(QString::fromStdString(scale->maxLabel));
    series.title = QString("%1 (%2–%3%4)")
                       .arg(QString::fromStdString(scale->prompt))
                       .arg(scale->min)
                       .arg(scale->max)
                       .arg(anchors.isEmpty() ? QString() : "; " + anchors.join(", "));
    const bool between = p.design == exp::DesignKind::Between;
    // Conditions in protocol order: groups as declared, stimuli as declared.
    std::map<std::pair<int, int>, RatingCondition> byKey;
    std::map<std::string, int> groupOrder;
    for (std::size_t g = 0; g < p.groups.size(); ++g)
        groupOrder[p.groups[g].id] = static_cast<int>(g);
    std::map<std::string, int> stimulusOrder;
    for (std::size_t s = 0; s < p.stimuli.size(); ++s)
        stimulusOrder[p.stimuli[s].id] = static_cast<int>(s);
    for (const auto& person : store.participants()) {
        for (const auto& t : store.trials(person.code)) {
            if (!t.answered || t.excluded || t.practice) continue;
            const auto it = t.answer.ratings.find(scaleId);
            if (it == t.answer.ratings.end()) continue;
            const int g = between ? groupOrder[person.groupId] : 0;
            const auto so = stimulusOrder.find(t.stimulus.id);
            const int s =
                so == stimulusOrder.end() ? static_cast<int>(stimulusOrder.size()) : so->second;
            auto& c = byKey[{g, s}];
            if (c.label.isEmpty()) {
                c.label = stimulusLabel(t.stimulus);
                if (between) {
                    const exp::Group* group = p.group(person.groupId);
                    c.label = QString::fromStdString(
                                  group && !group->label.empty() ? group->label : person.groupId) +
                              " · " + c.label;
                }
            }
            c.values.push_back(it->second);
        }
    }
    for (auto& [key, c] : byKey) {
        double sum = 0;
        for (double v : c.values) sum += v;
        c.mean = sum / static_cast<double>(c.values.size());
        c.ciLow = c.ciHigh = std::numeric_limits<double>::quiet_NaN();
        if (c.values.size() >= 2) {
            const auto t = analysis::tTest(c.values);
            if (t.ok() && t.confInt) {
                c.ciLow = t.confInt->lower;
                c.ciHigh = t.confInt->upper;
            } else {
                c.ciLow = c.ciHigh = c.mean; // all values equal: no spread
            }
        }
        series.conditions.push_back(std::move(c));
    }
    return series;
}

RatingsPlot::RatingsPlot(QWidget* parent) : QWidget(parent) {
    setAccessibleName(tr("Ratings per condition"));
    setMinimumHeight(260);
}

void RatingsPlot::setSeries(RatingSeries series) {
    series_ = std::move(series);
    setAccessibleDescription(
        tr("%1: %2").arg(series_.title, counted(static_cast<long long>(series_.conditions.size()),
                                                tr("condition"), tr("conditions"))));
    update();
}

void RatingsPlot::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    paintFigure(p, QSizeF(size()));
}

QString RatingsPlot::save(const QString& path) const {
    if (series_.conditions.empty()) return tr("%1: no ratings yet, nothing to draw").arg(path);
    const double height = 90.0 + 26.0 * static_cast<double>(series_.conditions.size());
    return saveFigure([this](QPainter& p, const QSizeF& s) { paintFigure(p, s); },
                      QSizeF(900, height), path, series_.title);
}

void RatingsPlot::paintFigure(QPainter& p, const QSizeF& size) const {
    p.setFont(font());
    p.fillRect(QRectF(QPointF(0, 0), size), Qt::white);
    p.setPen(Qt::black);
    if (series_.conditions.empty()) {
        p.drawText(QRectF(QPointF(0, 0), size), Qt::AlignCenter,
                   tr("No ratings yet: the plot fills in as answers are committed."));
        return;
    }
    // Conditions are rows (their labels, however long, read horizontally on the left); the
    // scale runs along the x axis.
    const QFontMetrics fm(font());
    double longest = 0;
    QStringList labels;
    for (const auto& c : series_.conditions) {
        labels << QString("%1  (n = %2)").arg(c.label).arg(c.values.size());
        longest = std::max(longest, static_cast<double>(fm.horizontalAdvance(labels.back())));
    }
    const double labelW = std::min(longest + 12, size.width() * 0.5);
    const double top = 34, bottom = 2.5 * fm.height() + 8, right = 20;
    const QRectF plot(labelW, top, size.width() - labelW - right, size.height() - top - bottom);
    if (plot.width() <= 10 || plot.height() <= 10) return;
    const double span = std::max(1, series_.max - series_.min);
    const auto xOf = [&](double v) {
        return plot.left() + (v - series_.min + 0.5) / (span + 1.0) * plot.width();
    };
    QFont bold = font();
    bold.setBold(true);
    p.setFont(bold);
    p.drawText(QRectF(0, 0, size.width(), top - 4), Qt::AlignCenter | Qt::TextWordWrap,
               series_.title);
    p.setFont(font());
    // X axis: a tick per scale point, grid lines, axis title.
    const int step = span > 12 ? 2 : 1;
    for (int v = series_.min; v <= series_.max; v += step) {
        const double x = xOf(v);
        p.setPen(QColor(230, 230, 230));
        p.drawLine(QPointF(x, plot.top()), QPointF(x, plot.bottom()));
        p.setPen(Qt::black);
        p.drawText(QRectF(x - 20, plot.bottom() + 2, 40, fm.height()), Qt::AlignCenter,
                   QString::number(v));
    }
    p.setPen(QColor(120, 120, 120));
    p.drawLine(QPointF(plot.left(), plot.bottom()), QPointF(plot.right(), plot.bottom()));
    p.setPen(Qt::black);
    p.drawText(QRectF(plot.left(), plot.bottom() + fm.height() + 2, plot.width(), fm.height()),
               Qt::AlignLeft | Qt::AlignVCenter, tr("Rating"));
    p.setPen(QColor(60, 60, 60));
    p.drawText(QRectF(plot.left(), plot.bottom() + fm.height() + 2, plot.width(), fm.height()),
               Qt::AlignRight | Qt::AlignVCenter,
               tr("dots: each answer · square: mean · whiskers: 95 % CI (t)"));
    const double slot = plot.height() / static_cast<double>(series_.conditions.size());
    for (std::size_t i = 0; i < series_.conditions.size(); ++i) {
        const auto& c = series_.conditions[i];
        const double y = plot.top() + (static_cast<double>(i) + 0.5) * slot;
        p.setPen(Qt::black);
        p.drawText(QRectF(0, y - slot / 2, labelW - 10, slot), Qt::AlignRight | Qt::AlignVCenter,
                   fm.elidedText(labels[static_cast<int>(i)], Qt::ElideMiddle,
                                 static_cast<int>(labelW - 12)));
        // Individual answers: grey dots above the mean, spread by a fixed pattern.
        p.setPen(Qt::NoPen);
        p.setBrush(QColor(110, 110, 110, 150));
        std::map<double, int> seen;
        for (double v : c.values) {
            const int k = seen[v]++;
            const double dx = (k % 2 ? 1 : -1) * ((k + 1) / 2) * 3.0;
            p.drawEllipse(QPointF(xOf(v) + std::clamp(dx, -9.0, 9.0), y - slot * 0.22), 2.5, 2.5);
        }
        // Mean and 95 % CI below them.
        p.setPen(QPen(QColor(31, 111, 235), 2));
        p.setBrush(QColor(31, 111, 235));
        const double my = y + slot * 0.12;
        if (std::isfinite(c.ciLow) && std::isfinite(c.ciHigh)) {
            const double lo = std::max<double>(c.ciLow, series_.min - 0.5);
            const double hi = std::min<double>(c.ciHigh, series_.max + 0.5);
            p.drawLine(QPointF(xOf(lo), my), QPointF(xOf(hi), my));
            p.drawLine(QPointF(xOf(lo), my - 4), QPointF(xOf(lo), my + 4));
            p.drawLine(QPointF(xOf(hi), my - 4), QPointF(xOf(hi), my + 4));
        }
        p.drawRect(QRectF(xOf(c.mean) - 4, my - 4, 8, 8));
    }
}

} // namespace underfoot::gui
