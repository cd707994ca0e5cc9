// SPDX-License-Identifier: GPL-3.0-or-later
// Mixed-effects models against R (lme4::glmer, lmerTest::lmer). The reference cases, with their
// data, the R call that produced each value and R's warnings, are in
// tests/analysis/data/mixed_models_reference.json, written by
//   Rscript tests/analysis/data/mixed_models_reference.R >
//   tests/analysis/data/mixed_models_reference.json
// (R 4.2.2, lme4 and lmerTest from Debian 12; versions recorded in the file).
// Tolerances: relative 1e-4 on estimates, standard errors, variances, log-likelihoods
// and statistics; relative 1e-3 on p-values and Satterthwaite df.
#include "analysis/stats/MixedModels.h"
#include "analysis/io/StatsJsonMixed.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

using namespace underfoot::analysis;
using nlohmann::json;

namespace {

const json& reference() {
    static const json j = [] {
        std::ifstream in(std::string(UNDERFOOT_SOURCE_DIR) +
                         "/tests/analysis/data/mixed_models_reference.json");
        return json::parse(in);
    }();
    return j;
}

std::vector<std::string> caseNames() {
    std::vector<std::string> names;
    for (const auto& c : reference().at("cases")) names.push_back(c.at("name").get<std::string>());
    return names;
}

const json& findCase(const std::string& name) {
    for (const auto& c : reference().at("cases"))
        if (c.at("name") == name) return c;
    throw std::runtime_error("no case " + name);
}

double value(const json& v) {
    return v.is_number() ? v.get<double>() : std::nan("");
}

/// |actual - expected| <= rel * |expected| + abs.
void expectClose(double actual, double expected, double rel, double abs, const std::string& what) {
    if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(actual)) << what << ": expected NaN, got " << actual;
        return;
    }
    EXPECT_NEAR(actual, expected, rel * std::fabs(expected) + abs)
        << what << ": expected " << expected << " got " << actual;
}

MixedModelData dataOf(const json& c) {
    MixedModelData d;
    const json& data = c.at("data");
    for (const auto& y : data.at("y")) d.y.push_back(y.get<double>());
    d.condition = data.at("condition").get<std::vector<std::string>>();
    d.participant = data.at("participant").get<std::vector<std::string>>();
    if (data.contains("surface")) d.surface = data.at("surface").get<std::vector<std::string>>();
    return d;
}

bool anyWarningContains(const MixedModelResult& r, const std::string& text) {
    for (const auto& w : r.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}

class MixedModelReference : public ::testing::TestWithParam<std::string> {};

TEST_P(MixedModelReference, MatchesR) {
    const json& c = findCase(GetParam());
    SCOPED_TRACE(c.at("call").get<std::string>());
    const bool glmm = c.at("kind") == "glmm";
    const MixedModelData data = dataOf(c);
    const MixedModelResult r =
        glmm ? fitLogisticMixedModel(data, c.at("nAGQ").get<int>()) : fitLinearMixedModel(data);
    if (c.contains("error")) {
        // R stopped: so do we, with R's message first.
        ASSERT_FALSE(r.ok()) << "R stopped with: " << c.at("error");
        std::string rMessage = c.at("error").get<std::string>();
        rMessage = rMessage.substr(0, rMessage.find(" ("));
        EXPECT_NE(r.error.find(rMessage.substr(0, 40)), std::string::npos)
            << "ours: " << r.error << "\nR: " << c.at("error");
        return;
    }
    ASSERT_TRUE(r.ok()) << r.error;
    const std::string compare = c.at("compare").get<std::string>();
    const bool singular = c.at("singular").get<bool>();
    // (on the flat ridge of a non-identified design, R's theta stops near the 1e-4 threshold)
    if (compare != "loglik" || GetParam().find("separation") != std::string::npos) {
        EXPECT_EQ(anyWarningContains(r, "boundary (singular) fit"), singular);
    }
    if (compare == "loglik") {
        // separation or one answer per participant: the estimates diverge or lie on a flat
        // ridge (R stops wherever its optimiser gives up); the log-likelihood tends to its
        // supremum and the LRT is stable.
        expectClose(r.logLik, value(c.at("loglik")), 0, 2e-3, "logLik");
        if (GetParam().find("separation") != std::string::npos) {
            EXPECT_TRUE(anyWarningContains(r, "separation"));
        }
        if (c.contains("lrt"))
            expectClose(r.lrt.statistic, value(c.at("lrt").at("statistic")), 0, 5e-3, "LRT");
        return;
    }
    const json& fixed = c.at("fixed");
    ASSERT_EQ(r.fixed.size(), fixed.size());
    for (std::size_t k = 0; k < fixed.size(); ++k) {
        const json& f = fixed[k];
        const auto& ours = r.fixed[k];
        const std::string name = f.at("name").get<std::string>();
        EXPECT_EQ(ours.name, name);
        const double se = value(f.at("se"));
        // relative 1e-4 (absolute floor 1e-4 SE for coefficients that are almost zero)
        expectClose(ours.estimate, value(f.at("estimate")), 1e-4, 1e-4 * se, name + " estimate");
        expectClose(ours.se, se, 1e-4, 0, name + " se");
        expectClose(ours.statistic, value(f.at("statistic")), 1e-4, 1e-4, name + " statistic");
        expectClose(ours.p, value(f.at("p")), 1e-3, 1e-12, name + " p");
        if (!glmm) expectClose(ours.df, value(f.at("df")), 1e-3, 0, name + " df");
    }
    expectClose(r.randomVariance, value(c.at("random_variance")), 1e-4, singular ? 1e-7 : 0,
                "random variance");
    if (!glmm)
        expectClose(r.residualVariance, value(c.at("residual_variance")), 1e-4, 0,
                    "residual variance");
    expectClose(r.logLik, value(c.at("loglik")), 1e-4, 1e-6, "logLik");
    expectClose(r.aic, value(c.at("aic")), 1e-4, 1e-6, "AIC");
    if (c.contains("lrt")) {
        expectClose(r.lrt.statistic, value(c.at("lrt").at("statistic")), 1e-4, 1e-5, "LRT");
        EXPECT_EQ(r.lrt.df, value(c.at("lrt").at("df")));
        expectClose(r.lrt.p, value(c.at("lrt").at("p")), 1e-3, 1e-9, "LRT p");
    }
}

INSTANTIATE_TEST_SUITE_P(R, MixedModelReference, ::testing::ValuesIn(caseNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

TEST(MixedModelReferenceFile, HasAtLeastSixtyCasesIncludingDegenerateOnes) {
    const auto& cases = reference().at("cases");
    EXPECT_GE(cases.size(), 60u);
    int errors = 0, singular = 0, separation = 0;
    for (const auto& c : cases) {
        errors += c.contains("error") ? 1 : 0;
        singular += c.value("singular", false) ? 1 : 0;
        separation += c.at("compare") == "loglik" ? 1 : 0;
    }
    EXPECT_GE(errors, 4);
    EXPECT_GE(singular, 3);
    EXPECT_GE(separation, 2);
}

TEST(GaussHermite, MatchesMomentsOfTheStandardNormal) {
    std::vector<double> z, w;
    gaussHermiteRule(10, z, w);
    double m0 = 0, m2 = 0, m4 = 0;
    for (std::size_t k = 0; k < z.size(); ++k) {
        m0 += w[k];
        m2 += w[k] * z[k] * z[k];
        m4 += w[k] * std::pow(z[k], 4);
    }
    EXPECT_NEAR(m0, 1.0, 1e-13);
    EXPECT_NEAR(m2, 1.0, 1e-12);
    EXPECT_NEAR(m4, 3.0, 1e-11);
}

TEST(MixedModelJson, AnswersGlmmRequestWithAllFields) {
    const auto& c = findCase("glmm_between_np12_nt4_laplace");
    json request{{"y", c.at("data").at("y")},
                 {"condition", c.at("data").at("condition")},
                 {"participant", c.at("data").at("participant")},
                 {"nAGQ", 1}};
    const auto response = runMixedModelRequest("glmm", request.dump());
    ASSERT_TRUE(response.ok) << response.json;
    const json out = json::parse(response.json);
    for (const char* key : {"fixed", "random_variance", "loglik", "aic", "lrt", "warnings"})
        EXPECT_TRUE(out.contains(key)) << key;
    expectClose(out.at("loglik").get<double>(), value(c.at("loglik")), 1e-4, 0, "loglik");
    EXPECT_EQ(out.at("fixed").size(), 2u);
    EXPECT_EQ(out.at("fixed")[1].at("name"), "conditionb");
}

TEST(MixedModelJson, NumericConditionsAreOrderedNumerically) {
    // levels 2 and 10: R's factor() of numbers orders them numerically (2 < 10)
    json request{{"y", {1, 2, 3, 4, 5, 6, 7, 9}},
                 {"condition", {2, 2, 10, 10, 2, 2, 10, 10}},
                 {"participant", {"a", "a", "a", "a", "b", "b", "b", "b"}}};
    const auto response = runMixedModelRequest("lmm", request.dump());
    ASSERT_TRUE(response.ok) << response.json;
    EXPECT_EQ(json::parse(response.json).at("fixed")[1].at("name"), "condition10");
}

TEST(MixedModelJson, RejectsBadRequestsWithClearMessages) {
    auto error = [](const char* test, const std::string& body) {
        const auto r = runMixedModelRequest(test, body);
        EXPECT_FALSE(r.ok);
        return json::parse(r.json).at("error").get<std::string>();
    };
    EXPECT_NE(error("glmm", R"({"y":[0,1],"condition":["a","b"]})").find("participant"),
              std::string::npos);
    EXPECT_NE(
        error("glmm", R"({"y":[0,2,1,0],"condition":["a","b","a","b"],"participant":[1,1,2,2]})")
            .find("0 (not correct) or 1"),
        std::string::npos);
    EXPECT_NE(error("glmm", R"({"y":[0,1],"condition":["a","b"],"participant":[1,2],"nAGQ":0})")
                  .find("nAGQ"),
              std::string::npos);
    EXPECT_NE(error("lmm", R"({"y":[0,1],"condition":["a","b"],"participant":[1,2],"bogus":1})")
                  .find("unknown field 'bogus'"),
              std::string::npos);
    EXPECT_NE(error("lmm", R"({"y":[0,1,2],"condition":["a","b"],"participant":[1,2,3]})")
                  .find("same length"),
              std::string::npos);
    EXPECT_NE(error("lmm", "{").find("invalid JSON"), std::string::npos);
}

TEST(MixedModels, MissingValuesAreDroppedAsRDoes) {
    const auto& c = findCase("lmm_between_np12_nt2");
    MixedModelData d = dataOf(c);
    const auto full = fitLinearMixedModel(d);
    d.y.push_back(std::nan(""));
    d.condition.push_back("a");
    d.participant.push_back("p01");
    const auto withMissing = fitLinearMixedModel(d);
    ASSERT_TRUE(withMissing.ok());
    EXPECT_EQ(withMissing.nObs, full.nObs);
    EXPECT_DOUBLE_EQ(withMissing.fixed[1].estimate, full.fixed[1].estimate);
}

} // namespace
