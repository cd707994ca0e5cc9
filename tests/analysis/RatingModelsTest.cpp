// SPDX-License-Identifier: GPL-3.0-or-later
// Mixed models of a rating study's scales (the clmm and the LMM beside the Friedman test) and
// their place in every format of the rating report.
#include "analysis/ratings/RatingModels.h"
#include "analysis/report/RatingReport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace underfoot::analysis;

namespace {

/// 12 participants rate three stimuli twice on a 1..7 scale; "loud" is rated higher.
RatingData study(bool wholePoints = true) {
    RatingData d;
    d.title = "test";
    d.scales = {{"realism", "How real?", 1, 7, ""}};
    d.stimulusOrder = {"quiet", "medium", "loud"};
    std::mt19937_64 rng(3);
    std::normal_distribution<double> normal;
    for (int p = 0; p < 12; ++p) {
        const double bias = normal(rng);
        for (std::size_t s = 0; s < 3; ++s)
            for (int k = 0; k < 2; ++k) {
                double v = 3.5 + bias + 0.9 * static_cast<double>(s) + normal(rng);
                v = std::clamp(wholePoints ? std::round(v) : v, 1.0, 7.0);
                d.ratings.push_back(
                    {"p" + std::to_string(p), d.stimulusOrder[s], {}, "realism", v});
            }
    }
    return d;
}

} // namespace

TEST(RatingModels, ClmmAndLmmOfTheStimulusBesideFriedman) {
    const auto a = analyzeRatingStudy(study());
    ASSERT_EQ(a.scales.size(), 1u);
    const auto& m = a.scales[0].models;
    ASSERT_TRUE(m.fitted);
    EXPECT_EQ(m.ratings, 72u);
    ASSERT_TRUE(m.lmm.ok()) << m.lmm.error;
    ASSERT_TRUE(m.clmm.ok()) << m.clmm.error;
    EXPECT_EQ(m.clmm.lrt.df, 2);
    EXPECT_LT(m.clmm.lrt.p, 0.001); // a strong stimulus effect
    EXPECT_EQ(m.clmm.fixed.size(), 2u);
    EXPECT_EQ(m.clmm.fixed[0].name, "conditionmedium"); // the first stimulus is the reference
    EXPECT_GT(m.clmm.fixed[1].estimate, m.clmm.fixed[0].estimate);
    EXPECT_NE(m.advice.find("Which test to cite: the cumulative link mixed model"),
              std::string::npos);
}

TEST(RatingModels, ReportShowsTheModelsAndWhichToCiteInEveryFormat) {
    const auto a = analyzeRatingStudy(study());
    for (const auto f :
         {ReportFormat::Markdown, ReportFormat::Html, ReportFormat::Latex, ReportFormat::Csv}) {
        const std::string out = renderRatingReport(a, f, {});
        EXPECT_NE(out.find("Which test to cite: the cumulative link mixed model"),
                  std::string::npos)
            << static_cast<int>(f);
        if (f != ReportFormat::Csv) {
            EXPECT_NE(out.find("clmm (ordinal::clmm, logit, Laplace)"), std::string::npos);
            EXPECT_NE(out.find("LMM (lmerTest::lmer"), std::string::npos);
        } else {
            EXPECT_NE(out.find("model,realism,clmm,cite,lrt_p,"), std::string::npos);
            EXPECT_NE(out.find("model,realism,lmm,,lrt_p,"), std::string::npos);
        }
    }
}

TEST(RatingModels, ContinuousRatingsGetTheLmmAndSayWhyNoClmm) {
    const auto a = analyzeRatingStudy(study(false));
    const auto& m = a.scales[0].models;
    ASSERT_TRUE(m.lmm.ok());
    EXPECT_NE(m.clmmSkipped.find("not a whole point"), std::string::npos);
    EXPECT_NE(m.advice.find("no clmm"), std::string::npos);
}

TEST(RatingModels, CategoriesOfAScale) {
    std::string why;
    EXPECT_EQ(ratingCategories({1, 3, 7}, 1, 7, why).size(), 7u);
    EXPECT_TRUE(why.empty());
    EXPECT_TRUE(ratingCategories({1, 3.5}, 1, 7, why).empty());
    EXPECT_FALSE(why.empty());
    EXPECT_TRUE(ratingCategories({0.2}, 0, 1.5, why).empty());
}
