// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// RFC 4180 CSV reading and writing (quoted fields, doubled quotes, line breaks in quotes).
#include <cstddef>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::analysis::csv {

/// One record with the line on which it starts (1-based).
struct Record {
    std::size_t line = 0;
    std::vector<std::string> fields;
};

/// Parses a whole CSV text. Throws std::runtime_error naming `sourceName` and the line when a
/// quoted field is not closed or a quote appears inside an unquoted field.
std::vector<Record> parse(std::string_view text, std::string_view sourceName);

/// Reads a file and parses it; throws std::runtime_error naming the file when it cannot be read.
std::vector<Record> readFile(const std::string& path);

/// Quotes a field when it contains a comma, quote or line break.
std::string escape(std::string_view field);

/// Joins fields into one CSV line (without the line break).
std::string joinLine(const std::vector<std::string>& fields);

} // namespace underfoot::analysis::csv
