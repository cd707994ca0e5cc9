// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot analyze` with the mixed models beside the between-group comparisons:
// the rows are the models of MixedModels.h (checked against R in MixedModelsTest.cpp) fitted on
// the trials the tables use, and every export format carries them with the advice sentence.
#include "analysis/report/MixedModelReport.h"
#include "analysis/report/Export.h"
#include "analysis/stats/MixedModels.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace underfoot::analysis;

namespace {

/// Two groups of 8 participants, 3 surfaces x 2 repetitions; participants differ in skill.
std::vector<TrialRecord> trials() {
    const std::vector<std::string> surfaces{"gravel", "wood", "beach_sand"};
    std::vector<TrialRecord> out;
    unsigned state = 12345;
    auto next = [&] { // small LCG, deterministic
        state = state * 1103515245u + 12345u;
        return static_cast<double>((state >> 8) & 0xFFFF) / 65536.0;
    };
    for (int g = 0; g < 2; ++g)
        for (int p = 0; p < 8; ++p) {
            const double skill = (p % 4) * 0.15 - 0.2 + (g == 1 ? 0.15 : 0.0);
            for (const auto& s : surfaces)
                for (int rep = 1; rep <= 2; ++rep) {
                    TrialRecord t;
                    t.participant = fmt::format("{}{:02d}", g == 0 ? "A" : "B", p);
                    t.group = g == 0 ? "none" : "coherent";
                    t.surfaceId = s;
                    t.stimulusId = s;
                    t.repetition = rep;
                    const bool correct = next() < 0.6 + skill;
                    t.answerId = correct ? s : (s == "wood" ? "gravel" : "wood");
                    t.realism = std::round(3 + 3 * next() + (correct ? 1 : 0));
                    t.quality = std::round(2 + 4 * next());
                    out.push_back(t);
                }
        }
    return out;
}

AnalysisReport analysed(const std::vector<TrialRecord>& ts, AnalysisOptions& o) {
    o.byGroup = true;
    o.groupOrder = {"none", "coherent"};
    auto report = analyzeTrials(ts, o);
    addMixedModelComparisons(report, ts, o);
    return report;
}

} // namespace

TEST(MixedModelReport, OneModelBesideEveryComparisonPlusThePooledOne) {
    const auto ts = trials();
    AnalysisOptions o;
    const auto report = analysed(ts, o);
    ASSERT_FALSE(report.mixedModels.empty());
    std::size_t perSurface = 0, pooled = 0, ordinal = 0;
    for (const auto& m : report.mixedModels) {
        if (m.model.rfind("clmm", 0) == 0) { // beside each lmer row of a rating
            ++ordinal;
            EXPECT_NE(m.measure, Measure::Correct);
            EXPECT_FALSE(std::isnan(m.nonparametricP)); // the Mann-Whitney p beside it
        }
        EXPECT_TRUE(m.error.empty()) << m.error;
        EXPECT_EQ(m.groupA, "none");
        EXPECT_EQ(m.groupB, "coherent");
        if (m.surfaceId.empty())
            ++pooled;
        else {
            ++perSurface;
            EXPECT_FALSE(std::isnan(m.classicP)); // the chi-square / t p beside it
        }
        EXPECT_FALSE(std::isnan(m.lrtP));
    }
    std::size_t classic = 0, ratings = 0;
    for (const auto& c : report.comparisons) {
        if (c.measure != Measure::DontKnow) ++classic;
        if (c.measure == Measure::Realism || c.measure == Measure::Quality) ++ratings;
    }
    // one glmer row per identification comparison, an lmer and a clmm row per rating one
    EXPECT_EQ(perSurface, classic + ratings);
    EXPECT_EQ(pooled, 5u); // correct; realism and quality by lmer and clmm, over all surfaces
    EXPECT_EQ(ordinal, ratings + 2);
    EXPECT_NE(report.mixedModelAdvice.find("cite the cumulative link mixed model"),
              std::string::npos);
    EXPECT_NE(report.mixedModelAdvice.find("Which test to cite: the mixed models"),
              std::string::npos);
    EXPECT_NE(report.mixedModelAdvice.find("up to 2 answers per surface"), std::string::npos);
}

TEST(MixedModelReport, PooledCorrectRowIsTheGlmerFitOfTheSameTrials) {
    const auto ts = trials();
    AnalysisOptions o;
    const auto report = analysed(ts, o);
    MixedModelData d;
    d.conditionLevels = {"none", "coherent"};
    for (const auto& t : ts) {
        d.y.push_back(t.answerId == t.surfaceId ? 1 : 0);
        d.condition.push_back(t.group);
        d.participant.push_back(t.participant);
        d.surface.push_back(t.surfaceId);
    }
    const auto direct = fitLogisticMixedModel(d, 1);
    ASSERT_TRUE(direct.ok());
    const auto* c = direct.coefficient("conditioncoherent");
    ASSERT_NE(c, nullptr);
    bool found = false;
    for (const auto& m : report.mixedModels)
        if (m.measure == Measure::Correct && m.surfaceId.empty()) {
            found = true;
            EXPECT_DOUBLE_EQ(m.estimate, c->estimate);
            EXPECT_DOUBLE_EQ(m.lrtP, direct.lrt.p);
            EXPECT_EQ(m.observations, 96);
            EXPECT_EQ(m.participants, 16);
        }
    EXPECT_TRUE(found);
}

TEST(MixedModelReport, EveryExportCarriesTheModelsAndTheAdvice) {
    const auto ts = trials();
    AnalysisOptions o;
    const auto report = analysed(ts, o);
    const std::string md = renderReport(report, ReportFormat::Markdown);
    EXPECT_NE(md.find("Mixed models beside the comparisons"), std::string::npos);
    EXPECT_NE(md.find("Which test to cite"), std::string::npos);
    const std::string html = renderReport(report, ReportFormat::Html);
    EXPECT_NE(html.find("<h2>Mixed models</h2>"), std::string::npos);
    EXPECT_NE(html.find("Which test to cite"), std::string::npos);
    const std::string tex = renderReport(report, ReportFormat::Latex);
    EXPECT_NE(tex.find("Mixed models beside the comparisons"), std::string::npos);
    EXPECT_NE(tex.find("\\paragraph{Which test to cite.}"), std::string::npos);
    const std::string csv = renderReport(report, ReportFormat::Csv);
    EXPECT_NE(csv.find("mixed_model,none vs coherent,all,,correct,lrt_p,"), std::string::npos);
    EXPECT_NE(csv.find("mixed_model_advice"), std::string::npos);
}

TEST(MixedModelReport, NothingWithoutGroups) {
    const auto ts = trials();
    AnalysisOptions o; // byGroup false
    auto report = analyzeTrials(ts, o);
    addMixedModelComparisons(report, ts, o);
    EXPECT_TRUE(report.mixedModels.empty());
    EXPECT_TRUE(report.mixedModelAdvice.empty());
}
