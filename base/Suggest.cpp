// SPDX-License-Identifier: GPL-3.0-or-later
#include "base/Suggest.h"

#include <algorithm>
#include <cctype>

namespace underfoot::base {

namespace {
char lower(char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}
} // namespace

std::string closestName(std::string_view name, const std::vector<std::string>& candidates) {
    std::string best;
    std::size_t bestDistance = std::max<std::size_t>(1, name.size() / 2) + 1;
    std::string wanted(name);
    for (auto& c : wanted) c = lower(c);
    std::vector<std::size_t> row, previous;
    for (const auto& candidate : candidates) {
        std::string lowered(candidate);
        for (auto& c : lowered) c = lower(c);
        // Wagner-Fischer, two rows.
        previous.resize(lowered.size() + 1);
        row.resize(lowered.size() + 1);
        for (std::size_t j = 0; j <= lowered.size(); ++j) previous[j] = j;
        for (std::size_t i = 1; i <= wanted.size(); ++i) {
            row[0] = i;
            for (std::size_t j = 1; j <= lowered.size(); ++j)
                row[j] = std::min({previous[j] + 1, row[j - 1] + 1,
                                   previous[j - 1] + (wanted[i - 1] == lowered[j - 1] ? 0 : 1)});
            std::swap(row, previous);
        }
        std::size_t distance = previous[lowered.size()];
        if (!wanted.empty() && lowered.find(wanted) != std::string::npos)
            distance = std::min<std::size_t>(distance, 1);
        if (distance < bestDistance) {
            bestDistance = distance;
            best = candidate;
        }
    }
    return best;
}

std::string sortedIdsWithSuggestion(std::string_view name, std::vector<std::string> ids) {
    std::sort(ids.begin(), ids.end());
    std::string out;
    for (const auto& id : ids) out += (out.empty() ? "" : ", ") + id;
    if (const std::string close = closestName(name, ids); !close.empty())
        out += " (did you mean '" + close + "'?)";
    return out;
}

} // namespace underfoot::base
