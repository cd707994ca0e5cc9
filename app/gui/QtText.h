// SPDX-License-Identifier: GPL-3.0-or-later
// The views' one-letter conversion from the library's UTF-8 std::string to QString.
#pragma once

#include <QString>

#include <string>

namespace underfoot::gui {

inline QString q(const std::string& s) {
    return QString::fromStdString(s);
}

} // namespace underfoot::gui
