// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The row of a rating scale's buttons (one checkable button per value, min..max), shared by the
/// experimenter's Run view and the participant window so that both show and take a rating the
/// same way; each caller keeps its own sizes and what a click does.
#include "experiment/Protocol.h"

#include <QFont>
#include <QSize>

#include <functional>
#include <optional>
#include <vector>

class QBoxLayout;
class QPushButton;
class QWidget;

namespace underfoot::gui {

struct ScaleRowStyle {
    QSize minimumButtonSize{48, 36};
    std::optional<QFont> font; ///< the buttons' font (default: the parent's)
};

/// Adds to `column` a row with a button per value of `scale` (children of `parent`), checkable,
/// without keyboard focus (keys go to the window's handler), accessible as "<scale id>: <value>";
/// a click calls `picked(value)`. Returns the buttons in value order.
std::vector<QPushButton*> addScaleRow(QBoxLayout* column, QWidget* parent,
                                      const experiment::Scale& scale, const ScaleRowStyle& style,
                                      std::function<void(int)> picked);

/// Checks the button of `value` (and no other; none when there is no value).
void showScaleValue(const std::vector<QPushButton*>& buttons, const experiment::Scale& scale,
                    std::optional<int> value);

} // namespace underfoot::gui
