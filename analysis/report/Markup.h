// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Escaping text for the report formats (internal to analysis/report): one implementation for
/// the confusion report (Export.cpp) and the rating report (RatingReport.cpp).
#include <string>
#include <string_view>

namespace underfoot::analysis::markup {

/// HTML/SVG text and attribute values: & < > " '.
std::string xmlEscape(std::string_view text);
/// LaTeX text: the ten special characters, < and >, and the UTF-8 ± and ² the tables use.
std::string latexEscape(std::string_view text);
/// A Markdown table cell: | escaped, line breaks as spaces.
std::string markdownCell(std::string_view text);

/// What a report that includes simulated participants says at its top: "Simulated data: 6 of 6
/// participants ..." ("" when `simulated` is 0; `total` 0 leaves the total out).
std::string simulatedNotice(int simulated, int total);
/// The notice as an HTML banner (a <p class="banner simulated" role="note">; "" when none).
std::string simulatedBannerHtml(int simulated, int total);

} // namespace underfoot::analysis::markup
