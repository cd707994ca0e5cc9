// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A confusion matrix drawn as a heat map: rows are presented stimuli, columns answer options,
/// colour is the row percentage, the text the count. Hovering a cell shows what it means.
#include "analysis/tables/Tables.h"

#include <QWidget>

namespace underfoot::gui {

class HeatMap : public QWidget {
    Q_OBJECT
  public:
    explicit HeatMap(QWidget* parent = nullptr);
    /// Shows `matrix` (an empty matrix shows a hint instead).
    void setMatrix(const analysis::ConfusionMatrix& matrix);
    const analysis::ConfusionMatrix& matrix() const { return matrix_; }
    /// Total count shown (sum of every cell).
    double total() const;
    QSize sizeHint() const override { return {900, 420}; }

  protected:
    void paintEvent(QPaintEvent* event) override;
    bool event(QEvent* event) override;

  private:
    struct Geometry {
        double left = 0, top = 0, cellW = 0, cellH = 0;
    };
    Geometry geometry() const;
    QString rowLabel(std::size_t row) const;
    analysis::ConfusionMatrix matrix_;
};

} // namespace underfoot::gui
