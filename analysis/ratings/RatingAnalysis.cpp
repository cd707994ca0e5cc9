// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/ratings/RatingAnalysis.h"

#include "analysis/ratings/RatingModels.h"

#include "analysis/stats/Numerics.h"
#include "analysis/stats/Tests.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace underfoot::analysis {

using numerics::kNaN;

double quantileType7(std::vector<double> values, double probability) {
    if (values.empty() || !(probability >= 0 && probability <= 1)) return kNaN;
    std::sort(values.begin(), values.end());
    const double h = (static_cast<double>(values.size()) - 1) * probability;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const auto hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (h - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

BoxStats boxStats(const std::vector<double>& values) {
    BoxStats b;
    b.n = values.size();
    if (values.empty()) return b;
    b.median = quantileType7(values, 0.5);
    b.q1 = quantileType7(values, 0.25);
    b.q3 = quantileType7(values, 0.75);
    const double iqr = b.q3 - b.q1;
    const double lowFence = b.q1 - 1.5 * iqr, highFence = b.q3 + 1.5 * iqr;
    b.whiskerLow = b.q1;
    b.whiskerHigh = b.q3;
    bool anyLow = false, anyHigh = false;
    for (double v : values) {
        if (v >= lowFence && v <= b.q1 && (!anyLow || v < b.whiskerLow)) {
            b.whiskerLow = v;
            anyLow = true;
        }
        if (v <= highFence && v >= b.q3 && (!anyHigh || v > b.whiskerHigh)) {
            b.whiskerHigh = v;
            anyHigh = true;
        }
        if (v < lowFence || v > highFence) {
            const bool extreme = v < b.q1 - 3 * iqr || v > b.q3 + 3 * iqr;
            (extreme ? b.extremes : b.outliers).push_back(v);
        }
    }
    std::sort(b.outliers.begin(), b.outliers.end());
    std::sort(b.extremes.begin(), b.extremes.end());
    return b;
}

SignedRankZ signedRankZ(const std::vector<double>& a, const std::vector<double>& b) {
    SignedRankZ r;
    std::vector<double> d;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
        if (!std::isnan(a[i]) && !std::isnan(b[i]) && a[i] != b[i]) d.push_back(a[i] - b[i]);
    r.n = d.size();
    if (d.empty()) return r;
    std::vector<double> absD(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) absD[i] = std::fabs(d[i]);
    const auto ranks = numerics::averageRanks(absD);
    for (std::size_t i = 0; i < d.size(); ++i) (d[i] > 0 ? r.vPlus : r.vMinus) += ranks[i];
    const double n = static_cast<double>(d.size());
    const double sigma =
        std::sqrt(n * (n + 1) * (2 * n + 1) / 24 - numerics::tieCorrectionSum(ranks) / 48);
    if (sigma <= 0) return r;
    r.z = (std::min(r.vPlus, r.vMinus) - n * (n + 1) / 4) / sigma;
    r.p = std::min(1.0, 2 * numerics::pnorm(r.z));
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
        pairs += !std::isnan(a[i]) && !std::isnan(b[i]) ? 1 : 0;
    r.effectR = std::fabs(r.z) / std::sqrt(static_cast<double>(pairs));
    return r;
}

namespace {

double medianOf(std::vector<double> v) {
    return v.empty() ? kNaN : numerics::median(v);
}

/// Participants with a value in every one of `columns`, and their rows.
std::vector<std::vector<double>>
completeRows(const std::vector<std::map<std::string, double>>& columns,
             std::vector<std::string>* who = nullptr) {
    std::vector<std::vector<double>> rows;
    if (columns.empty()) return rows;
    for (const auto& [participant, first] : columns.front()) {
        std::vector<double> row{first};
        bool complete = true;
        for (std::size_t c = 1; c < columns.size() && complete; ++c) {
            const auto it = columns[c].find(participant);
            if (it == columns[c].end())
                complete = false;
            else
                row.push_back(it->second);
        }
        if (!complete) continue;
        rows.push_back(std::move(row));
        if (who) who->push_back(participant);
    }
    return rows;
}

PairedComparison compare(const std::string& first, const std::map<std::string, double>& a,
                         const std::string& second, const std::map<std::string, double>& b,
                         const std::string& context) {
    PairedComparison c;
    c.first = first;
    c.second = second;
    c.context = context;
    const auto rows = completeRows({a, b});
    std::vector<double> x, y;
    for (const auto& row : rows) {
        x.push_back(row[0]);
        y.push_back(row[1]);
    }
    c.pairs = rows.size();
    c.medianFirst = medianOf(x);
    c.medianSecond = medianOf(y);
    c.test = signedRankZ(x, y);
    return c;
}

void holm(std::vector<PairedComparison>& comparisons) {
    std::vector<double> p;
    for (const auto& c : comparisons) p.push_back(c.test.p);
    const auto adjusted = pAdjust(p, PAdjustMethod::Holm);
    for (std::size_t i = 0; i < comparisons.size(); ++i) comparisons[i].pHolm = adjusted[i];
}

OmnibusTest omnibus(const std::string& name, const std::vector<std::string>& conditions,
                    const std::vector<std::map<std::string, double>>& columns) {
    OmnibusTest t;
    t.name = name;
    t.conditions = conditions;
    const auto rows = completeRows(columns);
    t.participants = rows.size();
    if (conditions.size() < 3) {
        // Two conditions: the Wilcoxon signed-rank test is the test (as in the paper).
        std::vector<double> x, y;
        for (const auto& row : rows) {
            x.push_back(row[0]);
            y.push_back(row.size() > 1 ? row[1] : kNaN);
        }
        WilcoxonOptions o;
        o.pairing = Pairing::Paired;
        o.exactness = Exactness::Approximate;
        o.continuity = Continuity::Uncorrected;
        t.result = conditions.size() == 2
                       ? wilcoxonTest(x, y, o)
                       : failedTest("Friedman rank sum test", "fewer than two conditions");
        return t;
    }
    t.result = rows.empty() ? failedTest("Friedman rank sum test", "no participant rated every "
                                                                   "condition")
                            : friedmanTest(rows);
    return t;
}

std::string levelsText(const std::map<std::string, std::string>& factors,
                       const std::string& except) {
    std::string out;
    for (const auto& [f, l] : factors)
        if (f != except) out += fmt::format("{}{}={}", out.empty() ? "" : ", ", f, l);
    return out;
}

} // namespace

RatingStudyAnalysis analyzeRatingStudy(const RatingData& data,
                                       const RatingAnalysisOptions& options) {
    if (data.ratings.empty())
        throw std::invalid_argument("no ratings to analyse (practice and excluded trials are "
                                    "left out)");
    RatingStudyAnalysis out;
    out.title = data.title;
    out.options = options;
    std::set<std::string> everyone;
    for (const auto& o : data.ratings) everyone.insert(o.participant);
    out.participants = everyone.size();

    // scale -> stimulus -> participant -> (sum, count)
    std::map<std::string, std::map<std::string, std::map<std::string, std::pair<double, int>>>>
        sums;
    std::map<std::string, std::map<std::string, std::string>> stimulusFactors;
    for (const auto& o : data.ratings) {
        auto& cell = sums[o.scale][o.stimulus][o.participant];
        cell.first += o.value;
        cell.second += 1;
        stimulusFactors[o.stimulus] = o.factors;
    }
    std::vector<std::string> fields =
        options.groupingFields.empty() ? data.groupingFields : options.groupingFields;

    for (const auto& info : data.scales) {
        const auto scaleIt = sums.find(info.id);
        if (scaleIt == sums.end()) continue;
        ScaleAnalysis sa;
        sa.scale = info;
        std::set<std::string> raters;
        for (const auto& stimulus : data.stimulusOrder) {
            const auto it = scaleIt->second.find(stimulus);
            if (it == scaleIt->second.end()) continue;
            RatingCell cell;
            cell.stimulus = stimulus;
            cell.factors = stimulusFactors[stimulus];
            std::vector<double> values;
            for (const auto& [participant, sc] : it->second) {
                cell.values[participant] = sc.first / sc.second;
                values.push_back(cell.values[participant]);
                raters.insert(participant);
            }
            cell.box = boxStats(values);
            cell.shapiro = values.size() >= 3 ? shapiroTest(values)
                                              : failedTest("Shapiro-Wilk normality test",
                                                           "sample size must be between 3 and "
                                                           "5000");
            sa.cells.push_back(std::move(cell));
        }
        sa.participants = raters.size();
        {
            std::vector<std::vector<double>> groups;
            for (const auto& c : sa.cells) {
                std::vector<double> v;
                for (const auto& [p, x] : c.values) v.push_back(x);
                groups.push_back(std::move(v));
            }
            sa.levene = groups.size() >= 2 ? leveneTest(groups)
                                           : failedTest("Levene's test", "fewer than two cells");
        }
        std::vector<std::string> names;
        std::vector<std::map<std::string, double>> columns;
        for (const auto& c : sa.cells) {
            names.push_back(c.stimulus);
            columns.push_back(c.values);
        }
        sa.omnibus = omnibus("all cells", names, columns);

        // Planned comparisons: cells differing in exactly one factor (simple effects); without
        // factors every pair of cells.
        for (std::size_t i = 0; i < sa.cells.size(); ++i)
            for (std::size_t j = i + 1; j < sa.cells.size(); ++j) {
                const auto& a = sa.cells[i];
                const auto& b = sa.cells[j];
                std::vector<std::string> differing;
                bool comparable = a.factors.size() == b.factors.size();
                for (const auto& [f, l] : a.factors) {
                    const auto it = b.factors.find(f);
                    if (it == b.factors.end())
                        comparable = false;
                    else if (it->second != l)
                        differing.push_back(f);
                }
                std::string context;
                if (a.factors.empty() && b.factors.empty())
                    context = "cells";
                else if (!comparable || differing.size() != 1)
                    continue;
                else {
                    const std::string rest = levelsText(a.factors, differing.front());
                    context = rest.empty() ? differing.front()
                                           : fmt::format("{} at {}", differing.front(), rest);
                }
                sa.planned.push_back(compare(a.stimulus, a.values, b.stimulus, b.values, context));
            }
        holm(sa.planned);

        // Main effects: per participant, median over the other factors, per level.
        for (const auto& factor : data.factorOrder) {
            const auto levelsIt = data.levelOrder.find(factor);
            if (levelsIt == data.levelOrder.end()) continue;
            FactorEffect fe;
            fe.factor = factor;
            std::vector<std::map<std::string, double>> levelColumns;
            for (const auto& level : levelsIt->second) {
                std::map<std::string, std::vector<double>> perParticipant;
                for (const auto& c : sa.cells) {
                    const auto f = c.factors.find(factor);
                    if (f == c.factors.end() || f->second != level) continue;
                    for (const auto& [p, v] : c.values) perParticipant[p].push_back(v);
                }
                if (perParticipant.empty()) continue;
                std::map<std::string, double> column;
                std::vector<double> all;
                for (auto& [p, v] : perParticipant) {
                    column[p] = numerics::median(v);
                    all.push_back(column[p]);
                }
                fe.levels.push_back(level);
                fe.levelStats.push_back(boxStats(all));
                levelColumns.push_back(std::move(column));
            }
            if (fe.levels.size() < 2) continue;
            fe.omnibus = omnibus(factor, fe.levels, levelColumns);
            for (std::size_t i = 0; i < fe.levels.size(); ++i)
                for (std::size_t j = i + 1; j < fe.levels.size(); ++j)
                    fe.pairs.push_back(compare(fe.levels[i], levelColumns[i], fe.levels[j],
                                               levelColumns[j], factor));
            holm(fe.pairs);
            sa.factorEffects.push_back(std::move(fe));
        }

        // Between participants: median over the cells of this scale, grouped by each field.
        std::map<std::string, double> participantMedian;
        {
            std::map<std::string, std::vector<double>> all;
            for (const auto& c : sa.cells)
                for (const auto& [p, v] : c.values) all[p].push_back(v);
            for (auto& [p, v] : all) participantMedian[p] = numerics::median(v);
        }
        for (const auto& field : fields) {
            GroupComparison gc;
            gc.field = field;
            std::map<std::string, std::vector<double>> byLevel;
            std::vector<std::string> order;
            for (const auto& [p, m] : participantMedian) {
                const auto pf = data.participantFields.find(p);
                if (pf == data.participantFields.end()) continue;
                const auto v = pf->second.find(field);
                if (v == pf->second.end() || v->second.empty()) continue;
                if (!byLevel.count(v->second)) order.push_back(v->second);
                byLevel[v->second].push_back(m);
            }
            std::sort(order.begin(), order.end());
            std::vector<std::vector<double>> groups;
            for (const auto& level : order) {
                const auto& v = byLevel[level];
                gc.groups.push_back({level, v.size(), numerics::median(v), quantileType7(v, 0.25),
                                     quantileType7(v, 0.75)});
                groups.push_back(v);
            }
            if (groups.size() < 2) continue;
            gc.kruskal = kruskalTest(groups);
            if (gc.kruskal.ok() && gc.kruskal.p < options.alpha) {
                WilcoxonOptions o;
                o.exactness = Exactness::Approximate;
                o.continuity = Continuity::Uncorrected;
                std::vector<double> p;
                for (std::size_t i = 0; i < groups.size(); ++i)
                    for (std::size_t j = i + 1; j < groups.size(); ++j) {
                        gc.pairs.push_back(
                            {order[i], order[j], wilcoxonTest(groups[i], groups[j], o)});
                        p.push_back(gc.pairs.back().test.ok() ? gc.pairs.back().test.p : kNaN);
                    }
                const auto adjusted = pAdjust(p, PAdjustMethod::Holm);
                for (std::size_t i = 0; i < gc.pairs.size(); ++i) gc.pairs[i].pHolm = adjusted[i];
            }
            sa.groups.push_back(std::move(gc));
        }
        sa.models = fitScaleModels(data, info, sa.omnibus);
        out.scales.push_back(std::move(sa));
    }

    // Spearman correlations between scales, on (participant, stimulus) cell means.
    std::vector<double> pc;
    for (std::size_t i = 0; i < out.scales.size(); ++i)
        for (std::size_t j = i + 1; j < out.scales.size(); ++j) {
            ScaleCorrelation c;
            c.first = out.scales[i].scale.id;
            c.second = out.scales[j].scale.id;
            std::vector<double> x, y;
            for (const auto& ci : out.scales[i].cells)
                for (const auto& cj : out.scales[j].cells) {
                    if (ci.stimulus != cj.stimulus) continue;
                    for (const auto& [p, v] : ci.values) {
                        const auto it = cj.values.find(p);
                        if (it == cj.values.end()) continue;
                        x.push_back(v);
                        y.push_back(it->second);
                    }
                }
            c.n = x.size();
            if (c.n < 3) continue;
            c.test = spearmanTest(x, y);
            pc.push_back(c.test.ok() ? c.test.p : kNaN);
            out.correlations.push_back(std::move(c));
        }
    const auto adjusted = pAdjust(pc, PAdjustMethod::Holm);
    for (std::size_t i = 0; i < out.correlations.size(); ++i)
        out.correlations[i].pHolm = adjusted[i];
    return out;
}

} // namespace underfoot::analysis
