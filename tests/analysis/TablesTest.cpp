// SPDX-License-Identifier: GPL-3.0-or-later
// Tables from trial records under the scoring rules; reference values from R 4.2.2 as quoted.
#include "analysis/tables/Tables.h"
#include "analysis/stats/Tests.h"
#include "analysis/tables/ScoringRules.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace underfoot::analysis;

namespace {

TrialRecord trial(const std::string& participant, const std::string& group,
                  const std::string& surface, const std::string& soundscape,
                  const std::string& answer, double realism, double quality,
                  const std::string& soundscapeAnswer = {}) {
    TrialRecord t;
    t.participant = participant;
    t.group = group;
    t.surfaceId = surface;
    t.stimulusId = surface;
    t.soundscapeId = soundscape;
    t.answerId = answer;
    t.realism = realism;
    t.quality = quality;
    t.soundscapeAnswer = soundscapeAnswer;
    return t;
}

std::vector<TrialRecord> smallStudy() {
    std::vector<TrialRecord> v{
        trial("p1", "A", "gravel", "", "gravel", 5, 4),
        trial("p1", "A", "gravel", "", "gravel", 6, 5),
        trial("p2", "A", "gravel", "", "dont_know", NAN, 3),
        trial("p2", "A", "gravel", "", "dirt_pebbles", 2, 6),
        trial("p1", "A", "wood_reverb", "", "wood", 7, 6),
        trial("p2", "A", "wood_reverb", "", "wood_reverb", 4, 5),
        trial("p3", "B", "gravel", "farm_courtyard", "gravel", 5, 5, "farm_courtyard"),
        trial("p3", "B", "gravel", "farm_courtyard", "gravel", 6, 6, "Courtyard of a farm"),
        trial("p4", "B", "gravel", "farm_courtyard", "gravel", 7, 7, "forest"),
        trial("p4", "B", "gravel", "farm_courtyard", "gravel", 4, 4, ""),
    };
    auto practice = trial("p1", "A", "gravel", "", "metal", 1, 1);
    practice.practice = true;
    auto excluded = trial("p2", "A", "gravel", "", "metal", 1, 1);
    excluded.excluded = true;
    auto unanswered = trial("p2", "A", "metal", "", "", NAN, NAN);
    v.push_back(practice);
    v.push_back(excluded);
    v.push_back(unanswered);
    return v;
}

const SummaryRow& row(const AnalysisReport& r, const std::string& group,
                      const std::string& surface) {
    for (const auto& s : r.summary)
        if (s.group == group && s.stimulus.surfaceId == surface) return s;
    throw std::runtime_error("no summary row " + group + "/" + surface);
}

} // namespace

TEST(ScoringRules, ReverbStimulusIsAnsweredByItsBaseSurface) {
    // The answer first, then the stimulus's surface (base/AnswerRule.h).
    EXPECT_TRUE(answerIsCorrect("wood", "wood_reverb"));
    EXPECT_TRUE(answerIsCorrect("wood_reverb", "wood_reverb"));
    EXPECT_FALSE(answerIsCorrect("creaking_wood", "wood_reverb"));
    EXPECT_TRUE(answerIsCorrect("wood_reverb", "wood")); // compared by base surfaces
    EXPECT_FALSE(answerIsCorrect("wood", "dont_know"));
    EXPECT_EQ(surfaceCategory("metal_reverb"), SurfaceCategory::Solid);
    EXPECT_EQ(surfaceCategory("puddles"), SurfaceCategory::Liquid);
    EXPECT_EQ(surfaceCategory("high_grass"), SurfaceCategory::Aggregate);
}

TEST(ScoringRules, RecordedCorrectnessWinsOverTheDerivedOne) {
    auto t = trial("p", "g", "gravel", "", "gravel", 5, 5);
    EXPECT_TRUE(rules::isCorrect(t));
    t.recordedCorrect = false;
    EXPECT_FALSE(rules::isCorrect(t));
    EXPECT_FALSE(rules::countsForRealism(t));
}

TEST(Confusion, RowsFollowTheCatalogAndDontKnowStaysLast) {
    const auto trials = smallStudy();
    const auto m = buildConfusion(trials, defaultAnswerList(), SoundscapeSplit::BySoundscape, "A");
    ASSERT_EQ(m.rows.size(), 2u);
    EXPECT_EQ(m.rows[0].surfaceId, "gravel");
    EXPECT_EQ(m.rows[1].surfaceId, "wood_reverb");
    // 15 surfaces + the unlisted answer "wood_reverb" + don't know
    ASSERT_EQ(m.columns.options.size(), 17u);
    EXPECT_EQ(m.columns.options.back().id, "dont_know");
    EXPECT_EQ(m.columns.options[15].id, "wood_reverb");
    const auto gravel = *m.columns.indexOf("gravel");
    EXPECT_EQ(m.counts[0][gravel], 2);
    EXPECT_EQ(m.counts[0][*m.columns.indexOf("dont_know")], 1);
    EXPECT_EQ(m.counts[0][*m.columns.indexOf("metal")], 0); // practice and excluded left out
    EXPECT_EQ(m.rowTotal(0), 4);
    EXPECT_DOUBLE_EQ(m.rowPercent(0, gravel), 50.0);
}

TEST(Confusion, CategoryMatrixSumsAnswersByMaterialClass) {
    const auto trials = smallStudy();
    const auto m = buildConfusion(trials, defaultAnswerList(), SoundscapeSplit::Pooled);
    const auto c = buildCategoryMatrix(m);
    ASSERT_EQ(c.rows.size(), 2u);
    EXPECT_EQ(c.rows[0], SurfaceCategory::Solid);
    EXPECT_EQ(c.rows[1], SurfaceCategory::Aggregate);
    ASSERT_EQ(c.columns.size(), 4u); // no "other" column when every answer is in the catalog
    EXPECT_EQ(c.counts[0][0], 2);    // wood_reverb answered wood / wood_reverb: solid
    EXPECT_EQ(c.counts[1][1], 7);    // gravel answered gravel x6, dirt x1: aggregate
    EXPECT_EQ(c.counts[1][3], 1);    // one "I don't know"
    EXPECT_DOUBLE_EQ(c.rowPercent(1, 1), 87.5);
}

TEST(Summary, RealismUsesCorrectAnswersAndQualityExcludesDontKnow) {
    AnalysisOptions o;
    o.byGroup = true;
    const auto trials = smallStudy();
    const auto r = analyzeTrials(trials, o);
    const auto& a = row(r, "A", "gravel");
    EXPECT_EQ(a.n, 4);
    EXPECT_DOUBLE_EQ(a.correct.percent, 50);
    EXPECT_DOUBLE_EQ(a.wrong.percent, 25);
    EXPECT_DOUBLE_EQ(a.dontKnow.percent, 25);
    EXPECT_EQ(a.realism.n, 2); // 5 and 6: the wrong answer's realism 2 is not used
    EXPECT_DOUBLE_EQ(a.realism.mean, 5.5);
    EXPECT_EQ(a.quality.n, 3); // 4, 5, 6: the don't-know answer's quality 3 is not used
    EXPECT_DOUBLE_EQ(a.quality.mean, 5);
    EXPECT_EQ(a.soundscapeCorrect.n, 0);
    const auto& reverb = row(r, "A", "wood_reverb");
    EXPECT_DOUBLE_EQ(reverb.correct.percent, 100);
    EXPECT_NEAR(reverb.realism.sd, 2.12132034355964, 1e-12); // R: sd(c(7,4))
}

TEST(Summary, MeansCarrySdSeAndTIntervalsAndProportionsWilson) {
    AnalysisOptions o;
    o.byGroup = true;
    const auto trials = smallStudy();
    const auto r = analyzeTrials(trials, o);
    const auto& b = row(r, "B", "gravel");
    EXPECT_EQ(b.stimulus.soundscapeId, "farm_courtyard");
    // R: x <- c(5,6,7,4); mean, sd, sd/2, t.test(x)$conf.int
    EXPECT_DOUBLE_EQ(b.realism.mean, 5.5);
    EXPECT_NEAR(b.realism.sd, 1.29099444873581, 1e-12);
    EXPECT_NEAR(b.realism.se, 0.645497224367903, 1e-12);
    EXPECT_NEAR(b.realism.ci.lower, 3.44573974323948, 1e-10);
    EXPECT_NEAR(b.realism.ci.upper, 7.55426025676052, 1e-10);
    // soundscape named by id and by label count as correct; the empty answer is not counted
    EXPECT_EQ(b.soundscapeCorrect.n, 3);
    EXPECT_EQ(b.soundscapeCorrect.count, 2);
    // R: prop.test(2, 3, correct=FALSE)$conf.int * 100
    EXPECT_NEAR(b.soundscapeCorrect.wilson.lower, 20.7659600802048, 1e-10);
    EXPECT_NEAR(b.soundscapeCorrect.wilson.upper, 93.8508055279604, 1e-10);
    // R: prop.test(3, 4, correct=FALSE)$conf.int * 100
    const Interval w = wilsonInterval(3, 4);
    EXPECT_NEAR(100 * w.lower, 30.0641842582402, 1e-10);
    EXPECT_NEAR(100 * w.upper, 95.4412739190299, 1e-10);
    EXPECT_EQ(b.correct.wilson.upper, 100);
}

TEST(Summary, NotesCountWhatWasLeftOut) {
    const auto trials = smallStudy();
    const auto r = analyzeTrials(trials, AnalysisOptions{});
    ASSERT_FALSE(r.notes.empty());
    EXPECT_NE(r.notes[0].find("10 trials of 4 participants"), std::string::npos) << r.notes[0];
    EXPECT_NE(r.notes[0].find("1 practice, 1 excluded, 1 unanswered"), std::string::npos);
    EXPECT_EQ(r.groups, std::vector<std::string>{"all"});
    EXPECT_TRUE(r.comparisons.empty());
}

TEST(Comparisons, GroupsAreComparedPerSurfaceWithRDefaults) {
    AnalysisOptions o;
    o.byGroup = true;
    const auto trials = smallStudy();
    const auto r = analyzeTrials(trials, o);
    const ComparisonRow* correct = nullptr;
    const ComparisonRow* realism = nullptr;
    const ComparisonRow* quality = nullptr;
    for (const auto& c : r.comparisons) {
        if (c.surfaceId != "gravel") continue;
        if (c.measure == Measure::Correct) correct = &c;
        if (c.measure == Measure::Realism) realism = &c;
        if (c.measure == Measure::Quality) quality = &c;
    }
    ASSERT_TRUE(correct && realism && quality);
    // R: chisq.test(matrix(c(2,2,4,0),2,byrow=TRUE)) -> 0.666666666666667, p 0.414216178242525
    EXPECT_NEAR(correct->test.statistic, 0.666666666666667, 1e-12);
    EXPECT_NEAR(correct->test.p, 0.414216178242525, 1e-12);
    EXPECT_NEAR(correct->fisherP, 0.428571428571429, 1e-12); // R: fisher.test(same)$p.value
    // R: t.test(c(5,6), c(5,6,7,4)) -> t = 0, df = 3.69230769230769, p = 1
    EXPECT_NEAR(realism->test.df[0], 3.69230769230769, 1e-12);
    EXPECT_NEAR(realism->test.p, 1, 1e-12);
    // R: t.test(c(4,5,6), c(5,6,7,4)) -> t = -0.577350269189626, df 4.95918367346939
    EXPECT_NEAR(quality->test.statistic, -0.577350269189626, 1e-12);
    EXPECT_NEAR(quality->test.p, 0.588921549285826, 1e-10);
    EXPECT_EQ(quality->pHolm, quality->test.p); // one surface: Holm changes nothing
    // wood_reverb exists only in group A: no comparison for it
    for (const auto& c : r.comparisons) EXPECT_NE(c.surfaceId, "wood_reverb");
}

TEST(Comparisons, PublishedGravelTestIsReproducedFromTrialRecords) {
    // 20 presentations per group: audio 8 correct, audio-haptic 18 correct (Eurohaptics 2010)
    std::vector<TrialRecord> trials;
    for (int i = 0; i < 20; ++i) {
        trials.push_back(trial("a" + std::to_string(i / 2), "audio", "gravel", "",
                               i < 8 ? "gravel" : "dirt_pebbles", 5, 5));
        trials.push_back(trial("h" + std::to_string(i / 2), "audiohaptic", "gravel", "",
                               i < 18 ? "gravel" : "dont_know", 5, 5));
    }
    AnalysisOptions o;
    o.byGroup = true;
    const auto r = analyzeTrials(trials, o);
    ASSERT_FALSE(r.comparisons.empty());
    const auto& c = r.comparisons.front();
    EXPECT_EQ(c.measure, Measure::Correct);
    // R: chisq.test(matrix(c(8,12,18,2),2,byrow=TRUE)) -> X-squared = 8.9011, p = 0.00285
    EXPECT_NEAR(c.test.statistic, 8.9010989010989, 1e-12);
    EXPECT_NEAR(c.test.p, 0.00284999090249869, 1e-15);
    // constant ratings: R's t.test stops with "data are essentially constant"
    for (const auto& row : r.comparisons)
        if (row.measure == Measure::Realism) {
            EXPECT_EQ(row.test.error, "data are essentially constant");
        }
}

TEST(Summary, GroupOrderCanFollowTheProtocol) {
    AnalysisOptions o;
    o.byGroup = true;
    o.groupOrder = {"B", "A", "missing"};
    const auto trials = smallStudy();
    const auto r = analyzeTrials(trials, o);
    EXPECT_EQ(r.groups, (std::vector<std::string>{"B", "A"}));
    EXPECT_EQ(r.summary.front().group, "B");
    EXPECT_EQ(r.confusions.front().group, "B");
    ASSERT_FALSE(r.comparisons.empty());
    EXPECT_EQ(r.comparisons.front().groupA, "B");
}
