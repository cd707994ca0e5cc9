// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/Csv.h"

#include "base/CsvCell.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace underfoot::analysis::csv {

std::vector<Record> parse(std::string_view text, std::string_view sourceName) {
    std::vector<Record> records;
    std::size_t line = 1, i = 0;
    if (text.substr(0, 3) == "\xEF\xBB\xBF") i = 3; // UTF-8 byte order mark
    while (i < text.size()) {
        Record record;
        record.line = line;
        std::string field;
        bool endOfRecord = false;
        while (!endOfRecord) {
            field.clear();
            if (i < text.size() && text[i] == '"') {
                const std::size_t openLine = line;
                ++i;
                bool closed = false;
                while (i < text.size()) {
                    const char c = text[i];
                    if (c == '"') {
                        if (i + 1 < text.size() && text[i + 1] == '"') {
                            field += '"';
                            i += 2;
                            continue;
                        }
                        ++i;
                        closed = true;
                        break;
                    }
                    if (c == '\n') ++line;
                    field += c;
                    ++i;
                }
                if (!closed)
                    throw std::runtime_error(
                        fmt::format("{}:{}: quoted field is not closed (expected a closing '\"')",
                                    sourceName, openLine));
                if (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r')
                    throw std::runtime_error(
                        fmt::format("{}:{}: expected ',' or end of line after a quoted field",
                                    sourceName, line));
            } else {
                while (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r') {
                    if (text[i] == '"')
                        throw std::runtime_error(fmt::format(
                            "{}:{}: quote inside an unquoted field (expected the whole field "
                            "in quotes)",
                            sourceName, line));
                    field += text[i++];
                }
            }
            base::csvUnprotect(field); // the apostrophe csvCell put before a formula
            record.fields.push_back(field);
            if (i >= text.size()) {
                endOfRecord = true;
            } else if (text[i] == ',') {
                ++i;
            } else {
                if (text[i] == '\r') ++i;
                if (i < text.size() && text[i] == '\n') ++i;
                ++line;
                endOfRecord = true;
            }
        }
        const bool blank = record.fields.size() == 1 && record.fields[0].empty();
        if (!blank) records.push_back(std::move(record));
    }
    return records;
}

std::vector<Record> readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot open the file for reading", path));
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return parse(buffer.str(), path);
}

std::string escape(std::string_view field) {
    return base::csvCell(field);
}

std::string joinLine(const std::vector<std::string>& fields) {
    std::string out;
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (i > 0) out += ',';
        out += escape(fields[i]);
    }
    return out;
}

} // namespace underfoot::analysis::csv
