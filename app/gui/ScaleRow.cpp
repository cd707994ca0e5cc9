// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/ScaleRow.h"

#include <QBoxLayout>
#include <QHBoxLayout>
#include <QPushButton>

namespace underfoot::gui {

std::vector<QPushButton*> addScaleRow(QBoxLayout* column, QWidget* parent,
                                      const experiment::Scale& scale, const ScaleRowStyle& style,
                                      std::function<void(int)> picked) {
    auto* row = new QHBoxLayout;
    column->addLayout(row);
    std::vector<QPushButton*> buttons;
    for (int v = scale.min; v <= scale.max; ++v) {
        auto* b = new QPushButton(QString::number(v), parent);
        b->setCheckable(true);
        b->setFocusPolicy(Qt::NoFocus);
        b->setMinimumSize(style.minimumButtonSize);
        if (style.font) b->setFont(*style.font);
        b->setStyleSheet("QPushButton:checked { background: #1f6feb; color: white; "
                         "font-weight: bold; }");
        b->setAccessibleName(QStringLiteral("%1: %2").arg(QString::fromStdString(scale.id)).arg(v));
        QObject::connect(b, &QPushButton::clicked, parent, [picked, v] { picked(v); });
        row->addWidget(b);
        buttons.push_back(b);
    }
    row->addStretch();
    return buttons;
}

void showScaleValue(const std::vector<QPushButton*>& buttons, const experiment::Scale& scale,
                    std::optional<int> value) {
    for (std::size_t b = 0; b < buttons.size(); ++b)
        buttons[b]->setChecked(value && *value == scale.min + static_cast<int>(b));
}

} // namespace underfoot::gui
