// SPDX-License-Identifier: GPL-3.0-or-later
// Each of the paper's three studies runs end to end with simulated participants (create the
// study, register, run every trial through the session, rate, export, analyse), the analysis has
// the paper's form, and the same seed gives the same study and the same report.
#include "StudySupport.h"
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/RatingReport.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

using namespace underfoot;
using namespace underfoot::wading::test;

namespace {

const analysis::ScaleAnalysis& scale(const analysis::RatingStudyAnalysis& a,
                                     const std::string& id) {
    for (const auto& s : a.scales)
        if (s.scale.id == id) return s;
    throw std::runtime_error("no scale " + id);
}

const analysis::FactorEffect& effect(const analysis::ScaleAnalysis& s, const std::string& factor) {
    for (const auto& f : s.factorEffects)
        if (f.factor == factor) return f;
    throw std::runtime_error("no factor " + factor);
}

std::string ratingsCsv(const experiment::StudyStore& store) {
    std::ostringstream out;
    experiment::writeRatingsCsv(store, out);
    return out.str();
}

} // namespace

TEST(WadingStudiesEndToEnd, ListeningTestOfSixteenParticipantsInThePapersForm) {
    auto store = simulatedStudy("wading_listening.toml", "wading_listening_ratings.toml", 16, 7,
                                scratchFile("s1.db"));
    for (const auto& p : store.participants())
        EXPECT_EQ(p.status, experiment::ParticipantStatus::Completed);
    const auto data = exportedRatings(store);
    EXPECT_EQ(data.ratings.size(), 16u * 24u);
    const auto a = analysis::analyzeRatingStudy(data);
    EXPECT_EQ(a.participants, 16u);
    ASSERT_EQ(a.scales.size(), 4u);
    for (const auto& s : a.scales) {
        ASSERT_EQ(s.cells.size(), 6u) << s.scale.id;
        EXPECT_EQ(s.scale.max, 10.0);
        // Friedman across the six cells: df 5, every participant rated every cell.
        EXPECT_EQ(s.omnibus.result.statisticName, "Friedman chi-squared");
        EXPECT_EQ(s.omnibus.result.df, std::vector<double>{5});
        EXPECT_EQ(s.omnibus.participants, 16u);
        // Planned comparisons: depth at each of 3 cadences + 3 cadence pairs at each depth.
        ASSERT_EQ(s.planned.size(), 9u);
        for (const auto& c : s.planned) {
            EXPECT_GE(c.pHolm, c.test.p - 1e-15);
            EXPECT_LE(c.test.z, 0.0) << "SPSS-style Z is never positive";
        }
        EXPECT_EQ(s.factorEffects.size(), 2u);
        for (const auto& cell : s.cells) EXPECT_EQ(cell.box.n, 16u);
    }
    // The simulated effects are found: deep is rated deeper at every cadence (model: +4 points).
    for (const auto& c : scale(a, "depth").planned)
        if (c.context.rfind("depth at", 0) == 0) {
            EXPECT_LT(c.pHolm, 0.05) << c.first << " vs " << c.second;
            const bool deepFirst = c.first.find("deep") != std::string::npos;
            EXPECT_GT(deepFirst ? c.medianFirst : c.medianSecond,
                      deepFirst ? c.medianSecond : c.medianFirst);
        }
    EXPECT_LT(effect(scale(a, "speed"), "cadence").omnibus.result.p, 0.05);
    // Spearman correlations between the four scales: 6 pairs over 16 x 6 cells each.
    ASSERT_EQ(a.correlations.size(), 6u);
    for (const auto& c : a.correlations) EXPECT_EQ(c.n, 96u);
    // The report: per scale a figure of means with 95 % CIs and a box plot (six boxes each) in
    // HTML and Markdown.
    const std::string html = analysis::renderRatingReport(a, analysis::ReportFormat::Html);
    EXPECT_EQ(std::count(html.begin(), html.end(), '\n') > 0, true);
    std::size_t svgs = 0, boxes = 0;
    for (std::size_t at = 0; (at = html.find("<svg", at)) != std::string::npos; ++at) ++svgs;
    for (std::size_t at = 0; (at = html.find("<rect", at)) != std::string::npos; ++at) ++boxes;
    EXPECT_EQ(svgs, 8u);
    EXPECT_EQ(boxes, 24u);
    const std::string md = analysis::renderRatingReport(a, analysis::ReportFormat::Markdown);
    EXPECT_NE(md.find("## Scale naturalness (0 to 10)"), std::string::npos);
    EXPECT_NE(md.find("| depth at cadence=80 |"), std::string::npos);
    const std::string csv = analysis::renderRatingReport(a, analysis::ReportFormat::Csv);
    EXPECT_EQ(csv.substr(0, analysis::kRatingTidyCsvHeader.size()), analysis::kRatingTidyCsvHeader);
}

TEST(WadingStudiesEndToEnd, InteractiveTestComparesTwoOrThreeConditionsPerItem) {
    auto store = simulatedStudy("wading_interactive.toml", "wading_interactive_ratings.toml", 12, 3,
                                scratchFile("s2.db"));
    // Balanced over the six Latin-square orders: two participants each.
    for (const auto& g : store.groupCounts()) EXPECT_EQ(g.completed, 2) << g.groupId;
    for (const auto& p : store.participants())
        for (const auto& t : store.trials(p.code)) EXPECT_EQ(t.lapsDone, 6);
    const auto a = analysis::analyzeRatingStudy(exportedRatings(store));
    ASSERT_EQ(a.scales.size(), 7u);
    // Items asked in S5.0 and S0.8 only: one Wilcoxon test; all three conditions: Friedman df 2.
    EXPECT_EQ(scale(a, "agency").cells.size(), 2u);
    EXPECT_EQ(scale(a, "agency").omnibus.result.statisticName, "V");
    EXPECT_EQ(scale(a, "agency").planned.size(), 1u);
    EXPECT_EQ(scale(a, "comfort").cells.size(), 3u);
    EXPECT_EQ(scale(a, "comfort").omnibus.result.df, std::vector<double>{2});
    EXPECT_EQ(scale(a, "comfort").planned.size(), 3u);
    // Spearman on the long-form items: pairs of items share 24 (2 conditions) or 36 cells.
    ASSERT_EQ(a.correlations.size(), 21u);
    for (const auto& c : a.correlations) EXPECT_TRUE(c.n == 24u || c.n == 36u) << c.n;
}

TEST(WadingStudiesEndToEnd, RealismTestWithGroupsOfExpertiseAndDevice) {
    const auto started = std::chrono::steady_clock::now();
    auto store = simulatedStudy("wading_realism.toml", "wading_realism_ratings.toml", 55, 21,
                                scratchFile("s3.db"));
    const auto data = exportedRatings(store);
    const auto a = analysis::analyzeRatingStudy(data);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    RecordProperty("simulate_and_analyse_55_s", std::to_string(seconds));
    const auto& r = scale(a, "realism");
    ASSERT_EQ(r.cells.size(), 9u);
    EXPECT_EQ(r.omnibus.result.df, std::vector<double>{8});
    // Each clip rated twice: a cell value is the mean of two ratings (multiples of 0.5).
    for (const auto& c : r.cells)
        for (const auto& [p, v] : c.values) EXPECT_DOUBLE_EQ(v * 2, std::round(v * 2));
    // Planned: sound types within each cadence (3 x 3) and cadences within each sound (3 x 3).
    EXPECT_EQ(r.planned.size(), 18u);
    const auto& sound = effect(r, "algorithm");
    EXPECT_EQ(sound.levels.size(), 3u);
    EXPECT_LT(sound.omnibus.result.p, 0.001);
    EXPECT_EQ(sound.pairs.size(), 3u);
    // Between participants: a Kruskal-Wallis test per grouping field (4 levels each, df 3).
    ASSERT_EQ(r.groups.size(), 3u);
    std::size_t grouped = 0;
    for (const auto& g : r.groups) {
        EXPECT_EQ(g.kruskal.df, std::vector<double>{static_cast<double>(g.groups.size()) - 1});
        for (const auto& level : g.groups) grouped += level.n;
    }
    EXPECT_EQ(grouped, 3u * 55u);
    EXPECT_TRUE(a.correlations.empty()) << "one scale: nothing to correlate";
}

TEST(WadingStudiesEndToEnd, SameSeedSameStudyAndReportDifferentSeedDifferentRatings) {
    auto one = simulatedStudy("wading_realism.toml", "wading_realism_ratings.toml", 6, 99,
                              scratchFile("d1.db"));
    auto two = simulatedStudy("wading_realism.toml", "wading_realism_ratings.toml", 6, 99,
                              scratchFile("d2.db"));
    auto other = simulatedStudy("wading_realism.toml", "wading_realism_ratings.toml", 6, 100,
                                scratchFile("d3.db"));
    EXPECT_EQ(ratingsCsv(one), ratingsCsv(two));
    EXPECT_NE(ratingsCsv(one), ratingsCsv(other));
    for (const auto& p : one.participants()) {
        const auto a = one.trials(p.code), b = two.trials(p.code);
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_EQ(a[i].replays, b[i].replays);
            EXPECT_EQ(a[i].renderSeed, b[i].renderSeed);
        }
        EXPECT_EQ(p.fields, two.participant(p.code).fields);
    }
    const auto reportOne = analysis::renderRatingReport(
        analysis::analyzeRatingStudy(exportedRatings(one)), analysis::ReportFormat::Markdown);
    const auto reportTwo = analysis::renderRatingReport(
        analysis::analyzeRatingStudy(exportedRatings(two)), analysis::ReportFormat::Markdown);
    EXPECT_EQ(reportOne, reportTwo);
}
