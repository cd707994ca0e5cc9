// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/tables/Tables.h"

#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"
#include "analysis/tables/ScoringRules.h"
#include "base/Plural.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

namespace underfoot::analysis {

using numerics::dbl;
using numerics::kNaN;

double ConfusionMatrix::rowTotal(std::size_t row) const {
    double s = 0;
    for (double v : counts[row]) s += v;
    return s;
}

double ConfusionMatrix::rowPercent(std::size_t row, std::size_t column) const {
    const double total = rowTotal(row);
    return total > 0 ? 100.0 * counts[row][column] / total : kNaN;
}

double CategoryMatrix::rowPercent(std::size_t row, std::size_t column) const {
    double total = 0;
    for (double v : counts[row]) total += v;
    return total > 0 ? 100.0 * counts[row][column] / total : kNaN;
}

const char* measureName(Measure measure) {
    switch (measure) {
    case Measure::Correct:
        return "correct";
    case Measure::DontKnow:
        return "dont_know";
    case Measure::Realism:
        return "realism";
    case Measure::Quality:
        return "quality";
    }
    return "correct";
}

namespace {

std::size_t surfaceRank(const std::string& id) {
    const auto& catalog = surfaceCatalog();
    for (std::size_t i = 0; i < catalog.size(); ++i)
        if (catalog[i].id == id) return i;
    return catalog.size();
}

std::size_t soundscapeRank(const std::string& id) {
    if (id.empty()) return 0;
    const auto& catalog = soundscapeCatalog();
    for (std::size_t i = 0; i < catalog.size(); ++i)
        if (catalog[i].id == id) return i + 1;
    return catalog.size() + 1;
}

} // namespace

bool stimulusBefore(const StimulusKey& a, const StimulusKey& b) {
    const auto ka = std::make_tuple(surfaceRank(a.surfaceId), a.surfaceId,
                                    soundscapeRank(a.soundscapeId), a.soundscapeId);
    const auto kb = std::make_tuple(surfaceRank(b.surfaceId), b.surfaceId,
                                    soundscapeRank(b.soundscapeId), b.soundscapeId);
    return ka < kb;
}

ConfusionMatrix buildConfusion(std::span<const TrialRecord> trials, const AnswerList& answers,
                               SoundscapeSplit split, const std::string& group) {
    ConfusionMatrix m;
    m.group = group.empty() ? "all" : group;
    m.columns = answers;
    std::vector<const TrialRecord*> used;
    std::set<StimulusKey> keys;
    for (const auto& t : trials) {
        if (!group.empty() && t.group != group) continue;
        if (!rules::entersTables(t)) continue;
        used.push_back(&t);
        keys.insert({t.surfaceId, split == SoundscapeSplit::BySoundscape ? t.soundscapeId : ""});
        m.columns.addBeforeDontKnow(t.answerId);
    }
    m.rows.assign(keys.begin(), keys.end());
    std::sort(m.rows.begin(), m.rows.end(), stimulusBefore);
    std::map<StimulusKey, std::size_t> rowIndex;
    for (std::size_t i = 0; i < m.rows.size(); ++i) rowIndex[m.rows[i]] = i;
    std::map<std::string, std::size_t> columnIndex;
    for (std::size_t j = 0; j < m.columns.options.size(); ++j)
        columnIndex[m.columns.options[j].id] = j;
    m.counts.assign(m.rows.size(), std::vector<double>(m.columns.options.size(), 0.0));
    for (const TrialRecord* t : used) {
        const StimulusKey key{t->surfaceId,
                              split == SoundscapeSplit::BySoundscape ? t->soundscapeId : ""};
        m.counts[rowIndex[key]][columnIndex[t->answerId]] += 1;
    }
    return m;
}

CategoryMatrix buildCategoryMatrix(const ConfusionMatrix& confusion) {
    CategoryMatrix c;
    c.group = confusion.group;
    c.columns = {"solid", "aggregate", "liquid", "dont_know", "other"};
    const std::vector<SurfaceCategory> order{SurfaceCategory::Solid, SurfaceCategory::Aggregate,
                                             SurfaceCategory::Liquid, SurfaceCategory::Unknown};
    std::map<SurfaceCategory, std::vector<double>> rows;
    for (std::size_t i = 0; i < confusion.rows.size(); ++i) {
        auto& row = rows[surfaceCategory(confusion.rows[i].surfaceId)];
        row.resize(c.columns.size(), 0.0);
        for (std::size_t j = 0; j < confusion.columns.options.size(); ++j) {
            const auto& id = confusion.columns.options[j].id;
            std::size_t column = 4;
            if (id == kDontKnowId) {
                column = 3;
            } else {
                switch (surfaceCategory(id)) {
                case SurfaceCategory::Solid:
                    column = 0;
                    break;
                case SurfaceCategory::Aggregate:
                    column = 1;
                    break;
                case SurfaceCategory::Liquid:
                    column = 2;
                    break;
                case SurfaceCategory::Unknown:
                    column = 4;
                    break;
                }
            }
            row[column] += confusion.counts[i][j];
        }
    }
    for (auto category : order) {
        auto it = rows.find(category);
        if (it == rows.end()) continue;
        c.rows.push_back(category);
        c.counts.push_back(it->second);
    }
    // Drop the "other" column when nobody gave an answer outside the catalog.
    bool anyOther = false;
    for (const auto& row : c.counts) anyOther = anyOther || row[4] > 0;
    if (!anyOther) {
        c.columns.pop_back();
        for (auto& row : c.counts) row.pop_back();
    }
    return c;
}

namespace {

/// Everything the summary and the comparisons need about one (group, stimulus).
struct Cell {
    std::string group;
    StimulusKey key;
    double n = 0, correct = 0, dontKnow = 0, soundscapeN = 0, soundscapeCorrect = 0;
    std::vector<double> realism, quality;
};

Proportion proportion(double count, double n, double confLevel) {
    Proportion p;
    p.count = count;
    p.n = n;
    p.percent = n > 0 ? 100.0 * count / n : kNaN;
    const Interval w = wilsonInterval(count, n, confLevel);
    p.wilson = {100.0 * w.lower, 100.0 * w.upper, confLevel};
    return p;
}

MeanSummary meanSummary(const std::vector<double>& values, double confLevel) {
    MeanSummary m;
    m.n = dbl(values.size());
    m.ci.level = confLevel;
    m.values = values;
    if (values.empty()) return m;
    m.mean = numerics::mean(values);
    if (values.size() < 2) return m;
    m.sd = std::sqrt(numerics::variance(values));
    m.se = m.sd / std::sqrt(m.n);
    const double q = numerics::qt((1 + confLevel) / 2, m.n - 1);
    m.ci.lower = m.mean - q * m.se;
    m.ci.upper = m.mean + q * m.se;
    return m;
}

SummaryRow summarize(const Cell& c, double confLevel) {
    SummaryRow r;
    r.group = c.group;
    r.stimulus = c.key;
    r.n = c.n;
    r.correct = proportion(c.correct, c.n, confLevel);
    r.dontKnow = proportion(c.dontKnow, c.n, confLevel);
    r.wrong = proportion(c.n - c.correct - c.dontKnow, c.n, confLevel);
    r.soundscapeCorrect = proportion(c.soundscapeCorrect, c.soundscapeN, confLevel);
    r.realism = meanSummary(c.realism, confLevel);
    r.quality = meanSummary(c.quality, confLevel);
    return r;
}

void sortCells(std::vector<Cell>& cells, const std::vector<std::string>& groups) {
    auto groupRank = [&](const std::string& g) {
        return static_cast<std::size_t>(std::find(groups.begin(), groups.end(), g) -
                                        groups.begin());
    };
    std::stable_sort(cells.begin(), cells.end(), [&](const Cell& a, const Cell& b) {
        if (a.group != b.group) return groupRank(a.group) < groupRank(b.group);
        return stimulusBefore(a.key, b.key);
    });
}

/// Between-group comparisons per surface, pooled over soundscapes within each group.
std::vector<ComparisonRow> compare(const std::vector<Cell>& cells,
                                   const std::vector<std::string>& groups, bool withRatings) {
    std::map<std::pair<std::string, std::string>, Cell> pooled; // (group, surface)
    std::map<std::string, Cell> perGroup;
    std::vector<std::string> surfaces;
    for (const auto& c : cells) {
        auto& p = pooled[{c.group, c.key.surfaceId}];
        p.group = c.group;
        p.key.surfaceId = c.key.surfaceId;
        p.n += c.n;
        p.correct += c.correct;
        p.dontKnow += c.dontKnow;
        p.realism.insert(p.realism.end(), c.realism.begin(), c.realism.end());
        p.quality.insert(p.quality.end(), c.quality.begin(), c.quality.end());
        auto& g = perGroup[c.group];
        g.n += c.n;
        g.dontKnow += c.dontKnow;
        if (std::find(surfaces.begin(), surfaces.end(), c.key.surfaceId) == surfaces.end())
            surfaces.push_back(c.key.surfaceId);
    }
    std::stable_sort(surfaces.begin(), surfaces.end(), [](const auto& a, const auto& b) {
        return stimulusBefore({a, ""}, {b, ""});
    });
    std::vector<ComparisonRow> out;
    for (std::size_t i = 0; i < groups.size(); ++i)
        for (std::size_t j = i + 1; j < groups.size(); ++j) {
            const auto& ga = groups[i];
            const auto& gb = groups[j];
            for (Measure measure : {Measure::Correct, Measure::Realism, Measure::Quality}) {
                if (measure != Measure::Correct && !withRatings) continue;
                const std::size_t first = out.size();
                for (const auto& surface : surfaces) {
                    auto ia = pooled.find({ga, surface});
                    auto ib = pooled.find({gb, surface});
                    if (ia == pooled.end() || ib == pooled.end()) continue;
                    const Cell& a = ia->second;
                    const Cell& b = ib->second;
                    ComparisonRow row;
                    row.measure = measure;
                    row.surfaceId = surface;
                    row.groupA = ga;
                    row.groupB = gb;
                    if (measure == Measure::Correct) {
                        const CountTable table{{a.correct, a.n - a.correct},
                                               {b.correct, b.n - b.correct}};
                        row.nA = a.n;
                        row.nB = b.n;
                        row.valueA = a.n > 0 ? 100 * a.correct / a.n : kNaN;
                        row.valueB = b.n > 0 ? 100 * b.correct / b.n : kNaN;
                        row.test = chisqTest(table);
                        const auto f = fisherTest(table);
                        row.fisherP = f.ok() ? f.p : kNaN;
                        row.effectName = "phi";
                        row.effect = phiCoefficient(table);
                    } else {
                        const auto& xa = measure == Measure::Realism ? a.realism : a.quality;
                        const auto& xb = measure == Measure::Realism ? b.realism : b.quality;
                        row.nA = dbl(xa.size());
                        row.nB = dbl(xb.size());
                        row.valueA = numerics::mean(xa);
                        row.valueB = numerics::mean(xb);
                        row.test = tTest(xa, xb);
                        row.effectName = "Cohen's d";
                        row.effect = cohensD(xa, xb);
                    }
                    out.push_back(std::move(row));
                }
                // Holm across the surfaces of this pair and measure.
                std::vector<double> p;
                for (std::size_t k = first; k < out.size(); ++k)
                    p.push_back(out[k].test.ok() ? out[k].test.p : kNaN);
                const auto adjusted = pAdjust(p, PAdjustMethod::Holm);
                for (std::size_t k = first; k < out.size(); ++k) out[k].pHolm = adjusted[k - first];
            }
            // Share of "I don't know", pooled over surfaces.
            const Cell& a = perGroup[ga];
            const Cell& b = perGroup[gb];
            ComparisonRow row;
            row.measure = Measure::DontKnow;
            row.groupA = ga;
            row.groupB = gb;
            row.nA = a.n;
            row.nB = b.n;
            row.valueA = a.n > 0 ? 100 * a.dontKnow / a.n : kNaN;
            row.valueB = b.n > 0 ? 100 * b.dontKnow / b.n : kNaN;
            const CountTable table{{a.dontKnow, a.n - a.dontKnow}, {b.dontKnow, b.n - b.dontKnow}};
            row.test = chisqTest(table);
            const auto f = fisherTest(table);
            row.fisherP = f.ok() ? f.p : kNaN;
            row.effectName = "phi";
            row.effect = phiCoefficient(table);
            row.pHolm = row.test.ok() ? row.test.p : kNaN;
            out.push_back(std::move(row));
        }
    return out;
}

std::vector<std::string> sortedGroups(const std::set<std::string>& groups,
                                      const std::vector<std::string>& order) {
    std::vector<std::string> out;
    for (const auto& g : order)
        if (groups.count(g) && std::find(out.begin(), out.end(), g) == out.end()) out.push_back(g);
    for (const auto& g : groups)
        if (std::find(out.begin(), out.end(), g) == out.end()) out.push_back(g);
    return out;
}

} // namespace

AnalysisReport analyzeTrials(std::span<const TrialRecord> trials, const AnalysisOptions& options) {
    AnalysisReport report;
    {
        // Who the report covers, and how many of them are simulated (its banner says so).
        std::set<std::string> everyone, simulated;
        for (const auto& t : trials) {
            everyone.insert(t.participant);
            if (t.simulated) simulated.insert(t.participant);
        }
        report.participants = static_cast<int>(everyone.size());
        report.simulatedParticipants = static_cast<int>(simulated.size());
    }
    std::set<std::string> groupSet;
    std::size_t entered = 0, practice = 0, excluded = 0, unanswered = 0;
    std::set<std::string> participants;
    std::map<std::pair<std::string, StimulusKey>, Cell> cells;
    for (const auto& t : trials) {
        if (t.practice) {
            ++practice;
            continue;
        }
        if (t.excluded) {
            ++excluded;
            continue;
        }
        if (t.answerId.empty()) {
            ++unanswered;
            continue;
        }
        ++entered;
        participants.insert(t.participant);
        const std::string group = options.byGroup ? t.group : std::string("all");
        groupSet.insert(group);
        const StimulusKey key{t.surfaceId,
                              options.split == SoundscapeSplit::BySoundscape ? t.soundscapeId : ""};
        Cell& c = cells[{group, key}];
        c.group = group;
        c.key = key;
        c.n += 1;
        if (rules::isCorrect(t)) c.correct += 1;
        if (rules::isDontKnow(t)) c.dontKnow += 1;
        if (rules::countsForRealism(t)) c.realism.push_back(t.realism);
        if (rules::countsForQuality(t)) c.quality.push_back(t.quality);
        if (const auto sc = rules::soundscapeCorrect(t)) {
            c.soundscapeN += 1;
            if (*sc) c.soundscapeCorrect += 1;
        }
        if (!std::isnan(t.realism) || !std::isnan(t.quality)) report.hasRatings = true;
    }
    report.groups = sortedGroups(groupSet, options.groupOrder);
    report.notes.push_back(
        fmt::format("{} of {} {} the tables; left out: {} practice, {} excluded, {} unanswered.",
                    counted(entered, "trial"), counted(participants.size(), "participant"),
                    entered == 1 ? "enters" : "enter", practice, excluded, unanswered));
    for (const auto& group : report.groups) {
        auto confusion = buildConfusion(trials, options.answers, options.split,
                                        options.byGroup ? group : std::string());
        confusion.group = group;
        report.categories.push_back(buildCategoryMatrix(confusion));
        report.confusions.push_back(std::move(confusion));
    }
    std::vector<Cell> list;
    for (auto& [key, cell] : cells) list.push_back(std::move(cell));
    sortCells(list, report.groups);
    for (const auto& c : list) report.summary.push_back(summarize(c, options.confLevel));
    if (options.byGroup && report.groups.size() >= 2)
        report.comparisons = compare(list, report.groups, report.hasRatings);
    return report;
}

AnalysisReport analyzeConfusions(std::vector<ConfusionMatrix> confusions,
                                 const AnalysisOptions& options) {
    AnalysisReport report;
    std::vector<Cell> list;
    for (auto& m : confusions) {
        report.groups.push_back(m.group);
        for (std::size_t i = 0; i < m.rows.size(); ++i) {
            Cell c;
            c.group = m.group;
            c.key = m.rows[i];
            if (options.split == SoundscapeSplit::Pooled) c.key.soundscapeId.clear();
            c.n = m.rowTotal(i);
            for (std::size_t j = 0; j < m.columns.options.size(); ++j) {
                const auto& id = m.columns.options[j].id;
                if (answerIsCorrect(id, m.rows[i].surfaceId)) c.correct += m.counts[i][j];
                if (id == kDontKnowId) c.dontKnow += m.counts[i][j];
            }
            if (!std::isnan(m.nominalRowTotal) && c.n != m.nominalRowTotal)
                report.notes.push_back(fmt::format(
                    "{}: row {}{} sums to {} answers, not the {} presentations of the design; "
                    "its percentages use the row's own total.",
                    m.group, labelFor(m.rows[i].surfaceId),
                    m.rows[i].soundscapeId.empty() ? std::string()
                                                   : " / " + labelFor(m.rows[i].soundscapeId),
                    c.n, m.nominalRowTotal));
            auto same = std::find_if(list.begin(), list.end(), [&](const Cell& o) {
                return o.group == c.group && o.key == c.key;
            });
            if (same != list.end()) {
                same->n += c.n;
                same->correct += c.correct;
                same->dontKnow += c.dontKnow;
            } else {
                list.push_back(std::move(c));
            }
        }
        report.categories.push_back(buildCategoryMatrix(m));
        report.confusions.push_back(std::move(m));
    }
    sortCells(list, report.groups);
    for (const auto& c : list) report.summary.push_back(summarize(c, options.confLevel));
    if (report.groups.size() >= 2) report.comparisons = compare(list, report.groups, false);
    return report;
}

} // namespace underfoot::analysis
