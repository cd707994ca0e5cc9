// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/CountTables.h"

#include "analysis/io/Csv.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace underfoot::analysis {

namespace {

std::string answerIdForCode(const std::string& code) {
    if (code == "DK" || code == "dk" || code == kDontKnowId) return std::string(kDontKnowId);
    if (auto s = findSurface(code)) return s->id;
    return {};
}

} // namespace

ConfusionMatrix parseCountTable(std::string_view text, std::string_view sourceName,
                                std::string group, double nominalRowTotal) {
    const auto records = csv::parse(text, sourceName);
    if (records.empty())
        throw std::runtime_error(fmt::format("{}:1: empty file, expected a header "
                                             "'stimulus,[soundscape,]CODE,...'",
                                             sourceName));
    const auto& header = records.front().fields;
    if (header.empty() || header[0] != "stimulus")
        throw std::runtime_error(fmt::format("{}:1:1: first column is '{}', expected 'stimulus'",
                                             sourceName, header.empty() ? "" : header[0]));
    const bool hasSoundscape = header.size() > 1 && header[1] == "soundscape";
    const std::size_t firstCount = hasSoundscape ? 2 : 1;
    ConfusionMatrix m;
    m.group = std::move(group);
    m.nominalRowTotal = nominalRowTotal;
    for (std::size_t j = firstCount; j < header.size(); ++j) {
        const std::string id = answerIdForCode(header[j]);
        if (id.empty())
            throw std::runtime_error(fmt::format(
                "{}:1:{}: unknown answer code '{}' (expected a surface code such as BS, GL, "
                "WD or DK)",
                sourceName, j + 1, header[j]));
        if (m.columns.indexOf(id))
            throw std::runtime_error(fmt::format("{}:1:{}: answer code '{}' appears twice",
                                                 sourceName, j + 1, header[j]));
        m.columns.options.push_back({id, labelFor(id)});
    }
    if (m.columns.options.empty())
        throw std::runtime_error(
            fmt::format("{}:1: no answer columns after 'stimulus'", sourceName));
    for (std::size_t r = 1; r < records.size(); ++r) {
        const auto& rec = records[r];
        if (rec.fields.size() != header.size())
            throw std::runtime_error(fmt::format("{}:{}: {} fields, expected {} as in the header",
                                                 sourceName, rec.line, rec.fields.size(),
                                                 header.size()));
        const auto surface = findSurface(rec.fields[0]);
        if (!surface)
            throw std::runtime_error(fmt::format(
                "{}:{}:1: unknown stimulus code '{}' (expected a surface code such as BS)",
                sourceName, rec.line, rec.fields[0]));
        StimulusKey key{surface->id, ""};
        if (hasSoundscape && !rec.fields[1].empty()) {
            const auto id = findSoundscapeId(rec.fields[1]);
            if (!id)
                throw std::runtime_error(fmt::format(
                    "{}:{}:2: unknown soundscape '{}' (expected e.g. Forest, Beach, Ski slope)",
                    sourceName, rec.line, rec.fields[1]));
            key.soundscapeId = *id;
        }
        std::vector<double> row;
        for (std::size_t j = firstCount; j < rec.fields.size(); ++j) {
            const std::string& cell = rec.fields[j];
            long long value = 0;
            const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
            if (cell.empty() || ec != std::errc() || end != cell.data() + cell.size() || value < 0)
                throw std::runtime_error(
                    fmt::format("{}:{}:{}: count '{}' is not a non-negative integer", sourceName,
                                rec.line, j + 1, cell));
            row.push_back(static_cast<double>(value));
        }
        m.rows.push_back(key);
        m.counts.push_back(std::move(row));
    }
    return m;
}

ConfusionMatrix readCountTable(const std::string& path, double nominalRowTotal) {
    std::string group = std::filesystem::path(path).stem().string();
    constexpr std::string_view suffix = "_confusion";
    if (group.size() > suffix.size() && group.ends_with(suffix))
        group.resize(group.size() - suffix.size());
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot open the file for reading", path));
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return parseCountTable(buffer.str(), path, std::move(group), nominalRowTotal);
}

} // namespace underfoot::analysis
