// SPDX-License-Identifier: GPL-3.0-or-later
// Statistics beyond the reference studies: fisher.test on r x c tables, cor.test (pearson, kendall)
// and wilcox.test(conf.int = TRUE), against R 4.2.2 (Debian 12). Every reference value was printed
// by R with sprintf("%.15g", ...) from the call quoted next to it; the R script that printed
// them all is tests/analysis/data/stat_holes_reference.R.
#include "analysis/io/StatsJson.h"
#include "analysis/stats/Tests.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

void expectCi(const TestResult& r, double lower, double upper, double level, double rel = 1e-9) {
    ASSERT_TRUE(r.confInt.has_value());
    expectRel(r.confInt->lower, lower, rel);
    expectRel(r.confInt->upper, upper, rel);
    expectRel(r.confInt->level, level);
}

// Same data as StatTestsTest.cpp (and the R script).
const std::vector<double> kSleep1{0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0};
const std::vector<double> kSleep2{1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4};
const std::vector<double> kDx{1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30};
const std::vector<double> kDy{0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29};
const std::vector<double> kRx{0.80, 0.83, 1.89, 1.04, 1.45, 1.38, 1.91, 1.64, 0.73, 1.46};
const std::vector<double> kRy{1.15, 0.88, 0.90, 0.74, 1.21};
const std::vector<double> kA{5, 6, 4, 7, 5, 6, 3, 5, 6, 7, 4, 5};
const std::vector<double> kB{3, 4, 4, 5, 2, 4, 3, 5, 4, 3, 2, 4};

std::vector<double> seq(int n, double (*f)(double), double scale, double divisor = 1) {
    std::vector<double> v;
    for (int i = 1; i <= n; ++i) v.push_back(f(static_cast<double>(i) / divisor) * scale);
    return v;
}

} // namespace

// ---------------------------------------------------------------- Fisher r x c

TEST(FisherRxC, MatchesRsNetworkAlgorithmOnStudySizedTables) {
    // R: fisher.test(matrix(c(3,1,4, 2,6,1), 2, byrow=TRUE))$p.value
    expectRel(fisherTestRxC({{3, 1, 4}, {2, 6, 1}}).p, 0.0929658576717399, 1e-7);
    // R: fisher.test(matrix(c(5,1,0, 2,4,3, 0,2,6), 3, byrow=TRUE))$p.value
    expectRel(fisherTestRxC({{5, 1, 0}, {2, 4, 3}, {0, 2, 6}}).p, 0.00732024128051968, 1e-7);
    // R: fisher.test(matrix(c(4,2,1,0, 1,3,2,2, 0,1,3,5), 3, byrow=TRUE))$p.value
    expectRel(fisherTestRxC({{4, 2, 1, 0}, {1, 3, 2, 2}, {0, 1, 3, 5}}).p, 0.060589169284821, 1e-7);
    // R: fisher.test(matrix(c(3,2,5, 0,0,0, 1,4,2), 3, byrow=TRUE))$p.value (a zero row)
    expectRel(fisherTestRxC({{3, 2, 5}, {0, 0, 0}, {1, 4, 2}}).p, 0.456499382969972, 1e-7);
    // R: fisher.test(matrix(c(12,5,7,7, 5,12,7,7), 2, byrow=TRUE))$p.value (tied probabilities)
    expectRel(fisherTestRxC({{12, 5, 7, 7}, {5, 12, 7, 7}}).p, 0.120709398123556, 1e-7);
    // R: fisher.test(matrix(c(1,2,3, 3,2,1), 2, byrow=TRUE))$p.value (mirror tables, equal P)
    expectRel(fisherTestRxC({{1, 2, 3}, {3, 2, 1}}).p, 0.766233766233766, 1e-7);
    // Larger problems (R: Job <- matrix(c(1,2,1,0, 3,3,6,1, 10,10,14,9, 6,7,12,11), 4, 4),
    // fisher.test(Job) = 0.782684938965639, 9e7 tables) take seconds; see
    // docs/reference/statistics.md.
    const auto big = fisherTestRxC({{5, 1, 0}, {2, 4, 3}, {0, 2, 6}});
    EXPECT_EQ(big.method, "Fisher's Exact Test for Count Data");
    EXPECT_TRUE(big.estimate.empty());
    EXPECT_FALSE(big.confInt.has_value());
}

TEST(FisherRxC, TwoByTwoAgreesWithTheTwoByTwoTest) {
    // R: fisher.test(matrix(c(8,12,18,2),2,byrow=TRUE))$p.value
    expectRel(fisherTestRxC({{8, 12}, {18, 2}}).p, 0.00219964124302278, 1e-7);
}

TEST(FisherRxC, RefusesBadOrTooLargeProblemsWithAClearMessage) {
    EXPECT_EQ(fisherTestRxC({{1, 2, 3}}).error, "'x' must have at least 2 rows and columns");
    EXPECT_FALSE(fisherTestRxC({{1, 2, 3}, {4, 5}}).ok());
    EXPECT_FALSE(fisherTestRxC({{1, -2, 3}, {4, 5, 6}}).ok());
    const auto tooBig = fisherTestRxC({{600, 1}, {1, 600}});
    EXPECT_NE(tooBig.error.find("exceeds the limit"), std::string::npos) << tooBig.error;
    // R: fisher.test(matrix(c(4,2,1,0, 1,3,2,2, 0,1,3,5), 3, byrow=TRUE)) has 7854 tables
    const auto tooMany = fisherTestRxC({{4, 2, 1, 0}, {1, 3, 2, 2}, {0, 1, 3, 5}}, 7000);
    EXPECT_NE(tooMany.error.find("tables have these margins"), std::string::npos) << tooMany.error;
    const auto rounded = fisherTestRxC({{1.2, 2, 3}, {4, 5, 6}});
    ASSERT_EQ(rounded.warnings.size(), 1u);
}

// ---------------------------------------------------------------- Pearson

TEST(PearsonTest, MatchesCorTestWithFisherZInterval) {
    // R: cor.test(dx, dy)
    const auto r = pearsonTest(kDx, kDy);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.method, "Pearson's product-moment correlation");
    EXPECT_EQ(r.statisticName, "t");
    expectRel(r.statistic, 4.2310389906589);
    expectRel(r.p, 0.0038831303761205);
    EXPECT_EQ(r.df, std::vector<double>{7});
    expectRel(r.estimate[0].value, 0.847876519115364);
    expectCi(r, 0.420581259032382, 0.967311626153293, 0.95);
    // R: cor.test(s1, s2, alternative="greater", conf.level=0.9)
    const auto g = pearsonTest(kSleep1, kSleep2, Alternative::Greater, 0.9);
    expectRel(g.statistic, 3.70899042780411);
    expectRel(g.p, 0.00298249789845923);
    expectRel(g.estimate[0].value, 0.795170205833578);
    expectCi(g, 0.537730137359964, 1, 0.9);
    // R: cor.test(a, b, alternative="less")
    const auto l = pearsonTest(kA, kB, Alternative::Less);
    expectRel(l.statistic, 1.35629787941608);
    expectRel(l.p, 0.897582396525169);
    expectRel(l.estimate[0].value, 0.394173656404643);
    expectCi(l, -1, 0.746506113675994, 0.95);
    // R: cor.test(c(1,2,3,4), c(2,1,4,3))
    const auto four = pearsonTest(std::vector<double>{1, 2, 3, 4}, std::vector<double>{2, 1, 4, 3});
    expectRel(four.statistic, 1.06066017177982);
    expectRel(four.p, 0.4);
    expectCi(four, -0.852932564694718, 0.990127710799694, 0.95);
}

TEST(PearsonTest, ThreePairsHaveNoIntervalAndTwoAreAnError) {
    // R: cor.test(c(1,2,3), c(1,3,2)) -> no conf.int (n = 3)
    const auto r = pearsonTest(std::vector<double>{1, 2, 3}, std::vector<double>{1, 3, 2});
    expectRel(r.statistic, 0.577350269189626);
    expectRel(r.p, 0.666666666666667);
    expectRel(r.estimate[0].value, 0.5);
    EXPECT_FALSE(r.confInt.has_value());
    EXPECT_EQ(pearsonTest(std::vector<double>{1, 2}, std::vector<double>{1, 3}).error,
              "not enough finite observations");
    EXPECT_FALSE(pearsonTest(std::vector<double>{1, 2, 3}, std::vector<double>{1, 3}).ok());
}

// ---------------------------------------------------------------- Kendall

TEST(KendallTest, ExactWithoutTiesForSmallN) {
    // R: cor.test(rx, sin(1:10), method="kendall", alternative="less")
    const auto r = kendallTest(kRx, seq(10, std::sin, 1), Alternative::Less);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.method, "Kendall's rank correlation tau");
    EXPECT_EQ(r.statisticName, "T");
    EXPECT_EQ(r.statistic, 23);
    expectRel(r.p, 0.569099702380952);
    expectRel(r.estimate[0].value, 0.0222222222222222);
}

TEST(KendallTest, TiesUseTieCorrectedNormalApproximationAndTauB) {
    // R: cor.test(dx, dy, method="kendall") -> warning "Cannot compute exact p-value with ties"
    const auto r = kendallTest(kDx, kDy);
    EXPECT_EQ(r.statisticName, "z");
    expectRel(r.statistic, 1.89736659610103);
    expectRel(r.p, 0.0577795711235972);
    expectRel(r.estimate[0].value, 0.514495755427527);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_EQ(r.warnings[0], "Cannot compute exact p-value with ties");
    // R: cor.test(dx, dy, method="kendall", alternative="greater")
    expectRel(kendallTest(kDx, kDy, Alternative::Greater).p, 0.0288897855617986);
    // R: cor.test(dx, dy, method="kendall", exact=FALSE) (no warning)
    const auto approx = kendallTest(kDx, kDy, Alternative::TwoSided, Exactness::Approximate);
    expectRel(approx.p, 0.0577795711235972);
    EXPECT_TRUE(approx.warnings.empty());
    // R: cor.test(a, b, method="kendall")
    const auto ab = kendallTest(kA, kB);
    expectRel(ab.statistic, 1.27182440353723);
    expectRel(ab.p, 0.203435516248352);
    expectRel(ab.estimate[0].value, 0.320983337620978);
    // R: cor.test(a, b, method="kendall", continuity=TRUE)
    const auto cc =
        kendallTest(kA, kB, Alternative::TwoSided, Exactness::Auto, Continuity::Corrected);
    expectRel(cc.statistic, 1.19701120332916);
    expectRel(cc.p, 0.231302188045529);
}

TEST(KendallTest, FiftyOrMoreUseTheNormalApproximation) {
    // R: x60 <- sin(1:60)*10; y60 <- cos((1:60)/3)*5 + (1:60)/20; cor.test(x60, y60,
    // method="kendall")
    const auto x = seq(60, std::sin, 10);
    auto y = seq(60, std::cos, 5, 3);
    for (int i = 0; i < 60; ++i) y[static_cast<std::size_t>(i)] += (i + 1) / 20.0;
    const auto r = kendallTest(x, y);
    EXPECT_EQ(r.statisticName, "z");
    expectRel(r.statistic, 0.242361265574447);
    expectRel(r.p, 0.808500245352538);
    expectRel(r.estimate[0].value, 0.0214689265536723);
}

// ---------------------------------------------------------------- Wilcoxon intervals

TEST(WilcoxonCi, ExactHodgesLehmannForSmallSamplesWithoutTies) {
    WilcoxonOptions paired;
    paired.pairing = Pairing::Paired;
    // R: wilcox.test(dx, dy, paired=TRUE, conf.int=TRUE)
    const auto p = wilcoxonTestCi(kDx, kDy, paired);
    ASSERT_TRUE(p.ok()) << p.error;
    expectRel(p.statistic, 40);
    expectRel(p.p, 0.0390625);
    EXPECT_EQ(p.estimate[0].name, "(pseudo)median");
    expectRel(p.estimate[0].value, 0.46);
    expectCi(p, 0.01, 0.786, 0.95);
    // R: wilcox.test(dx, dy, paired=TRUE, alternative="less", conf.int=TRUE)
    paired.alternative = Alternative::Less;
    expectCi(wilcoxonTestCi(kDx, kDy, paired), -INFINITY, 0.726, 0.95);
    // R: wilcox.test(dx, mu=1.5, conf.int=TRUE)
    WilcoxonOptions one;
    one.mu = 1.5;
    const auto o = wilcoxonTestCi(kDx, one);
    expectRel(o.p, 0.25);
    expectRel(o.estimate[0].value, 1.725);
    expectCi(o, 1.165, 2.37, 0.95);
    // R: wilcox.test(rx, ry, conf.int=TRUE)
    const auto t = wilcoxonTestCi(kRx, kRy);
    expectRel(t.statistic, 35);
    expectRel(t.p, 0.254412254412254);
    EXPECT_EQ(t.estimate[0].name, "difference in location");
    expectRel(t.estimate[0].value, 0.305);
    expectCi(t, -0.15, 0.76, 0.95);
    // R: wilcox.test(rx, ry, alternative="greater", conf.int=TRUE, conf.level=0.9)
    WilcoxonOptions greater;
    greater.alternative = Alternative::Greater;
    const auto g = wilcoxonTestCi(kRx, kRy, greater, 0.9);
    expectRel(g.p, 0.127206127206127);
    expectCi(g, -0.05, INFINITY, 0.9);
}

TEST(WilcoxonCi, UnachievableLevelIsLoweredWithRsWarning) {
    // R: wilcox.test(c(1.1,2.2,3.3), conf.int=TRUE) -> conf.level 0.75, warning
    const auto r = wilcoxonTestCi(std::vector<double>{1.1, 2.2, 3.3});
    expectRel(r.estimate[0].value, 2.2);
    expectCi(r, 1.1, 3.3, 0.75);
    ASSERT_FALSE(r.warnings.empty());
    EXPECT_EQ(r.warnings.back(), "requested conf.level not achievable");
}

TEST(WilcoxonCi, TiesInvertTheNormalApproximationAsR) {
    // Roots come from uniroot(tol = 1e-4): R and we take the same Brent steps (R's zeroin), so the
    // figures agree far beyond the 1e-4 tolerance.
    const double rel = 1e-9;
    // R: wilcox.test(a, b, conf.int=TRUE)
    const auto two = wilcoxonTestCi(kA, kB);
    expectRel(two.statistic, 122.5);
    expectRel(two.p, 0.00311316456638527);
    expectRel(two.estimate[0].value, 1.99996366797538, rel);
    expectCi(two, 0.999977916809077, 2.99999069019119, 0.95, rel);
    EXPECT_EQ(two.warnings.back(), "cannot compute exact confidence interval with ties");
    // R: wilcox.test(a, b, conf.int=TRUE, alternative="less")
    WilcoxonOptions less;
    less.alternative = Alternative::Less;
    const auto l = wilcoxonTestCi(kA, kB, less);
    expectRel(l.p, 0.998717068102475);
    expectCi(l, -INFINITY, 2.00002981738013, 0.95, rel);
    // R: wilcox.test(a, b, paired=TRUE, conf.int=TRUE)
    WilcoxonOptions paired;
    paired.pairing = Pairing::Paired;
    const auto p = wilcoxonTestCi(kA, kB, paired);
    expectRel(p.statistic, 45);
    expectRel(p.p, 0.00714009700956929);
    expectRel(p.estimate[0].value, 2.00000199741038, rel);
    expectCi(p, 1.50002620796399, 2.99994307862413, 0.95, rel);
    // R: wilcox.test(s1, s2, paired=TRUE, conf.int=TRUE)
    const auto s = wilcoxonTestCi(kSleep1, kSleep2, paired);
    expectRel(s.p, 0.00909069801592506);
    expectRel(s.estimate[0].value, -1.40003067218735, rel);
    expectCi(s, -2.94992079954078, -1.05001799066454, 0.95, rel);
    // R's warnings, in R's order
    const std::vector<std::string> warnings{"cannot compute exact p-value with ties",
                                            "cannot compute exact confidence interval with ties",
                                            "cannot compute exact p-value with zeroes",
                                            "cannot compute exact confidence interval with zeroes"};
    EXPECT_EQ(s.warnings, warnings);
}

TEST(WilcoxonCi, ForcedNormalApproximationWithoutTies) {
    const double rel = 1e-9;
    // R: wilcox.test(rx, ry, exact=FALSE, correct=FALSE, conf.int=TRUE)
    WilcoxonOptions o;
    o.exactness = Exactness::Approximate;
    o.continuity = Continuity::Uncorrected;
    const auto r = wilcoxonTestCi(kRx, kRy, o);
    expectRel(r.p, 0.220671361919847);
    expectRel(r.estimate[0].value, 0.302508339041572, rel);
    expectCi(r, -0.149980846290111, 0.759975066221572, 0.95, rel);
    // R: wilcox.test(dx, exact=FALSE, conf.int=TRUE, alternative="greater", mu=1)
    WilcoxonOptions g;
    g.exactness = Exactness::Approximate;
    g.alternative = Alternative::Greater;
    g.mu = 1;
    const auto one = wilcoxonTestCi(kDx, g);
    expectRel(one.statistic, 43);
    expectRel(one.p, 0.00890859437978936);
    expectRel(one.estimate[0].value, 1.72499667520037, rel);
    expectCi(one, 1.42496605617604, INFINITY, 0.95, rel);
}

// ---------------------------------------------------------------- JSON front end

TEST(StatHolesJson, NewTestsAreReachableThroughUnderfootStats) {
    using nlohmann::json;
    auto run = [](const char* test, const char* body) {
        const auto r = runStatsRequest(test, body);
        EXPECT_TRUE(r.ok) << r.json;
        return json::parse(r.json);
    };
    // R: fisher.test(matrix(c(3,1,4, 2,6,1), 2, byrow=TRUE))$p.value
    expectRel(run("fisher", R"({"table": [[3,1,4],[2,6,1]]})")["p"].get<double>(),
              0.0929658576717399, 1e-7);
    EXPECT_FALSE(
        runStatsRequest("fisher", R"({"table": [[3,1,4],[2,6,1]], "alternative": "less"})").ok);
    // R: cor.test(c(1,2,3,4), c(2,1,4,3))
    const auto pe = run("pearson", R"({"x": [1,2,3,4], "y": [2,1,4,3]})");
    expectRel(pe["p"].get<double>(), 0.4);
    expectRel(pe["conf_int"][0].get<double>(), -0.852932564694718);
    // R: cor.test(a, b, method="kendall", continuity=TRUE)
    const auto ke = run("kendall", R"({"x": [5,6,4,7,5,6,3,5,6,7,4,5],
                                       "y": [3,4,4,5,2,4,3,5,4,3,2,4], "continuity": true})");
    expectRel(ke["p"].get<double>(), 0.231302188045529);
    expectRel(ke["tau"].get<double>(), 0.320983337620978);
    // R: wilcox.test(rx, ry, conf.int=TRUE)
    const auto w = run("wilcoxon", R"({"x": [0.80,0.83,1.89,1.04,1.45,1.38,1.91,1.64,0.73,1.46],
                                       "y": [1.15,0.88,0.90,0.74,1.21], "conf_int": true})");
    expectRel(w["estimate"].get<double>(), 0.305);
    expectRel(w["conf_int"][1].get<double>(), 0.76);
    EXPECT_FALSE(runStatsRequest("wilcoxon", R"({"x": [1,2,3], "conf_level": 0.9})").ok);
}
