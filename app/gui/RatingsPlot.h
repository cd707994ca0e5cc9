// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Ratings per condition: every answer as a dot (spread sideways, deterministic), the mean as
/// a square and its 95 % confidence interval (t distribution, as R's t.test) as a whisker, on
/// the scale's full range with the scale's prompt and anchors as the axis title. Exported as SVG
/// or PNG like every figure of the Results view.
#include "experiment/Store.h"

#include <QWidget>

#include <string>
#include <vector>

class QPainter;

namespace underfoot::gui {

struct RatingCondition {
    QString label;              ///< the protocol's labels: group · stimulus
    std::vector<double> values; ///< every rating given (answered, not excluded, not practice)
    double mean = 0;
    double ciLow = 0, ciHigh = 0; ///< 95 % CI of the mean (NaN when fewer than two values)
};

struct RatingSeries {
    std::string scaleId;
    QString title; ///< prompt, range and anchors
    int min = 1, max = 7;
    std::vector<RatingCondition> conditions;
};

/// The ratings of scale `scaleId` in the study, per condition (group x stimulus for
/// between-subject designs, stimulus otherwise), in protocol order.
RatingSeries ratingSeries(const experiment::StudyStore& store, const std::string& scaleId);

/// The stimulus as people read it: its label, else the surface (+ soundscape) labels.
QString stimulusLabel(const experiment::Stimulus& stimulus);

class RatingsPlot : public QWidget {
    Q_OBJECT
  public:
    explicit RatingsPlot(QWidget* parent = nullptr);
    void setSeries(RatingSeries series);
    const RatingSeries& series() const { return series_; }
    QSize sizeHint() const override { return {900, 420}; }
    void paintFigure(QPainter& painter, const QSizeF& size) const;
    /// Writes the plot as .svg or .png (print resolution); "" or what went wrong.
    QString save(const QString& path) const;

  protected:
    void paintEvent(QPaintEvent* event) override;

  private:
    RatingSeries series_;
};

} // namespace underfoot::gui
