// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Counts in words with the right number: counted(1, "participant") is "1 participant",
/// counted(2, "participant") "2 participants", counted(0, "trial") "0 trials"; an irregular
/// plural is given (counted(n, "child", "children")). English: only 1 takes the singular.
#include <concepts>
#include <string>
#include <string_view>

namespace underfoot {

/// The noun alone, singular for 1 and plural otherwise ("s" appended unless `plural` is given).
template <std::integral N>
std::string plural(N n, std::string_view singular, std::string_view pluralForm = {}) {
    if (n == 1) return std::string(singular);
    return pluralForm.empty() ? std::string(singular) + "s" : std::string(pluralForm);
}

/// "1 participant", "3 participants".
template <std::integral N>
std::string counted(N n, std::string_view singular, std::string_view pluralForm = {}) {
    return std::to_string(n) + " " + plural(n, singular, pluralForm);
}

} // namespace underfoot
