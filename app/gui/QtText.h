// SPDX-License-Identifier: GPL-3.0-or-later
// The views' text helpers: the library's UTF-8 std::string as QString, counted nouns, and a
// widget's font scaled up.
#pragma once

#include <QFont>
#include <QString>
#include <QWidget>

#include <string>

namespace underfoot::gui {

inline QString q(const std::string& s) {
    return QString::fromStdString(s);
}

/// "1 participant", "3 participants": `n` with the singular or the plural noun.
inline QString counted(long long n, const QString& one, const QString& many) {
    return QString("%1 %2").arg(n).arg(n == 1 ? one : many);
}

/// `w`'s font, `factor` times its size.
inline QFont scaledFont(const QWidget* w, double factor) {
    QFont f = w->font();
    f.setPointSizeF(f.pointSizeF() * factor);
    return f;
}

} // namespace underfoot::gui
