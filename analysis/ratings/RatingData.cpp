// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/ratings/RatingData.h"

#include "analysis/io/Csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace underfoot::analysis {

namespace {

std::size_t column(const csv::Record& header, const std::string& name, const std::string& source) {
    const auto it = std::find(header.fields.begin(), header.fields.end(), name);
    if (it == header.fields.end())
        throw std::runtime_error(
            fmt::format("{}:{}: missing column '{}'", source, header.line, name));
    return static_cast<std::size_t>(it - header.fields.begin());
}

double number(const std::string& text, const std::string& source, std::size_t line,
              const std::string& what) {
    std::size_t used = 0;
    double v = std::numeric_limits<double>::quiet_NaN();
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v))
        throw std::runtime_error(
            fmt::format("{}:{}: {} is '{}'; expected a finite number", source, line, what, text));
    return v;
}

void addUnique(std::vector<std::string>& list, const std::string& value) {
    if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

bool isNumber(const std::string& s) {
    if (s.empty()) return false;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    return *end == '\0' && std::isfinite(v);
}

} // namespace

RatingData parseRatingData(const std::string& ratingsCsv, const std::string& ratingsSource,
                           const std::string& participantsCsv,
                           const std::string& participantsSource, const std::string& scalesCsv,
                           const std::string& scalesSource) {
    RatingData data;
    const auto records = csv::parse(ratingsCsv, ratingsSource);
    if (records.empty())
        throw std::runtime_error(fmt::format("{}: empty; expected the ratings CSV of `underfoot "
                                             "export`",
                                             ratingsSource));
    const csv::Record& header = records.front();
    const std::size_t cParticipant = column(header, "participant", ratingsSource);
    const std::size_t cStimulus = column(header, "stimulus_id", ratingsSource);
    const std::size_t cPractice = column(header, "practice", ratingsSource);
    const std::size_t cExcluded = column(header, "excluded", ratingsSource);
    const std::size_t cScale = column(header, "scale", ratingsSource);
    const std::size_t cValue = column(header, "value", ratingsSource);
    // Factor columns: between 'excluded' and 'scale'.
    std::vector<std::pair<std::string, std::size_t>> factorColumns;
    for (std::size_t c = cExcluded + 1; c < cScale; ++c) {
        factorColumns.emplace_back(header.fields[c], c);
        data.factorOrder.push_back(header.fields[c]);
    }
    std::vector<std::string> scaleOrder;
    for (std::size_t r = 1; r < records.size(); ++r) {
        const auto& f = records[r].fields;
        if (f.size() == 1 && f[0].empty()) continue;
        if (f.size() != header.fields.size())
            throw std::runtime_error(fmt::format("{}:{}: {} fields; expected {} as in the header",
                                                 ratingsSource, records[r].line, f.size(),
                                                 header.fields.size()));
        if (f[cPractice] == "1" || f[cExcluded] == "1") continue;
        RatingObservation o;
        o.participant = f[cParticipant];
        o.stimulus = f[cStimulus];
        o.scale = f[cScale];
        o.value = number(f[cValue], ratingsSource, records[r].line, "value");
        for (const auto& [name, c] : factorColumns) {
            if (f[c].empty()) continue;
            o.factors[name] = f[c];
            addUnique(data.levelOrder[name], f[c]);
        }
        addUnique(data.stimulusOrder, o.stimulus);
        addUnique(scaleOrder, o.scale);
        data.ratings.push_back(std::move(o));
    }
    // Numeric levels (cadences) in numeric order, others as first seen.
    for (auto& [name, levels] : data.levelOrder)
        if (std::all_of(levels.begin(), levels.end(), isNumber))
            std::stable_sort(levels.begin(), levels.end(), [](const auto& a, const auto& b) {
                return std::strtod(a.c_str(), nullptr) < std::strtod(b.c_str(), nullptr);
            });

    // Stimuli in factor-level order (first factor slowest) when every stimulus has every factor.
    std::map<std::string, std::map<std::string, std::string>> factorsOf;
    for (const auto& o : data.ratings) factorsOf[o.stimulus] = o.factors;
    const bool fullyCrossed =
        !data.factorOrder.empty() &&
        std::all_of(factorsOf.begin(), factorsOf.end(), [&](const auto& entry) {
            return entry.second.size() == data.factorOrder.size();
        });
    if (fullyCrossed) {
        auto key = [&](const std::string& stimulus) {
            std::vector<std::size_t> k;
            for (const auto& f : data.factorOrder) {
                const auto& levels = data.levelOrder[f];
                k.push_back(static_cast<std::size_t>(
                    std::find(levels.begin(), levels.end(), factorsOf[stimulus][f]) -
                    levels.begin()));
            }
            return k;
        };
        std::stable_sort(
            data.stimulusOrder.begin(), data.stimulusOrder.end(),
            [&](const std::string& a, const std::string& b) { return key(a) < key(b); });
    }

    if (!scalesCsv.empty()) {
        const auto rows = csv::parse(scalesCsv, scalesSource);
        if (rows.empty()) throw std::runtime_error(fmt::format("{}: empty", scalesSource));
        const auto& h = rows.front();
        const std::size_t cId = column(h, "scale", scalesSource);
        const std::size_t cPrompt = column(h, "prompt", scalesSource);
        const std::size_t cMin = column(h, "min", scalesSource);
        const std::size_t cMax = column(h, "max", scalesSource);
        const std::size_t cAnchors = column(h, "anchors", scalesSource);
        for (std::size_t r = 1; r < rows.size(); ++r) {
            const auto& f = rows[r].fields;
            if (f.size() != h.fields.size()) continue;
            RatingScaleInfo s;
            s.id = f[cId];
            s.prompt = f[cPrompt];
            s.min = number(f[cMin], scalesSource, rows[r].line, "min");
            s.max = number(f[cMax], scalesSource, rows[r].line, "max");
            s.anchors = f[cAnchors];
            data.scales.push_back(std::move(s));
        }
    }
    for (const auto& id : scaleOrder) {
        if (std::any_of(data.scales.begin(), data.scales.end(),
                        [&](const RatingScaleInfo& s) { return s.id == id; }))
            continue;
        RatingScaleInfo s;
        s.id = id;
        s.prompt = id;
        s.min = std::numeric_limits<double>::infinity();
        s.max = -std::numeric_limits<double>::infinity();
        for (const auto& o : data.ratings)
            if (o.scale == id) {
                s.min = std::min(s.min, o.value);
                s.max = std::max(s.max, o.value);
            }
        data.scales.push_back(std::move(s));
    }
    // Scales declared but never rated are dropped (nothing to analyse).
    std::erase_if(data.scales, [&](const RatingScaleInfo& s) {
        return std::find(scaleOrder.begin(), scaleOrder.end(), s.id) == scaleOrder.end();
    });

    if (!participantsCsv.empty()) {
        const auto rows = csv::parse(participantsCsv, participantsSource);
        if (rows.empty()) throw std::runtime_error(fmt::format("{}: empty", participantsSource));
        const auto& h = rows.front();
        const std::size_t cCode = column(h, "participant", participantsSource);
        const std::size_t cHearing = column(h, "hearing", participantsSource);
        for (std::size_t c = cHearing + 1; c < h.fields.size(); ++c)
            data.groupingFields.push_back(h.fields[c]);
        for (std::size_t r = 1; r < rows.size(); ++r) {
            const auto& f = rows[r].fields;
            if (f.size() != h.fields.size()) continue;
            for (std::size_t c = cHearing + 1; c < h.fields.size(); ++c)
                if (!f[c].empty()) data.participantFields[f[cCode]][h.fields[c]] = f[c];
        }
    }
    return data;
}

namespace {
std::string slurp(const std::string& path) {
    if (path.empty()) return {};
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot open the file", path));
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}
} // namespace

RatingData readRatingData(const std::string& ratingsPath, const std::string& participantsPath,
                          const std::string& scalesPath) {
    return parseRatingData(slurp(ratingsPath), ratingsPath, slurp(participantsPath),
                           participantsPath, slurp(scalesPath), scalesPath);
}

} // namespace underfoot::analysis
