// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/TrialCsv.h"

#include "analysis/io/Csv.h"
#include "analysis/model/Catalog.h"
#include "base/Plural.h"
#include "base/TrialColumns.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

namespace underfoot::analysis {

const std::vector<std::string>& trialCsvColumns() {
    static const std::vector<std::string> columns(base::kTrialColumns.begin(),
                                                  base::kTrialColumns.end());
    return columns;
}

const std::vector<std::string>& requiredTrialCsvColumns() {
    static const std::vector<std::string> columns{
        "participant", "group",   "practice", "stimulus_id",       "surface", "soundscape",
        "answer",      "realism", "quality",  "soundscape_answer", "excluded"};
    return columns;
}

namespace {

class RowReader {
  public:
    RowReader(std::string_view source, const csv::Record& header, const csv::Record& row,
              const std::map<std::string, std::size_t>& index)
        : source_(source), header_(header), row_(row), index_(index) {}

    std::string text(const std::string& column) const {
        auto it = index_.find(column);
        if (it == index_.end()) return {};
        return row_.fields[it->second];
    }
    /// The cell of a column that every row must fill ("source:line: empty participant
    /// (expected a participant code)" otherwise).
    std::string nonEmpty(const std::string& column, const char* expected) const {
        std::string v = text(column);
        if (v.empty())
            throw std::runtime_error(
                fmt::format("{}:{}: empty {} (expected {})", source_, row_.line, column, expected));
        return v;
    }
    std::optional<bool> boolean(const std::string& column) const {
        const std::string v = text(column);
        if (v.empty()) return std::nullopt;
        if (v == "1" || v == "true" || v == "TRUE") return true;
        if (v == "0" || v == "false" || v == "FALSE") return false;
        throw error(column, v, "0 or 1");
    }
    double number(const std::string& column) const {
        const std::string v = text(column);
        if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
        double out = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
        if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(out))
            throw error(column, v, "a finite number or an empty cell");
        return out;
    }
    int integer(const std::string& column) const {
        const std::string v = text(column);
        if (v.empty()) return 0;
        int out = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
        if (ec != std::errc() || end != v.data() + v.size())
            throw error(column, v, "an integer or an empty cell");
        return out;
    }

  private:
    std::runtime_error error(const std::string& column, const std::string& value,
                             const char* expected) const {
        const std::size_t col = index_.at(column) + 1;
        return std::runtime_error(fmt::format("{}:{}: column {} ('{}'): got '{}', expected {}",
                                              source_, row_.line, col, column, value, expected));
    }
    std::string_view source_;
    const csv::Record& header_;
    const csv::Record& row_;
    const std::map<std::string, std::size_t>& index_;
};

} // namespace

namespace {

std::vector<TrialRecord> recordsToTrials(const std::vector<csv::Record>& records,
                                         std::string_view sourceName) {
    if (records.empty())
        throw std::runtime_error(
            fmt::format("{}:1: empty file, expected a header line of trial columns", sourceName));
    const auto& header = records.front();
    std::map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < header.fields.size(); ++i) {
        if (!index.emplace(header.fields[i], i).second)
            throw std::runtime_error(fmt::format("{}:{}: column '{}' appears twice in the header",
                                                 sourceName, header.line, header.fields[i]));
    }
    std::string missing;
    int missingCount = 0;
    for (const auto& column : requiredTrialCsvColumns())
        if (!index.count(column)) {
            missing += (missing.empty() ? "" : ", ") + column;
            ++missingCount;
        }
    if (!missing.empty())
        throw std::runtime_error(
            fmt::format("{}:{}: missing required {} {} (expected the header of `underfoot export`)",
                        sourceName, header.line, plural(missingCount, "column"), missing));
    std::vector<TrialRecord> out;
    out.reserve(records.size() - 1);
    for (std::size_t r = 1; r < records.size(); ++r) {
        const auto& row = records[r];
        if (row.fields.size() != header.fields.size())
            throw std::runtime_error(fmt::format("{}:{}: {} fields, expected {} as in the header",
                                                 sourceName, row.line, row.fields.size(),
                                                 header.fields.size()));
        const RowReader cells(sourceName, header, row, index);
        TrialRecord t;
        t.study = cells.text("study");
        t.participant = cells.nonEmpty("participant", "a participant code");
        t.group = cells.text("group");
        t.session = cells.text("session");
        t.trialIndex = cells.integer("trial_index");
        t.block = cells.text("block");
        t.practice = cells.boolean("practice").value_or(false);
        t.stimulusId = cells.text("stimulus_id");
        t.surfaceId = cells.nonEmpty("surface", "the presented surface id");
        t.soundscapeId = cells.text("soundscape");
        t.modalities = cells.text("modalities");
        t.repetition = cells.integer("repetition");
        t.answerId = cells.text("answer");
        t.recordedCorrect = cells.boolean("correct");
        t.realism = cells.number("realism");
        t.quality = cells.number("quality");
        t.soundscapeAnswer = cells.text("soundscape_answer");
        t.recordedSoundscapeCorrect = cells.boolean("soundscape_correct");
        t.responseTimeSeconds = cells.number("response_time_s");
        t.excluded = cells.boolean("excluded").value_or(false);
        t.exclusionReason = cells.text("exclusion_reason");
        t.simulated = cells.boolean("simulated").value_or(false);
        out.push_back(std::move(t));
    }
    return out;
}

} // namespace

std::vector<TrialRecord> parseTrialCsv(std::string_view text, std::string_view sourceName) {
    return recordsToTrials(csv::parse(text, sourceName), sourceName);
}

std::vector<TrialRecord> readTrialCsv(const std::string& path) {
    return recordsToTrials(csv::readFile(path), path);
}

namespace {
std::string formatNumber(double v) {
    return std::isnan(v) ? std::string() : fmt::format("{}", v);
}
std::string formatBool(std::optional<bool> v) {
    return v ? (*v ? "1" : "0") : "";
}
} // namespace

std::string formatTrialCsv(const std::vector<TrialRecord>& records) {
    std::string out = csv::joinLine(trialCsvColumns()) + "\n";
    for (const auto& t : records) {
        const std::vector<std::string> fields{t.study,
                                              "",
                                              "",
                                              "",
                                              t.participant,
                                              t.group,
                                              t.session,
                                              std::to_string(t.trialIndex),
                                              t.block,
                                              t.practice ? "1" : "0",
                                              t.stimulusId,
                                              t.surfaceId,
                                              t.soundscapeId,
                                              t.modalities,
                                              t.surfaceId.ends_with("_reverb") ? "1" : "0",
                                              std::to_string(t.repetition),
                                              "",
                                              t.answerId,
                                              t.answerId.empty() ? "" : labelFor(t.answerId),
                                              formatBool(t.recordedCorrect),
                                              formatNumber(t.realism),
                                              formatNumber(t.quality),
                                              t.soundscapeAnswer,
                                              formatBool(t.recordedSoundscapeCorrect),
                                              formatNumber(t.responseTimeSeconds),
                                              t.excluded ? "1" : "0",
                                              t.exclusionReason,
                                              "",
                                              "",
                                              "",
                                              std::to_string(t.trialIndex + 1),
                                              t.simulated ? "1" : "0",
                                              "", // clip_file .. clip_sha256: not read back
                                              "",
                                              "",
                                              ""};
        out += csv::joinLine(fields) + "\n";
    }
    return out;
}

} // namespace underfoot::analysis
