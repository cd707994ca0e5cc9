// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Figures of the Results view (heat map, ratings plot) drawn by one paint function, so that
/// the same drawing goes to the screen, to SVG (QSvgGenerator) and to PNG at print resolution;
/// and the tests' results in words ("χ²(1) = 8.90, p = 0.003").
#include "analysis/stats/TestResult.h"

#include <QSizeF>
#include <QString>

#include <functional>

class QPainter;

namespace underfoot::gui {

/// Draws a figure into a rectangle of the given size (in points, origin top left).
using FigurePainter = std::function<void(QPainter&, const QSizeF&)>;

/// Print resolution of PNG exports (dots per inch).
inline constexpr int kPrintDpi = 300;

/// Writes the figure to `path`: `.svg` as vector graphics (size in points at 72 per inch,
/// `title` as the SVG title), `.png` at kPrintDpi (the size is taken at 96 logical dpi, so a
/// 900 x 420 figure becomes 2813 x 1313 pixels). Returns "" or what went wrong.
QString saveFigure(const FigurePainter& paint, const QSizeF& size, const QString& path,
                   const QString& title);

/// A test's result as a sentence part, APA style: "χ²(1) = 8.90, p = 0.003",
/// "t(11.8) = 2.31, p = 0.040", "p < 0.001"; the R error when the test did not run.
QString testInWords(const analysis::TestResult& test);

/// The surface's label from the catalogue ("beach sand"), or the id when unknown.
QString surfaceLabel(const std::string& id);
/// The soundscape's label from the catalogue, or the id when unknown.
QString soundscapeLabel(const std::string& id);

} // namespace underfoot::gui
