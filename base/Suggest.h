// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The "did you mean" of every message about an unknown name (a TOML key, a surface id, a
/// catalogue entry): the closest candidate by Levenshtein edit distance (Wagner & Fischer 1974,
/// "The string-to-string correction problem", JACM 21(1)), case-insensitive.
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::base {

/// The candidate closest to `name` by edit distance (insertions, deletions, substitutions;
/// case-insensitive), or "" when none is within half the name's length. A candidate that
/// contains `name` ("snow" in "deep_snow") counts as distance 1.
std::string closestName(std::string_view name, const std::vector<std::string>& candidates);

/// "a, b, c (did you mean 'b'?)": the names sorted, and the closest one to `name` when any.
std::string sortedIdsWithSuggestion(std::string_view name, std::vector<std::string> ids);

} // namespace underfoot::base
