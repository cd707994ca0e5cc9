// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/Markup.h"
#include "base/Plural.h"

#include <fmt/format.h>

namespace underfoot::analysis::markup {

std::string xmlEscape(std::string_view text) {
    std::string out;
    for (char c : text) {
        switch (c) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        case '\'':
            out += "&#39;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

std::string latexEscape(std::string_view text) {
    std::string out;
    for (char c : text) {
        switch (c) {
        case '&':
            out += "\\&";
            break;
        case '%':
            out += "\\%";
            break;
        case '$':
            out += "\\$";
            break;
        case '#':
            out += "\\#";
            break;
        case '_':
            out += "\\_";
            break;
        case '{':
            out += "\\{";
            break;
        case '}':
            out += "\\}";
            break;
        case '~':
            out += "\\textasciitilde{}";
            break;
        case '^':
            out += "\\textasciicircum{}";
            break;
        case '\\':
            out += "\\textbackslash{}";
            break;
        case '<':
            out += "\\textless{}";
            break;
        case '>':
            out += "\\textgreater{}";
            break;
        default:
            out += c;
        }
    }
    // UTF-8 symbols used by the tables
    std::string replaced;
    for (std::size_t i = 0; i < out.size();) {
        if (out.compare(i, 2, "\xC2\xB1") == 0) {
            replaced += "$\\pm$";
            i += 2;
        } else if (out.compare(i, 2, "\xC2\xB2") == 0) {
            replaced += "$^2$";
            i += 2;
        } else {
            replaced += out[i++];
        }
    }
    return replaced;
}

std::string markdownCell(std::string_view text) {
    std::string out;
    for (char c : text) {
        if (c == '|')
            out += "\\|";
        else if (c == '\n')
            out += ' ';
        else
            out += c;
    }
    return out;
}

std::string simulatedNotice(int simulated, int total) {
    if (simulated <= 0) return "";
    const std::string who = total > 0
                                ? fmt::format("{} of {}", simulated, counted(total, "participant"))
                                : counted(simulated, "participant");
    return fmt::format("Simulated data: {} in this report {} synthetic (made by `underfoot session "
                       "--simulate`), not people; its figures describe the simulation.",
                       who, simulated == 1 && total <= 1 ? "is" : "are");
}

std::string simulatedBannerHtml(int simulated, int total) {
    const std::string notice = simulatedNotice(simulated, total);
    if (notice.empty()) return "";
    return "<p class=\"banner simulated\" role=\"note\" style=\"background:#fff3cd;border:2px "
           "solid #b58100;padding:0.6em 1em;font-weight:600\">" +
           xmlEscape(notice) + "</p>\n";
}

} // namespace underfoot::analysis::markup
