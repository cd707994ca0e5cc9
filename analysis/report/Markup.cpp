// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/Markup.h"

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

} // namespace underfoot::analysis::markup
