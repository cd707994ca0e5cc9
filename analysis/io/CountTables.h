// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Import of published confusion tables (protocols/data/*_confusion.csv): a `stimulus` column,
/// an optional `soundscape` column, then one column per answer code (BS, GL, ..., DK).
#include "analysis/tables/Tables.h"

#include <string>
#include <string_view>

namespace underfoot::analysis {

/// Parses a count table. Codes map to surface ids (model/Catalog.h), DK to "dont_know",
/// soundscape labels ("Ski slope") to soundscape ids. Throws std::runtime_error with
/// "source:line:column: ..." on unknown codes, non-integer or negative counts, wrong widths.
/// `nominalRowTotal` (presentations per row, NaN if unknown) lets the analysis flag rows that
/// do not add up.
ConfusionMatrix parseCountTable(std::string_view text, std::string_view sourceName,
                                std::string group, double nominalRowTotal);

/// Reads a count table file; the group is named after the file ("..._confusion" removed).
ConfusionMatrix readCountTable(const std::string& path, double nominalRowTotal);

} // namespace underfoot::analysis
