// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// One CSV cell as every CSV the project writes spells it: RFC 4180 quoting (a cell holding a
// comma, a quote, CR or LF is quoted, quotes doubled), and formula-leading text made inert for
// spreadsheets (OWASP "CSV injection"): a cell starting with =, +, -, @, a tab or CR gets a
// leading apostrophe, unless the whole cell is a finite number (-1.5, +3, -2e-05 stay numbers,
// so R's read.csv and the analysis read them back unchanged). A reader that wants the text
// back removes one leading apostrophe from a cell whose second character is one of those six.
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

namespace underfoot::base {

/// Whether `cell` would start a formula in a spreadsheet (and is not a plain number).
inline bool csvFormulaLeading(std::string_view cell) {
    if (cell.empty()) return false;
    const char c = cell.front();
    // A cell that already looks protected is protected again, so that reading back is exact.
    if (c == '\'') return cell.size() > 1 && csvFormulaLeading(cell.substr(1));
    if (c != '=' && c != '+' && c != '-' && c != '@' && c != '\t' && c != '\r') return false;
    if (c == '+' || c == '-') {
        const std::string text(cell);
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() + text.size() && std::isfinite(v) && text.size() > 1 &&
            text.find_first_of("xXnNiI") == std::string::npos) // not hex, nan or inf
            return false;
    }
    return true;
}

/// The cell as written into a CSV file (see the header).
inline std::string csvCell(std::string_view value) {
    std::string text = csvFormulaLeading(value) ? "'" + std::string(value) : std::string(value);
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + '"';
}

/// Undoes csvCell's protection of a cell read back (after unquoting): drops one leading
/// apostrophe before a formula-leading cell.
inline void csvUnprotect(std::string& cell) {
    if (cell.size() > 1 && cell.front() == '\'' &&
        csvFormulaLeading(std::string_view(cell).substr(1)))
        cell.erase(0, 1);
}

} // namespace underfoot::base
