// SPDX-License-Identifier: GPL-3.0-or-later
// Reference values of the rating analysis. R is not installed here: each value comes from a
// textbook example whose published result is quoted (with the R call that reproduces it), or
// from a closed form worked out by hand in the comment.
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/RatingReport.h"
#include "analysis/stats/Tests.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace underfoot::analysis;

namespace {

/// A rating data set: participant p rated stimulus s value v on scale "x".
RatingData dataOf(const std::vector<std::tuple<std::string, std::string, double>>& rows,
                  const std::vector<std::string>& stimuli) {
    RatingData d;
    for (const auto& [p, s, v] : rows) d.ratings.push_back({p, s, {}, "x", v});
    d.stimulusOrder = stimuli;
    d.scales.push_back({"x", "X", 0, 10, ""});
    return d;
}

} // namespace

TEST(WadingRatingStats, QuantilesAreRType7) {
    // R: quantile(1:10, c(0.25, 0.5, 0.75)) -> 3.25 5.50 7.75 (h = 9p + 1, linear interpolation).
    std::vector<double> v{10, 9, 8, 7, 6, 5, 4, 3, 2, 1};
    EXPECT_DOUBLE_EQ(quantileType7(v, 0.25), 3.25);
    EXPECT_DOUBLE_EQ(quantileType7(v, 0.5), 5.5);
    EXPECT_DOUBLE_EQ(quantileType7(v, 0.75), 7.75);
    EXPECT_TRUE(std::isnan(quantileType7({}, 0.5)));
}

TEST(WadingRatingStats, BoxStatsSeparateOutliersFromExtremes) {
    // 1..9 plus 17 and 30: Q1 = 3.5, Q3 = 8.5 (type 7, n = 11: h = 3.5 and 8.5 -> 3.5, 8.5),
    // IQR 5; 1.5 IQR fences -4 and 16; 3 IQR limits -11.5 and 23.5. So 17 is an outlier
    // (circle), 30 an extreme (dot), and the upper whisker ends at 9.
    const BoxStats b = boxStats({1, 2, 3, 4, 5, 6, 7, 8, 9, 17, 30});
    EXPECT_DOUBLE_EQ(b.q1, 3.5);
    EXPECT_DOUBLE_EQ(b.q3, 8.5);
    EXPECT_DOUBLE_EQ(b.median, 6);
    EXPECT_DOUBLE_EQ(b.whiskerLow, 1);
    EXPECT_DOUBLE_EQ(b.whiskerHigh, 9);
    EXPECT_EQ(b.outliers, std::vector<double>{17});
    EXPECT_EQ(b.extremes, std::vector<double>{30});
}

TEST(WadingRatingStats, SignedRankZFollowsHollanderAndWolfe) {
    // Hollander & Wolfe (1973) p. 29, the example of R's ?wilcox.test (depression scale, first
    // and second visit). R: wilcox.test(x, y, paired = TRUE) gives V = 40 (exact p 0.03906).
    // Closed form of the normal approximation: n = 9, no ties, V- = 45 - 40 = 5,
    // sigma = sqrt(9 * 10 * 19 / 24) = sqrt(71.25) = 8.44097, Z = (5 - 22.5) / 8.44097
    // = -2.07322; p = 2 * pnorm(-2.07322) = erfc(2.07322 / sqrt(2)) = 0.038152, which is also
    // wilcox.test(x, y, paired = TRUE, exact = FALSE, correct = FALSE)$p.value.
    const std::vector<double> x{1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30};
    const std::vector<double> y{0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29};
    const SignedRankZ z = signedRankZ(x, y);
    EXPECT_EQ(z.n, 9u);
    EXPECT_DOUBLE_EQ(z.vPlus, 40);
    EXPECT_DOUBLE_EQ(z.vMinus, 5);
    EXPECT_NEAR(z.z, -17.5 / std::sqrt(71.25), 1e-12);
    EXPECT_NEAR(z.z, -2.07322, 5e-6);
    EXPECT_NEAR(z.p, std::erfc(17.5 / std::sqrt(71.25) / std::sqrt(2.0)), 1e-12);
    EXPECT_NEAR(z.p, 0.03815, 5e-6);
    WilcoxonOptions o;
    o.pairing = Pairing::Paired;
    o.exactness = Exactness::Approximate;
    o.continuity = Continuity::Uncorrected;
    EXPECT_NEAR(z.p, wilcoxonTest(x, y, o).p, 1e-14);
    EXPECT_NEAR(z.effectR, 2.07322 / 3.0, 5e-6);
}

TEST(WadingRatingStats, SignedRankZDropsZerosAndCorrectsTies) {
    // Differences (a - b): 0, 1, 1, -2, 3. The zero is dropped (n = 4); |d| = 1, 1, 2, 3 have
    // midranks 1.5, 1.5, 3, 4: V+ = 1.5 + 1.5 + 4 = 7, V- = 3. Tie correction: one pair of ties,
    // t^3 - t = 6, so sigma^2 = 4 * 5 * 9 / 24 - 6 / 48 = 7.5 - 0.125 = 7.375 and
    // Z = (3 - 5) / sqrt(7.375) = -0.736460.
    const SignedRankZ z = signedRankZ({5, 3, 4, 1, 6}, {5, 2, 3, 3, 3});
    EXPECT_EQ(z.n, 4u);
    EXPECT_DOUBLE_EQ(z.vPlus, 7);
    EXPECT_DOUBLE_EQ(z.vMinus, 3);
    EXPECT_NEAR(z.z, -2 / std::sqrt(7.375), 1e-12);
}

TEST(WadingRatingStats, FriedmanAndHolmOnAConsistentRanking) {
    // Four participants who all rate A < B < C: rank sums 4, 8, 12, so
    // X^2 = 12 / (n k (k + 1)) * sum R^2 - 3 n (k + 1) = 12 / 48 * 224 - 48 = 8 with df 2 and
    // p = exp(-8 / 2) = exp(-4) = 0.0183156 (chi-square with 2 df: survival exp(-x / 2)).
    // R: friedman.test(matrix(c(1,2,3, 2,3,4, 1,4,6, 0,5,9), 4, byrow = TRUE)).
    const auto d = dataOf({{"p1", "A", 1},
                           {"p1", "B", 2},
                           {"p1", "C", 3},
                           {"p2", "A", 2},
                           {"p2", "B", 3},
                           {"p2", "C", 4},
                           {"p3", "A", 1},
                           {"p3", "B", 4},
                           {"p3", "C", 6},
                           {"p4", "A", 0},
                           {"p4", "B", 5},
                           {"p4", "C", 9}},
                          {"A", "B", "C"});
    const auto a = analyzeRatingStudy(d);
    ASSERT_EQ(a.scales.size(), 1u);
    const auto& s = a.scales[0];
    EXPECT_DOUBLE_EQ(s.omnibus.result.statistic, 8.0);
    EXPECT_NEAR(s.omnibus.result.p, std::exp(-4.0), 1e-12);
    // Without factors every pair is compared: A-B, A-C, B-C, all differences negative, n = 4,
    // no ties among |d| for A-C (2, 2, 5, 9 -> tie!) ... so check the Holm step directly:
    ASSERT_EQ(s.planned.size(), 3u);
    std::vector<double> raw;
    for (const auto& c : s.planned) raw.push_back(c.test.p);
    const auto holm = pAdjust(raw, PAdjustMethod::Holm);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(s.planned[i].pHolm, holm[i]);
    // p.adjust(c(0.01, 0.02, 0.03), "holm") = 0.03 0.04 0.04 (3p, 2p, p with running maximum).
    EXPECT_EQ(pAdjust(std::vector<double>{0.01, 0.02, 0.03}, PAdjustMethod::Holm),
              (std::vector<double>{0.03, 0.04, 0.04}));
    // Medians per cell: A 1, B 3.5, C 5.
    EXPECT_DOUBLE_EQ(s.cells[0].box.median, 1.0);
    EXPECT_DOUBLE_EQ(s.cells[1].box.median, 3.5);
    EXPECT_DOUBLE_EQ(s.cells[2].box.median, 5.0);
}

TEST(WadingRatingStats, KruskalWallisAcrossParticipantGroups) {
    // Hollander & Wolfe (1973) p. 116, the example of R's ?kruskal.test (mucociliary efficiency):
    // kruskal.test(list(c(2.9, 3.0, 2.5, 2.6, 3.2), c(3.8, 2.7, 4.0, 2.4),
    //                   c(2.8, 3.4, 3.7, 2.2, 2.0)))
    // -> Kruskal-Wallis chi-squared = 0.77143, df = 2, p-value = 0.68.
    // Here each value is one participant's single rating, grouped by a participant field.
    const std::vector<std::vector<double>> groups{
        {2.9, 3.0, 2.5, 2.6, 3.2}, {3.8, 2.7, 4.0, 2.4}, {2.8, 3.4, 3.7, 2.2, 2.0}};
    RatingData d;
    d.scales.push_back({"x", "X", 0, 5, ""});
    d.stimulusOrder = {"A"};
    d.groupingFields = {"device"};
    int n = 0;
    for (std::size_t g = 0; g < groups.size(); ++g)
        for (double v : groups[g]) {
            const std::string p = "p" + std::to_string(n++);
            d.ratings.push_back({p, "A", {}, "x", v});
            d.participantFields[p]["device"] = "g" + std::to_string(g + 1);
        }
    const auto a = analyzeRatingStudy(d);
    ASSERT_EQ(a.scales[0].groups.size(), 1u);
    const auto& kw = a.scales[0].groups[0].kruskal;
    EXPECT_NEAR(kw.statistic, 0.77143, 5e-6);
    EXPECT_EQ(kw.df, std::vector<double>{2});
    EXPECT_NEAR(kw.p, 0.68, 5e-3);
    EXPECT_TRUE(a.scales[0].groups[0].pairs.empty()) << "no post-hoc tests after p = 0.68";
    EXPECT_EQ(a.scales[0].groups[0].groups[1].n, 4u);
}

TEST(WadingRatingStats, SpearmanBetweenScalesPairsTheSameCells) {
    // x = 1..5, y = 2, 1, 4, 3, 5: sum d^2 = 4, rho = 1 - 6 * 4 / (5 * 24) = 0.8. Exact p (n <= 9,
    // as R's cor.test(x, y, method = "spearman")): permutations of 5 with sum d^2 <= 4 are the
    // identity, 4 adjacent swaps and 3 pairs of disjoint adjacent swaps = 8 of 120, so
    // P(S <= 4) = 1/15 and the two-sided p = 2/15 = 0.13333.
    RatingData d;
    d.scales = {{"x", "X", 0, 10, ""}, {"y", "Y", 0, 10, ""}};
    const std::vector<double> x{1, 2, 3, 4, 5}, y{2, 1, 4, 3, 5};
    for (int i = 0; i < 5; ++i) {
        const std::string stim = "s" + std::to_string(i);
        d.stimulusOrder.push_back(stim);
        d.ratings.push_back({"p1", stim, {}, "x", x[static_cast<std::size_t>(i)]});
        d.ratings.push_back({"p1", stim, {}, "y", y[static_cast<std::size_t>(i)]});
    }
    const auto a = analyzeRatingStudy(d);
    ASSERT_EQ(a.correlations.size(), 1u);
    EXPECT_EQ(a.correlations[0].n, 5u);
    ASSERT_FALSE(a.correlations[0].test.estimate.empty());
    EXPECT_NEAR(a.correlations[0].test.estimate[0].value, 0.8, 1e-12);
    EXPECT_NEAR(a.correlations[0].test.p, 2.0 / 15.0, 1e-9);
}

TEST(WadingRatingStats, FactorialPlannedComparisonsAreSimpleEffects) {
    // A 2 x 2 design: cells differing in one factor only are compared (4 pairs, not 6).
    RatingData d;
    d.scales.push_back({"x", "X", 0, 10, ""});
    d.factorOrder = {"depth", "speed"};
    d.levelOrder = {{"depth", {"shallow", "deep"}}, {"speed", {"slow", "fast"}}};
    for (const auto& depth : {"shallow", "deep"})
        for (const auto& speed : {"slow", "fast"}) {
            const std::string stim = std::string(depth) + "_" + speed;
            d.stimulusOrder.push_back(stim);
            for (int p = 0; p < 6; ++p)
                d.ratings.push_back({"p" + std::to_string(p),
                                     stim,
                                     {{"depth", depth}, {"speed", speed}},
                                     "x",
                                     (std::string(depth) == "deep" ? 6.0 : 3.0) + p % 3});
        }
    const auto a = analyzeRatingStudy(d);
    const auto& s = a.scales[0];
    ASSERT_EQ(s.planned.size(), 4u);
    EXPECT_EQ(s.planned[0].context, "speed at depth=shallow");
    EXPECT_EQ(s.planned[1].context, "depth at speed=slow");
    // shallow_slow vs shallow_fast: all differences 0 -> no test (n = 0, p NaN).
    EXPECT_EQ(s.planned[0].test.n, 0u);
    EXPECT_TRUE(std::isnan(s.planned[0].test.p));
    // Main effect of depth: two levels -> a Wilcoxon test, every difference -3: V = 0, n = 6.
    ASSERT_EQ(s.factorEffects.size(), 2u);
    EXPECT_EQ(s.factorEffects[0].omnibus.result.statisticName, "V");
    EXPECT_DOUBLE_EQ(s.factorEffects[0].pairs[0].test.vPlus, 0.0);
    // All |d| tied (6 ties): sigma^2 = 6*7*13/24 - (216-6)/48 = 22.75 - 4.375 = 18.375;
    // Z = (0 - 10.5) / sqrt(18.375) = -2.44949.
    EXPECT_NEAR(s.factorEffects[0].pairs[0].test.z, -10.5 / std::sqrt(18.375), 1e-12);
    EXPECT_STREQ(significanceStars(0.0004), "***");
    EXPECT_STREQ(significanceStars(0.03), "*");
    EXPECT_STREQ(significanceStars(0.2), "");
}

TEST(WadingRatingStats, RatingCsvErrorsNameTheLine) {
    const std::string header =
        "study,participant,group,trial_index,stimulus_id,practice,excluded,depth,scale,value\n";
    try {
        parseRatingData(header + "S,P1,,0,a,0,0,deep,x,4\nS,P1,,1,b,0,0,deep,x,four\n", "r.csv");
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "r.csv:3: value is 'four'; expected a finite number");
    }
    try {
        parseRatingData("participant,stimulus_id,scale,value\n", "r.csv");
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "r.csv:1: missing column 'practice'");
    }
    // Practice and excluded rows are left out; levels of numeric factors sort numerically.
    const auto d = parseRatingData(
        "study,participant,group,trial_index,stimulus_id,practice,excluded,cadence,scale,value\n"
        "S,P1,,0,p,1,0,110,x,4\nS,P1,,1,a,0,0,118,x,5\nS,P1,,2,b,0,1,27,x,6\n"
        "S,P1,,3,c,0,0,27,x,7\n",
        "r.csv");
    EXPECT_EQ(d.ratings.size(), 2u);
    EXPECT_EQ(d.levelOrder.at("cadence"), (std::vector<std::string>{"27", "118"}));
    EXPECT_THROW(analyzeRatingStudy(RatingData{}), std::invalid_argument);
}
