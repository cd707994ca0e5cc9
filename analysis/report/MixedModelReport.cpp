// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/MixedModelReport.h"

#include "analysis/stats/MixedModels.h"
#include "analysis/stats/OrdinalMixed.h"
#include "analysis/stats/Tests.h"
#include "analysis/tables/ScoringRules.h"
#include "base/Plural.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace underfoot::analysis {

namespace {

/// One trial as a mixed model sees it.
struct Obs {
    std::string participant, group, surface;
    bool correct = false;
    double realism = std::nan(""), quality = std::nan("");
};

double valueOf(const Obs& o, Measure m) {
    switch (m) {
    case Measure::Correct:
        return o.correct ? 1.0 : 0.0;
    case Measure::Realism:
        return o.realism;
    case Measure::Quality:
        return o.quality;
    case Measure::DontKnow:
        break;
    }
    return std::nan("");
}

/// The model of a row: glmer on correct answers; lmer or clmm on ratings.
enum class Model { Logistic, Linear, Ordinal };

MixedComparisonRow fitOne(const std::vector<Obs>& obs, Measure measure, const std::string& surface,
                          const std::string& ga, const std::string& gb, int nAGQ, Model kind) {
    MixedComparisonRow row;
    row.measure = measure;
    row.surfaceId = surface;
    row.groupA = ga;
    row.groupB = gb;
    MixedModelData d;
    d.conditionLevels = {ga, gb};
    std::set<std::string> people;
    std::vector<double> xa, xb; // for the Mann-Whitney test of the pooled ratings
    for (const auto& o : obs) {
        if (o.group != ga && o.group != gb) continue;
        if (!surface.empty() && o.surface != surface) continue;
        const double y = valueOf(o, measure);
        if (std::isnan(y)) continue;
        d.y.push_back(y);
        d.condition.push_back(o.group);
        d.participant.push_back(o.participant);
        (o.group == ga ? xa : xb).push_back(y);
        if (surface.empty()) d.surface.push_back(o.surface);
        people.insert(o.participant);
    }
    if (surface.empty()) {
        std::set<std::string> surfaces(d.surface.begin(), d.surface.end());
        if (surfaces.size() < 2) d.surface.clear(); // one surface: no surface factor
    }
    row.observations = static_cast<double>(d.y.size());
    row.participants = static_cast<double>(people.size());
    if (kind != Model::Logistic) {
        const auto mw = wilcoxonTest(xa, xb);
        if (mw.ok()) row.nonparametricP = mw.p;
    }
    OrdinalMixedResult ordinal;
    if (kind == Model::Ordinal) {
        for (double y : d.y)
            if (std::floor(y) != y) {
                ordinal.error =
                    fmt::format("rating {} is not a whole point: the clmm needs ordered "
                                "categories",
                                y);
                break;
            }
        if (ordinal.error.empty()) ordinal = fitOrdinalMixedModel(d);
    }
    const MixedModelResult r = kind == Model::Logistic ? fitLogisticMixedModel(d, nAGQ)
                               : kind == Model::Linear
                                   ? fitLinearMixedModel(d)
                                   : static_cast<const MixedModelResult&>(ordinal);
    row.model = kind == Model::Logistic
                    ? (nAGQ == 1 ? "glmer (Laplace)" : fmt::format("glmer (nAGQ = {})", nAGQ))
                : kind == Model::Linear ? "lmer (REML, Satterthwaite df)"
                                        : "clmm (Laplace, logit)";
    if (!r.ok()) {
        row.error = r.error;
        return row;
    }
    row.warnings = r.warnings;
    row.randomVariance = r.randomVariance;
    row.lrtStatistic = r.lrt.statistic;
    row.lrtP = r.lrt.p;
    if (const auto* c = r.coefficient("condition" + gb)) {
        row.estimate = c->estimate;
        row.se = c->se;
        row.statistic = c->statistic;
        row.df = c->df;
        row.p = c->p;
    }
    return row;
}

} // namespace

void addMixedModelComparisons(AnalysisReport& report, std::span<const TrialRecord> trials,
                              const AnalysisOptions& options, int nAGQ) {
    report.mixedModels.clear();
    report.mixedModelAdvice.clear();
    if (!options.byGroup || report.groups.size() < 2) return;
    std::vector<Obs> obs;
    std::map<std::string, std::map<std::string, int>> presentations; // participant -> surface
    for (const auto& t : trials) {
        if (t.practice || t.excluded || t.answerId.empty()) continue;
        Obs o;
        o.participant = t.participant;
        o.group = t.group;
        o.surface = t.surfaceId;
        o.correct = rules::isCorrect(t);
        if (rules::countsForRealism(t)) o.realism = t.realism;
        if (rules::countsForQuality(t)) o.quality = t.quality;
        presentations[t.participant][t.surfaceId] += 1;
        obs.push_back(std::move(o));
    }
    int repeated = 0;
    for (const auto& [p, perSurface] : presentations)
        for (const auto& [s, n] : perSurface) repeated = std::max(repeated, n);
    std::vector<std::string> surfaces;
    for (const auto& c : report.comparisons)
        if (!c.surfaceId.empty() &&
            std::find(surfaces.begin(), surfaces.end(), c.surfaceId) == surfaces.end())
            surfaces.push_back(c.surfaceId);
    const auto& g = report.groups;
    int disagreements = 0, compared = 0;
    for (std::size_t i = 0; i < g.size(); ++i)
        for (std::size_t j = i + 1; j < g.size(); ++j)
            for (Measure m : {Measure::Correct, Measure::Realism, Measure::Quality}) {
                if (m != Measure::Correct && !report.hasRatings) continue;
                std::vector<std::string> list{""};
                for (const auto& s : report.comparisons)
                    if (s.measure == m && s.groupA == g[i] && s.groupB == g[j] &&
                        !s.surfaceId.empty())
                        list.push_back(s.surfaceId);
                const std::vector<Model> models =
                    m == Measure::Correct ? std::vector<Model>{Model::Logistic}
                                          : std::vector<Model>{Model::Linear, Model::Ordinal};
                for (const auto& surface : list)
                    for (const Model kind : models) {
                        auto row = fitOne(obs, m, surface, g[i], g[j], nAGQ, kind);
                        for (const auto& c : report.comparisons)
                            if (c.measure == m && c.groupA == g[i] && c.groupB == g[j] &&
                                c.surfaceId == surface && c.test.ok())
                                row.classicP = c.test.p;
                        if (kind != Model::Linear && !std::isnan(row.classicP) &&
                            !std::isnan(row.lrtP)) {
                            ++compared;
                            if ((row.classicP < 0.05) != (row.lrtP < 0.05)) ++disagreements;
                        }
                        report.mixedModels.push_back(std::move(row));
                    }
            }
    report.mixedModelAdvice = fmt::format(
        "Which test to cite: the mixed models. Each participant gave up to {} per "
        "surface, and answers of one participant are not independent; the chi-square and t-tests "
        "pool them as if they were, which understates their p-values when participants differ, "
        "while the mixed models (participant as random intercept; lme4 glmer / lmerTest lmer, "
        "likelihood-ratio test of the group) account for it. The chi-square / t-tests are shown "
        "to compare with the reference papers{}.{}",
        counted(repeated, "answer"),
        compared > 0 ? fmt::format(" (here they disagree about p < 0.05 in {} of {})",
                                   disagreements, counted(compared, "comparison"))
                     : std::string(),
        report.hasRatings
            ? " For the ratings cite the cumulative link mixed model (clmm, ordinal::clmm): a "
              "rating scale is ordered categories, not equally spaced numbers, and the clmm "
              "models them as such, while lmer and the t-test assume equal steps and normal "
              "errors; the Mann-Whitney test (wilcox.test) is the nonparametric check, and it "
              "too pools the answers of a participant."
            : "");
}

} // namespace underfoot::analysis
