// SPDX-License-Identifier: GPL-3.0-or-later
// Statistical tests against R 4.2.2 ("R version 4.2.2 Patched (2022-11-10 r83330)", Debian 12).
// Every reference value was printed by R with sprintf("%.15g", ...) from the call quoted next to
// it; the data vectors are defined identically here and in the R session.
#include "analysis/stats/Tests.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::analysis;

namespace {

void expectRel(double actual, double expected, double rel = 1e-9) {
    if (std::isinf(expected)) {
        EXPECT_EQ(actual, expected);
        return;
    }
    EXPECT_NEAR(actual, expected, std::fabs(expected) * rel + 1e-300)
        << "expected " << expected << " got " << actual;
}

void expectCi(const TestResult& r, double lower, double upper, double rel = 1e-9) {
    ASSERT_TRUE(r.confInt.has_value());
    expectRel(r.confInt->lower, lower, rel);
    expectRel(r.confInt->upper, upper, rel);
}

// sleep data: extra for group 1 and group 2
const std::vector<double> kSleep1{0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0};
const std::vector<double> kSleep2{1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4};
// depression scores (Hollander & Wolfe), R's wilcox.test example
const std::vector<double> kDx{1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30};
const std::vector<double> kDy{0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29};
// permeability constants, R's wilcox.test example
const std::vector<double> kRx{0.80, 0.83, 1.89, 1.04, 1.45, 1.38, 1.91, 1.64, 0.73, 1.46};
const std::vector<double> kRy{1.15, 0.88, 0.90, 0.74, 1.21};
// Likert-like ratings with ties
const std::vector<double> kA{5, 6, 4, 7, 5, 6, 3, 5, 6, 7, 4, 5};
const std::vector<double> kB{3, 4, 4, 5, 2, 4, 3, 5, 4, 3, 2, 4};
// kruskal.test example groups
const std::vector<double> kK1{2.9, 3.0, 2.5, 2.6, 3.2};
const std::vector<double> kK2{3.8, 2.7, 4.0, 2.4};
const std::vector<double> kK3{2.8, 3.4, 3.7, 2.2, 2.0};

std::vector<double> sinTimes(int n, double scale) { // R: sin(1:n) * scale
    std::vector<double> v;
    for (int i = 1; i <= n; ++i) v.push_back(std::sin(static_cast<double>(i)) * scale);
    return v;
}

} // namespace

// ---------------------------------------------------------------- chi-square

TEST(ChisqTest, PublishedGravelComparisonMatchesEurohapticsPaper) {
    // R: chisq.test(matrix(c(8,12,18,2),2,byrow=TRUE)) -> X-squared = 8.9011, df = 1, p = 0.00285
    const auto r = chisqTest({{8, 12}, {18, 2}});
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.method, "Pearson's Chi-squared test with Yates' continuity correction");
    expectRel(r.statistic, 8.9010989010989);
    EXPECT_EQ(r.df, std::vector<double>{1});
    expectRel(r.p, 0.00284999090249869);
    EXPECT_NEAR(r.statistic, 8.9011, 5e-5);
    EXPECT_NEAR(r.p, 0.00285, 5e-6);
}

TEST(ChisqTest, PublishedWoodComparisonMatchesEurohapticsPaper) {
    // R: chisq.test(matrix(c(10,10,18,2),2,byrow=TRUE)) -> 5.8333, p = 0.01573
    const auto r = chisqTest({{10, 10}, {18, 2}});
    expectRel(r.statistic, 5.83333333333333);
    expectRel(r.p, 0.0157252997545054);
    EXPECT_NEAR(r.p, 0.01573, 5e-6);
}

TEST(ChisqTest, WithoutYatesCorrectionGivesPearsonStatistic) {
    // R: chisq.test(matrix(c(8,12,18,2),2,byrow=TRUE), correct=FALSE)
    const auto r = chisqTest({{8, 12}, {18, 2}}, Continuity::Uncorrected);
    EXPECT_EQ(r.method, "Pearson's Chi-squared test");
    expectRel(r.statistic, 10.989010989011);
    expectRel(r.p, 0.000916537076114535);
}

TEST(ChisqTest, RowsByColumnsTableHasProductDegreesOfFreedom) {
    // R: chisq.test(matrix(c(762, 327, 468, 484, 239, 477), 2, byrow=TRUE))
    const auto r = chisqTest({{762, 327, 468}, {484, 239, 477}});
    expectRel(r.statistic, 30.0701490957547);
    EXPECT_EQ(r.df, std::vector<double>{2});
    expectRel(r.p, 2.95358918321176e-07);
    EXPECT_TRUE(r.warnings.empty());
}

TEST(ChisqTest, GoodnessOfFitUsesGivenProbabilities) {
    // R: chisq.test(c(89,37,30,28,2), p=c(40,20,20,15,5)/100)
    const std::vector<double> x{89, 37, 30, 28, 2}, p{.40, .20, .20, .15, .05};
    const auto r = chisqGoodnessOfFit(x, p);
    EXPECT_EQ(r.method, "Chi-squared test for given probabilities");
    expectRel(r.statistic, 9.99014336917563);
    EXPECT_EQ(r.df, std::vector<double>{4});
    expectRel(r.p, 0.0405940433447812);
    // R: chisq.test(c(20,15,25))
    const std::vector<double> u{20, 15, 25};
    expectRel(chisqGoodnessOfFit(u).p, 0.28650479686019);
}

TEST(ChisqTest, DegenerateTablesBehaveLikeR) {
    // R: chisq.test(matrix(c(0,0,5,7),2,byrow=TRUE)) -> X-squared NaN, p NaN, with a warning
    const auto zeroRow = chisqTest({{0, 0}, {5, 7}});
    ASSERT_TRUE(zeroRow.ok());
    EXPECT_TRUE(std::isnan(zeroRow.statistic));
    EXPECT_TRUE(std::isnan(zeroRow.p));
    EXPECT_EQ(zeroRow.method, "Pearson's Chi-squared test");
    EXPECT_FALSE(zeroRow.warnings.empty());
    // R: chisq.test(matrix(c(0,0,0,0),2)) -> error
    EXPECT_EQ(chisqTest({{0, 0}, {0, 0}}).error, "at least one entry of 'x' must be positive");
    // R: chisq.test(matrix(c(5,5,5,5),2)) -> no Yates in the method name, X-squared 0, p 1
    const auto balanced = chisqTest({{5, 5}, {5, 5}});
    EXPECT_EQ(balanced.method, "Pearson's Chi-squared test");
    EXPECT_EQ(balanced.statistic, 0);
    EXPECT_EQ(balanced.p, 1);
    EXPECT_FALSE(chisqTest({{1, -1}, {2, 3}}).ok());
    const std::vector<double> bad{1, 2}, badP{0.3, 0.3};
    EXPECT_EQ(chisqGoodnessOfFit(bad, badP).error, "probabilities must sum to 1.");
}

// ---------------------------------------------------------------- Fisher

TEST(FisherTest, TeaTastingMatchesConditionalMleAndInterval) {
    // R: fisher.test(matrix(c(3,1,1,3),2))
    const auto r = fisherTest({{3, 1}, {1, 3}});
    ASSERT_TRUE(r.ok());
    expectRel(r.p, 0.485714285714286);
    ASSERT_EQ(r.estimate.size(), 1u);
    EXPECT_EQ(r.estimate[0].name, "odds ratio");
    expectRel(r.estimate[0].value, 6.40830886700579, 1e-7);
    expectCi(r, 0.211732915305503, 621.933750545417, 1e-7);
}

TEST(FisherTest, OneSidedAndZeroCellCases) {
    // R: fisher.test(matrix(c(2,10,15,3),2), alternative="less")
    const auto less = fisherTest({{2, 15}, {10, 3}}, 0.95, Alternative::Less);
    expectRel(less.p, 0.000465180943362905);
    expectRel(less.estimate[0].value, 0.0469366088276989, 1e-7);
    expectCi(less, 0, 0.28496013793557, 1e-7);
    // R: fisher.test(matrix(c(8,12,18,2),2,byrow=TRUE), alternative="greater", conf.level=0.9)
    const auto greater = fisherTest({{8, 12}, {18, 2}}, 0.9, Alternative::Greater);
    expectRel(greater.p, 0.999931522178463);
    expectCi(greater, 0.0161328146758693, INFINITY, 1e-7);
    // R: fisher.test(matrix(c(0,5,6,4),2)) -> estimate 0, CI (0, 1.27875130893895)
    const auto zero = fisherTest({{0, 6}, {5, 4}});
    expectRel(zero.p, 0.043956043956044);
    EXPECT_EQ(zero.estimate[0].value, 0);
    expectCi(zero, 0, 1.27875130893895, 1e-7);
}

TEST(FisherTest, GravelAndLargerTablesMatchR) {
    // R: fisher.test(matrix(c(8,12,18,2),2,byrow=TRUE))
    const auto gravel = fisherTest({{8, 12}, {18, 2}});
    expectRel(gravel.p, 0.00219964124302278);
    expectRel(gravel.estimate[0].value, 0.0798174387180358, 1e-7);
    expectCi(gravel, 0.00708605026433447, 0.478691596101893, 1e-7);
    // R: fisher.test(matrix(c(120,85,64,131),2))
    const auto big = fisherTest({{120, 64}, {85, 131}});
    expectRel(big.p, 2.78648153001677e-07, 1e-7);
    expectRel(big.estimate[0].value, 2.88152365935567, 1e-7);
    expectCi(big, 1.88326374576351, 4.43927761399448, 1e-7);
}

TEST(FisherTest, RejectsTablesItCannotTest) {
    EXPECT_EQ(fisherTest({{1, 2, 3}}).error, "'x' must have at least 2 rows and columns");
    EXPECT_FALSE(fisherTest({{1, 2, 3}, {4, 5, 6}}).ok());
    EXPECT_FALSE(fisherTest({{1, 2}, {3, 4}}, 1.5).ok());
}

// ---------------------------------------------------------------- t tests

TEST(TTest, WelchIsTheDefaultTwoSampleTest) {
    // R: t.test(x, y) with the sleep data
    const auto r = tTest(kSleep1, kSleep2);
    EXPECT_EQ(r.method, "Welch Two Sample t-test");
    expectRel(r.statistic, -1.86081346748685);
    expectRel(r.df[0], 17.7764735161785);
    expectRel(r.p, 0.0793941401873582);
    expectCi(r, -3.36548323071171, 0.20548323071171);
    expectRel(r.estimate[0].value, 0.75);
    expectRel(r.estimate[1].value, 2.33);
}

TEST(TTest, StudentPairedAndOneSampleVariants) {
    // R: t.test(x, y, var.equal=TRUE)
    TTestOptions student;
    student.variance = Variance::Equal;
    const auto s = tTest(kSleep1, kSleep2, student);
    EXPECT_EQ(s.method, "Two Sample t-test");
    EXPECT_EQ(s.df, std::vector<double>{18});
    expectRel(s.p, 0.0791867142159382);
    expectCi(s, -3.3638740322876, 0.203874032287599);
    // R: t.test(x, y, paired=TRUE)
    TTestOptions paired;
    paired.pairing = Pairing::Paired;
    const auto p = tTest(kSleep1, kSleep2, paired);
    EXPECT_EQ(p.method, "Paired t-test");
    expectRel(p.statistic, -4.06212768338204);
    expectRel(p.p, 0.00283289019738427);
    expectCi(p, -2.45988576327698, -0.700114236723018);
    EXPECT_EQ(p.estimate[0].name, "mean difference");
    // R: t.test(x, mu=0.5)
    TTestOptions one;
    one.mu = 0.5;
    const auto o = tTest(kSleep1, one);
    EXPECT_EQ(o.method, "One Sample t-test");
    expectRel(o.statistic, 0.44190338023794);
    expectRel(o.p, 0.668986623614675);
    expectCi(o, -0.529780413526232, 2.02978041352623);
}

TEST(TTest, OneSidedAlternativesAndLevels) {
    // R: t.test(y, mu=1, alternative="less", conf.level=0.9)
    TTestOptions less;
    less.mu = 1;
    less.alternative = Alternative::Less;
    less.confLevel = 0.9;
    const auto l = tTest(kSleep2, less);
    expectRel(l.p, 0.967470057165952);
    expectCi(l, -INFINITY, 3.20568766585724);
    // R: t.test(x, y, alternative="greater")
    TTestOptions greater;
    greater.alternative = Alternative::Greater;
    const auto g = tTest(kSleep1, kSleep2, greater);
    expectRel(g.p, 0.960302929906321);
    expectCi(g, -3.05338149733161, INFINITY);
}

TEST(TTest, DegenerateSamplesGiveRsErrors) {
    const std::vector<double> constant{2, 2, 2}, single{2}, three{1, 2, 3}, four{4};
    EXPECT_EQ(tTest(constant).error, "data are essentially constant");  // R: t.test(c(2,2,2))
    EXPECT_EQ(tTest(single).error, "not enough 'x' observations");      // R: t.test(2)
    EXPECT_EQ(tTest(three, four).error, "not enough 'y' observations"); // R: t.test(1:3, 4)
    // R: t.test(c(1,2,3), 4, var.equal=TRUE) runs: t = -1.73205080756888, df = 2
    TTestOptions student;
    student.variance = Variance::Equal;
    const auto r = tTest(three, four, student);
    ASSERT_TRUE(r.ok());
    expectRel(r.statistic, -1.73205080756888);
    expectRel(r.p, 0.225403330758517);
    expectCi(r, -6.96827542350066, 2.96827542350066);
}

// ---------------------------------------------------------------- Wilcoxon

TEST(WilcoxonTest, PairedSignedRankIsExactWithoutTies) {
    // R: wilcox.test(x, y, paired=TRUE) (depression data) -> V = 40, p-value = 0.0390625
    WilcoxonOptions paired;
    paired.pairing = Pairing::Paired;
    const auto r = wilcoxonTest(kDx, kDy, paired);
    EXPECT_EQ(r.method, "Wilcoxon signed rank exact test");
    EXPECT_EQ(r.statisticName, "V");
    EXPECT_EQ(r.statistic, 40);
    expectRel(r.p, 0.0390625, 1e-12);
    EXPECT_FALSE(r.confInt.has_value()); // R's default conf.int = FALSE
    // R: wilcox.test(x, y, paired=TRUE, alternative="greater")
    paired.alternative = Alternative::Greater;
    expectRel(wilcoxonTest(kDx, kDy, paired).p, 0.01953125, 1e-12);
}

TEST(WilcoxonTest, RankSumIsExactForSmallSamplesWithoutTies) {
    // R: wilcox.test(x, y) (permeability data) -> W = 35, p-value = 0.2544
    const auto r = wilcoxonTest(kRx, kRy);
    EXPECT_EQ(r.method, "Wilcoxon rank sum exact test");
    EXPECT_EQ(r.statistic, 35);
    expectRel(r.p, 0.254412254412254);
    WilcoxonOptions greater;
    greater.alternative = Alternative::Greater;
    expectRel(wilcoxonTest(kRx, kRy, greater).p, 0.127206127206127);
    // R: wilcox.test(x, y, exact=FALSE)
    WilcoxonOptions normal;
    normal.exactness = Exactness::Approximate;
    const auto n = wilcoxonTest(kRx, kRy, normal);
    EXPECT_EQ(n.method, "Wilcoxon rank sum test with continuity correction");
    expectRel(n.p, 0.244623605126983);
}

TEST(WilcoxonTest, TiesSwitchToNormalApproximationWithTieCorrection) {
    // R: wilcox.test(a, b) -> W = 122.5, p = 0.00311316456638527 (+ warning about ties)
    const auto r = wilcoxonTest(kA, kB);
    EXPECT_EQ(r.method, "Wilcoxon rank sum test with continuity correction");
    EXPECT_EQ(r.statistic, 122.5);
    expectRel(r.p, 0.00311316456638527);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_EQ(r.warnings[0], "cannot compute exact p-value with ties");
    // R: wilcox.test(a, b, correct=FALSE)
    WilcoxonOptions plain;
    plain.continuity = Continuity::Uncorrected;
    const auto u = wilcoxonTest(kA, kB, plain);
    EXPECT_EQ(u.method, "Wilcoxon rank sum test");
    expectRel(u.p, 0.00282744488481755);
    // R: wilcox.test(a, b, paired=TRUE) -> V = 45, p = 0.00714009700956929 (ties and zeroes)
    WilcoxonOptions paired;
    paired.pairing = Pairing::Paired;
    const auto p = wilcoxonTest(kA, kB, paired);
    EXPECT_EQ(p.statistic, 45);
    expectRel(p.p, 0.00714009700956929);
    EXPECT_EQ(p.warnings.size(), 2u);
    // R: wilcox.test(a, b, paired=TRUE, correct=FALSE, alternative="less")
    paired.continuity = Continuity::Uncorrected;
    paired.alternative = Alternative::Less;
    expectRel(wilcoxonTest(kA, kB, paired).p, 0.997032764652946);
    // R: wilcox.test(dy, mu=1) -> V = 29, p = 0.476422052701023
    WilcoxonOptions mu;
    mu.mu = 1;
    const auto m = wilcoxonTest(kDy, mu);
    EXPECT_EQ(m.statistic, 29);
    expectRel(m.p, 0.476422052701023);
}

namespace {
std::vector<double> big1() { // R: ((1:49) * 37) %% 101 - 50.5
    std::vector<double> v;
    for (int i = 1; i <= 49; ++i) v.push_back(static_cast<double>((i * 37) % 101) - 50.5);
    return v;
}
std::vector<double> big2() { // R: ((1:49) * 53) %% 103 - 40.25
    std::vector<double> v;
    for (int i = 1; i <= 49; ++i) v.push_back(static_cast<double>((i * 53) % 103) - 40.25);
    return v;
}
} // namespace

TEST(WilcoxonTest, LargestExactSizesMatchRAndFiftySwitchesToNormal) {
    // R: wilcox.test(big1) -> V = 625, p = 0.905843557195151 (exact, n = 49)
    const auto s = wilcoxonTest(big1());
    EXPECT_EQ(s.method, "Wilcoxon signed rank exact test");
    EXPECT_EQ(s.statistic, 625);
    expectRel(s.p, 0.905843557195151);
    // R: wilcox.test(big1, big2) -> W = 1058, p = 0.314490271302231 (exact, 49 x 49)
    const auto w = wilcoxonTest(big1(), big2());
    EXPECT_EQ(w.method, "Wilcoxon rank sum exact test");
    EXPECT_EQ(w.statistic, 1058);
    expectRel(w.p, 0.314490271302231);
    // R: wilcox.test(c(big1, 77.5)) -> V = 675, p = 0.720963561834473 (normal, n = 50)
    auto fifty = big1();
    fifty.push_back(77.5);
    const auto f = wilcoxonTest(fifty);
    EXPECT_EQ(f.method, "Wilcoxon signed rank test with continuity correction");
    expectRel(f.p, 0.720963561834473);
}

TEST(WilcoxonTest, AllZeroOrAllTiedDataGiveNaNLikeR) {
    // R: wilcox.test(c(0,0,0)) -> V = 0, p-value = NaN
    const std::vector<double> zeros{0, 0, 0};
    const auto z = wilcoxonTest(zeros);
    ASSERT_TRUE(z.ok());
    EXPECT_EQ(z.statistic, 0);
    EXPECT_TRUE(std::isnan(z.p));
    // R: wilcox.test(c(1,1), c(1,1,1)) -> W = 3, p-value = NaN
    const std::vector<double> ones2{1, 1}, ones3{1, 1, 1};
    const auto t = wilcoxonTest(ones2, ones3);
    EXPECT_EQ(t.statistic, 3);
    EXPECT_TRUE(std::isnan(t.p));
    const std::vector<double> none;
    EXPECT_FALSE(wilcoxonTest(none).ok());
}

// ---------------------------------------------------------------- Kruskal, Friedman

TEST(KruskalTest, MatchesRWithAndWithoutTies) {
    // R: kruskal.test(list(k1, k2, k3)) -> 0.771428571428572, df 2, p 0.679964773578894
    const auto r = kruskalTest({kK1, kK2, kK3});
    expectRel(r.statistic, 0.771428571428572);
    EXPECT_EQ(r.df, std::vector<double>{2});
    expectRel(r.p, 0.679964773578894);
    // R: kruskal.test(list(a, b, c(1,2,2,3,5)))
    const auto t = kruskalTest({kA, kB, {1, 2, 2, 3, 5}});
    expectRel(t.statistic, 12.4741800834824);
    expectRel(t.p, 0.00195553778458981);
    // R: kruskal.test(list(c(1,1), c(1,1))) -> NaN statistic and p
    const auto c = kruskalTest({{1, 1}, {1, 1}});
    ASSERT_TRUE(c.ok());
    EXPECT_TRUE(std::isnan(c.statistic));
    EXPECT_EQ(kruskalTest({{1, 2}, {}}).error, "all groups must contain data");
}

TEST(FriedmanTest, RowsAreSubjectsAndColumnsConditions) {
    // R: friedman.test(matrix(c(5,4,7, 6,6,8, 3,5,4, 7,6,9, 4,4,6, 5,7,7, 6,5,8, 2,3,5),
    //                         ncol=3, byrow=TRUE))
    const auto r = friedmanTest(
        {{5, 4, 7}, {6, 6, 8}, {3, 5, 4}, {7, 6, 9}, {4, 4, 6}, {5, 7, 7}, {6, 5, 8}, {2, 3, 5}});
    EXPECT_EQ(r.method, "Friedman rank sum test");
    expectRel(r.statistic, 8.89655172413793);
    EXPECT_EQ(r.df, std::vector<double>{2});
    expectRel(r.p, 0.0116987197988249);
    // R: friedman.test(matrix(c(1,1,1,2,2,2),ncol=3,byrow=TRUE)) -> NaN
    EXPECT_TRUE(std::isnan(friedmanTest({{1, 1, 1}, {2, 2, 2}}).statistic));
}

// ---------------------------------------------------------------- Spearman

TEST(SpearmanTest, SmallSamplesUseExactPermutationDistribution) {
    // R: cor.test(c(4.1,2.3,5.6,3.3,1.9,6.2,2.8), c(3.0,2.9,4.8,3.9,1.1,5.0,2.0),
    //             method="spearman") -> S = 4, p = 0.00674603174603175, rho = 0.928571428571428
    const std::vector<double> s1{4.1, 2.3, 5.6, 3.3, 1.9, 6.2, 2.8};
    const std::vector<double> s2{3.0, 2.9, 4.8, 3.9, 1.1, 5.0, 2.0};
    const auto r = spearmanTest(s1, s2);
    EXPECT_EQ(r.method, "Spearman's rank correlation rho");
    EXPECT_NEAR(r.statistic, 4, 1e-9);
    expectRel(r.p, 0.00674603174603175);
    expectRel(r.estimate[0].value, 0.928571428571428);
    // R: cor.test(c(9,8,7,6,5,4,3,1,2), 1:9, method="spearman") -> p = 4.96031746031746e-05
    const std::vector<double> down{9, 8, 7, 6, 5, 4, 3, 1, 2}, up{1, 2, 3, 4, 5, 6, 7, 8, 9};
    const auto d = spearmanTest(down, up);
    expectRel(d.statistic, 238);
    expectRel(d.p, 4.96031746031746e-05);
}

TEST(SpearmanTest, MediumSamplesUseEdgeworthSeriesAsR) {
    // R: sx <- sin(1:20)*10; sy <- sx + cos((1:20)*3)*25; cor.test(sx, sy, method="spearman")
    const auto sx = sinTimes(20, 10);
    std::vector<double> sy;
    for (int i = 1; i <= 20; ++i)
        sy.push_back(sx[static_cast<std::size_t>(i - 1)] + std::cos(i * 3.0) * 25);
    const auto r = spearmanTest(sx, sy);
    expectRel(r.statistic, 884);
    expectRel(r.p, 0.148467126756072);
    expectRel(r.estimate[0].value, 0.335338345864662);
    // R: ... alternative="less" -> 0.926715409831242; exact=FALSE -> 0.148357298618493
    expectRel(spearmanTest(sx, sy, Alternative::Less).p, 0.926715409831242);
    expectRel(spearmanTest(sx, sy, Alternative::TwoSided, Exactness::Approximate).p,
              0.148357298618493);
    // R: cor.test(sx[1:10], sy[1:10], method="spearman") -> S = 96, p = 0.232418098250503
    const std::vector<double> x10(sx.begin(), sx.begin() + 10), y10(sy.begin(), sy.begin() + 10);
    expectRel(spearmanTest(x10, y10).p, 0.232418098250503);
}

TEST(SpearmanTest, LargeSamplesAndTiesUseTheTApproximation) {
    // R: lx <- sin(1:1300*0.7); ly <- lx*0.05 + cos(1:1300*1.3)
    std::vector<double> lx, ly;
    for (int i = 1; i <= 1300; ++i) {
        lx.push_back(std::sin(i * 0.7));
        ly.push_back(lx.back() * 0.05 + std::cos(i * 1.3));
    }
    // R: cor.test(lx, ly, method="spearman") -> S = 337368890, p = 0.00454978515131745
    const auto big = spearmanTest(lx, ly);
    expectRel(big.statistic, 337368890);
    expectRel(big.p, 0.00454978515131745, 1e-8);
    // R: cor.test(lx[1:1290], ly[1:1290], method="spearman") -> AS 89 at its largest n
    const std::vector<double> x1290(lx.begin(), lx.begin() + 1290),
        y1290(ly.begin(), ly.begin() + 1290);
    const auto edge = spearmanTest(x1290, y1290);
    expectRel(edge.statistic, 329728202);
    expectRel(edge.p, 0.00484559775560896, 1e-8);
    // R: cor.test(a, b, method="spearman") -> ties: S = 172.659068882126, p = 0.202186409769637
    const auto t = spearmanTest(kA, kB);
    expectRel(t.statistic, 172.659068882126);
    expectRel(t.p, 0.202186409769637);
    expectRel(t.estimate[0].value, 0.396296961950609);
    EXPECT_EQ(t.warnings.at(0), "Cannot compute exact p-value with ties");
}

TEST(SpearmanTest, ConstantOrTooShortInputBehavesLikeR) {
    // R: cor.test(c(1,1,1,1), 1:4, method="spearman") -> rho NA, S NA, p NA (warning)
    const std::vector<double> c{1, 1, 1, 1}, v{1, 2, 3, 4}, one{1}, two{2};
    const auto r = spearmanTest(c, v);
    ASSERT_TRUE(r.ok());
    EXPECT_TRUE(std::isnan(r.estimate[0].value));
    EXPECT_TRUE(std::isnan(r.p));
    // R: cor.test(1, 2, method="spearman") -> error
    EXPECT_EQ(spearmanTest(one, two).error, "not enough finite observations");
}

// ---------------------------------------------------------------- p.adjust

TEST(PAdjust, HolmBonferroniHochbergAndBhMatchR) {
    const std::vector<double> p{0.01, 0.04, 0.03, 0.20, 0.005, 0.5};
    // R: p.adjust(p, "holm") etc.
    const std::vector<double> holm{0.05, 0.12, 0.12, 0.4, 0.03, 0.5};
    const std::vector<double> bonf{0.06, 0.24, 0.18, 1, 0.03, 1};
    const std::vector<double> bh{0.03, 0.06, 0.06, 0.24, 0.03, 0.5};
    const auto h = pAdjust(p, PAdjustMethod::Holm), b = pAdjust(p, PAdjustMethod::Bonferroni),
               hb = pAdjust(p, PAdjustMethod::Hochberg),
               fdr = pAdjust(p, PAdjustMethod::BenjaminiHochberg);
    for (std::size_t i = 0; i < p.size(); ++i) {
        expectRel(h[i], holm[i], 1e-12);
        expectRel(b[i], bonf[i], 1e-12);
        expectRel(hb[i], holm[i], 1e-12); // R gives the same values for hochberg here
        expectRel(fdr[i], bh[i], 1e-12);
    }
    // R: p.adjust(c(0.01, NA, 0.04), "holm") -> 0.02, NA, 0.04
    const std::vector<double> withNa{0.01, NAN, 0.04};
    const auto a = pAdjust(withNa, PAdjustMethod::Holm);
    expectRel(a[0], 0.02, 1e-12);
    EXPECT_TRUE(std::isnan(a[1]));
    expectRel(a[2], 0.04, 1e-12);
}

// ---------------------------------------------------------------- Shapiro-Wilk

TEST(ShapiroTest, MatchesRoyston1995AsInR) {
    // R: shapiro.test(c(1,2,4)) (n = 3, exact p)
    const std::vector<double> three{1, 2, 4};
    const auto r3 = shapiroTest(three);
    expectRel(r3.statistic, 0.964285714285714);
    expectRel(r3.p, 0.636886845028963, 1e-8);
    // R: shapiro.test(c(4.1,2.3,5.6,3.3,1.9,6.2,2.8))
    const std::vector<double> s1{4.1, 2.3, 5.6, 3.3, 1.9, 6.2, 2.8};
    const auto r7 = shapiroTest(s1);
    expectRel(r7.statistic, 0.922361099318846);
    expectRel(r7.p, 0.487958725854866, 1e-8);
    // R: shapiro.test(sin(1:20)*10)
    const auto r20 = shapiroTest(sinTimes(20, 10));
    expectRel(r20.statistic, 0.892879806114363);
    expectRel(r20.p, 0.0303891062365882, 1e-8);
    // R: shapiro.test(exp(sin(1:100)))
    std::vector<double> e;
    for (int i = 1; i <= 100; ++i) e.push_back(std::exp(std::sin(static_cast<double>(i))));
    const auto r100 = shapiroTest(e);
    expectRel(r100.statistic, 0.863644697267069);
    expectRel(r100.p, 3.91801224262459e-08, 1e-7);
}

TEST(ShapiroTest, RejectsTooFewOrIdenticalValues) {
    const std::vector<double> two{1, 2}, same{1, 1, 1, 1};
    EXPECT_EQ(shapiroTest(two).error, "sample size must be between 3 and 5000");
    EXPECT_EQ(shapiroTest(same).error, "all 'x' values are identical");
}

// ---------------------------------------------------------------- Levene

TEST(LeveneTest, MedianCenterIsBrownForsytheAndMeanIsLevene) {
    // R (car::leveneTest semantics in base R): y <- c(k1,k2,k3); g <- factor(rep(1:3, c(5,4,5)))
    //   d <- abs(y - ave(y, g, FUN=median)); anova(lm(d ~ g))
    const auto med = leveneTest({kK1, kK2, kK3});
    expectRel(med.statistic, 4.47685434384756);
    EXPECT_EQ(med.df, (std::vector<double>{2, 11}));
    expectRel(med.p, 0.0378033090886112);
    // same with FUN=mean
    const auto mea = leveneTest({kK1, kK2, kK3}, LeveneCenter::Mean);
    expectRel(mea.statistic, 4.78146920806927);
    expectRel(mea.p, 0.0320399114162382);
    EXPECT_FALSE(leveneTest({kK1}).ok());
}

// ---------------------------------------------------------------- binomial and proportions

TEST(BinomTest, ExactPValueAndClopperPearsonInterval) {
    // R: binom.test(682, 925, p=0.75)
    const auto r = binomTest(682, 925, 0.75);
    EXPECT_EQ(r.method, "Exact binomial test");
    expectRel(r.p, 0.382491559574852, 1e-8);
    expectCi(r, 0.707668264079039, 0.765406558241525);
    expectRel(r.estimate[0].value, 0.737297297297297);
    // R: binom.test(3, 20, p=0.3, alternative="less", conf.level=0.9)
    const auto l = binomTest(3, 20, 0.3, Alternative::Less, 0.9);
    expectRel(l.p, 0.107086804503731);
    expectCi(l, 0, 0.304186811407479);
    // R: binom.test(0, 10) and binom.test(10, 10, p=0.8)
    const auto z = binomTest(0, 10);
    expectRel(z.p, 0.001953125, 1e-12);
    expectCi(z, 0, 0.308497107818761);
    const auto a = binomTest(10, 10, 0.8);
    expectRel(a.p, 0.228248064, 1e-9);
    expectCi(a, 0.691502892181239, 1);
    EXPECT_EQ(binomTest(11, 10).error, "'n' must be a positive integer >= 'x'");
}

TEST(BinomTest, LargeCountsCountTheOtherTailByBisectionAndHugeOnesAreRefused) {
    // More than 10^6 terms on the other side of the mean: counted by bisection on the monotone
    // density instead of one by one (a fuzzed n of 7.8e98 looped for ever). R 4.2:
    // binom.test(1498000, 3000000, 0.5), binom.test(1001700, 3333333, 0.3),
    // binom.test(999000, 3333333, 0.3)
    expectRel(binomTest(1498000, 3000000, 0.5).p, 0.020953349433570377, 1e-6);
    expectRel(binomTest(1001700, 3333333, 0.3).p, 0.042164931449614557, 1e-6);
    expectRel(binomTest(999000, 3333333, 0.3).p, 0.2322312084468296, 1e-6);
    EXPECT_EQ(binomTest(7, 7.8e98, 0.3).error, "'n' must be at most 2^53 = 9007199254740992");
    EXPECT_TRUE(binomTest(7, 1e15, 0.3).ok()); // bounded work at any exact count
}

TEST(FisherTest, MarginsBeyondTheEnumerationLimitAreRefusedNotEnumerated) {
    // 4e8 counts would have held 2e8 densities in memory and run for minutes.
    const CountTable big{{300000000, 100000000}, {100000000, 300000000}};
    const auto r = fisherTest(big);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.error.find("more than the 100000 this exact test enumerates"), std::string::npos)
        << r.error;
    EXPECT_TRUE(fisherTest({{40000, 10000}, {10000, 40000}}).ok());
}

TEST(PropTest, OneTwoAndKSampleTestsMatchR) {
    // R: prop.test(15, 20)
    const std::vector<double> x1{15}, n1{20};
    const auto one = propTest(x1, n1);
    EXPECT_EQ(one.method, "1-sample proportions test with continuity correction");
    expectRel(one.statistic, 4.05);
    expectRel(one.p, 0.0441713449084427);
    expectCi(one, 0.505884541417155, 0.904067408130394);
    // R: prop.test(15, 20, p=0.6, correct=FALSE)
    const std::vector<double> p06{0.6};
    const auto onePlain =
        propTest(x1, n1, p06, Alternative::TwoSided, 0.95, Continuity::Uncorrected);
    expectRel(onePlain.statistic, 1.875);
    expectCi(onePlain, 0.531299122381256, 0.888138298592334);
    // R: prop.test(c(8,18), c(20,20)) = the gravel comparison again
    const std::vector<double> x2{8, 18}, n2{20, 20};
    const auto two = propTest(x2, n2);
    EXPECT_EQ(two.method, "2-sample test for equality of proportions with continuity correction");
    expectRel(two.statistic, 8.9010989010989);
    expectRel(two.p, 0.00284999090249869);
    expectCi(two, -0.801761932272242, -0.198238067727758);
    // R: prop.test(c(18,8), c(20,20), alternative="greater")
    const std::vector<double> x2r{18, 8};
    const auto greater = propTest(x2r, n2, {}, Alternative::Greater);
    expectRel(greater.p, 0.00142499545124935);
    expectCi(greater, 0.238714726039475, 1);
    // R: prop.test(c(83,90,129,70), c(86,93,136,82)) (smokers)
    const std::vector<double> x4{83, 90, 129, 70}, n4{86, 93, 136, 82};
    const auto four = propTest(x4, n4);
    EXPECT_EQ(four.method,
              "4-sample test for equality of proportions without continuity correction");
    expectRel(four.statistic, 12.6004112971276);
    EXPECT_EQ(four.df, std::vector<double>{3});
    expectRel(four.p, 0.00558547666162702);
    EXPECT_FALSE(four.confInt.has_value());
}

TEST(WilsonInterval, EqualsPropTestWithoutCorrection) {
    // R: prop.test(8, 20, correct=FALSE)$conf.int
    const auto w = wilsonInterval(8, 20);
    expectRel(w.lower, 0.218806532372817);
    expectRel(w.upper, 0.613418499237747);
    // R: prop.test(0, 20, correct=FALSE)$conf.int
    const auto z = wilsonInterval(0, 20);
    EXPECT_EQ(z.lower, 0);
    expectRel(z.upper, 0.161125158052819);
    EXPECT_TRUE(std::isnan(wilsonInterval(0, 0).lower));
}

TEST(EffectSizes, PhiCramersVAndCohensD) {
    // phi = (8*2 - 12*18) / sqrt(20*20*26*14); V = sqrt(X2/(n)) for 2x2 (uncorrected X2 10.989)
    expectRel(phiCoefficient({{8, 12}, {18, 2}}), (16.0 - 216.0) / std::sqrt(20.0 * 20 * 26 * 14));
    expectRel(cramersV({{8, 12}, {18, 2}}), std::sqrt(10.989010989011 / 40), 1e-9);
    // R: (mean(x)-mean(y)) / sqrt(((9*var(x)) + 9*var(y))/18) with the sleep data
    // = -1.58 / sqrt((var(x)+var(y))/2) = -0.83218108134954
    expectRel(cohensD(kSleep1, kSleep2), -0.83218108134954, 1e-9);
}

TEST(WilcoxonTest, ForcedExactBeyondTheSupportedSizeIsAClearError) {
    std::vector<double> x, y;
    for (int i = 0; i < 150; ++i) {
        x.push_back(i * 1.5 + 0.25);
        y.push_back(i * 1.7 + 0.5);
    }
    WilcoxonOptions exact;
    exact.exactness = Exactness::Exact;
    const auto r = wilcoxonTest(x, y, exact); // 150 x 150 > 10000
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.error.find("m * n <= 10000"), std::string::npos);
    // R: wilcox.test(x, y, exact=FALSE) works at any size
    exact.exactness = Exactness::Approximate;
    EXPECT_TRUE(wilcoxonTest(x, y, exact).ok());
}

TEST(WilcoxonTest, ForcedExactDistributionsMatchRBeyondTheDefaultSizes) {
    // R: x <- (0:99)*1.5+0.25; y <- (0:99)*1.7+0.5; wilcox.test(x, y, exact=TRUE)$p.value
    std::vector<double> x, y;
    for (int i = 0; i < 100; ++i) {
        x.push_back(i * 1.5 + 0.25);
        y.push_back(i * 1.7 + 0.5);
    }
    WilcoxonOptions exact;
    exact.exactness = Exactness::Exact;
    const auto r = wilcoxonTest(x, y, exact);
    EXPECT_EQ(r.method, "Wilcoxon rank sum exact test");
    expectRel(r.p, 0.14525018504351, 1e-12);
    // R: i <- 1:1000; z <- i*ifelse(i%%3==0,-1,1)+0.001*i; wilcox.test(z, exact=TRUE)$p.value
    std::vector<double> z;
    for (int i = 1; i <= 1000; ++i) z.push_back(i * (i % 3 == 0 ? -1.0 : 1.0) + 0.001 * i);
    const auto s = wilcoxonTest(z, exact);
    EXPECT_EQ(s.method, "Wilcoxon signed rank exact test");
    expectRel(s.p, 1.94234194595631e-20, 1e-9);
}

TEST(PairwiseWilcoxon, PairedConditionsWithHolmMatchPairwiseWilcoxTest) {
    const std::vector<double> a{6.1, 5.2, 7.3, 4.8, 6.6, 5.9, 7.0, 6.4, 5.5, 6.8};
    const std::vector<double> b{5.0, 5.1, 6.2, 4.1, 6.0, 5.3, 6.1, 5.7, 5.6, 5.9};
    const std::vector<double> c{7.2, 6.0, 7.9, 5.5, 7.1, 6.9, 7.6, 7.7, 6.3, 7.4};
    // R: x <- c(a,b,c); g <- factor(rep(c("a","b","c"), each=10))
    //    pairwise.wilcox.test(x, g, paired=TRUE, p.adjust.method="holm")
    //    raw: wilcox.test(b, a, paired=TRUE) 0.00796348920654999, (c, a) 0.00585709908528413,
    //         (c, b) 0.00588927004181748; all Holm-adjusted to 0.0175712972558524
    WilcoxonOptions paired;
    paired.pairing = Pairing::Paired;
    const auto r = pairwiseWilcoxon({a, b, c}, PAdjustMethod::Holm, paired);
    ASSERT_EQ(r.size(), 3u);
    EXPECT_EQ(r[0].first, 1u);
    EXPECT_EQ(r[0].second, 0u);
    EXPECT_EQ(r[2].first, 2u);
    EXPECT_EQ(r[2].second, 1u);
    expectRel(r[0].test.p, 0.00796348920654999);
    expectRel(r[1].test.p, 0.00585709908528413);
    expectRel(r[2].test.p, 0.00588927004181748);
    for (const auto& pair : r) expectRel(pair.pAdjusted, 0.0175712972558524);
    // R: pairwise.wilcox.test(x, g, p.adjust.method="bonferroni") (rank-sum)
    const auto u = pairwiseWilcoxon({a, b, c}, PAdjustMethod::Bonferroni);
    expectRel(u[0].pAdjusted, 0.266198401539789);
    expectRel(u[1].pAdjusted, 0.12352130258131);
    expectRel(u[2].pAdjusted, 0.00579632568310356);
    // R: friedman.test(cbind(a,b,c)) -> 18.2, p 0.000111665808490115
    std::vector<std::vector<double>> rows;
    for (std::size_t i = 0; i < a.size(); ++i) rows.push_back({a[i], b[i], c[i]});
    const auto f = friedmanTest(rows);
    expectRel(f.statistic, 18.2);
    expectRel(f.p, 0.000111665808490115);
}
