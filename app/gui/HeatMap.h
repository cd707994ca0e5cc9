// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A confusion matrix drawn as a heat map: rows are presented stimuli, columns answer options
/// (the protocol's labels), colour is the row percentage, each cell shows its count and row
/// percentage; axis titles name both. Hovering a cell shows what it means. The same drawing is
/// exported as SVG or PNG (saveFigure).
#include "analysis/tables/Tables.h"

#include <QWidget>

class QPainter;

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
    /// Draws the heat map into `size` (screen and export).
    void paintFigure(QPainter& painter, const QSizeF& size) const;
    /// Writes the heat map as .svg or .png (print resolution); "" or what went wrong.
    QString save(const QString& path) const;
    /// The text of row `row` / column `column` (protocol labels).
    QString rowLabel(std::size_t row) const;
    QString columnLabel(std::size_t column) const;

  protected:
    void paintEvent(QPaintEvent* event) override;
    bool event(QEvent* event) override;

  private:
    struct Geometry {
        double left = 0, top = 0, cellW = 0, cellH = 0;
    };
    Geometry geometry(const QSizeF& size) const;
    analysis::ConfusionMatrix matrix_;
};

} // namespace underfoot::gui
