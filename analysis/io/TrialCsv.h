// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The long-format trial CSV of `underfoot export`: one row per trial, columns read by header
/// name (extra columns are ignored; missing required columns are an error naming the file).
#include "analysis/model/TrialRecord.h"

#include <string>
#include <string_view>
#include <vector>

namespace underfoot::analysis {

/// Header of the long-format trial CSV, in the order `underfoot export` writes it.
const std::vector<std::string>& trialCsvColumns();

/// Columns that must be present for an analysis.
const std::vector<std::string>& requiredTrialCsvColumns();

/// Parses a trial CSV text. Throws std::runtime_error with "source:line: ..." messages on
/// missing required columns, wrong field counts and malformed cells (booleans 0/1, finite
/// numbers; an empty cell means missing).
std::vector<TrialRecord> parseTrialCsv(std::string_view text, std::string_view sourceName);

/// Reads a trial CSV file (see parseTrialCsv).
std::vector<TrialRecord> readTrialCsv(const std::string& path);

/// Writes records in the long format with the full header (used for synthetic studies and
/// round-trip tests; the experiment layer's export writes the same columns).
std::string formatTrialCsv(const std::vector<TrialRecord>& records);

} // namespace underfoot::analysis
