// SPDX-License-Identifier: GPL-3.0-or-later
// The cumulative link mixed model against R's ordinal::clmm. The reference cases, with their
// data, the R call that produced each value and R's warnings, are in
// tests/analysis/data/ordinal_mixed_reference.json, written by
//   Rscript tests/analysis/data/ordinal_mixed_reference.R >
//   tests/analysis/data/ordinal_mixed_reference.json
// (R 4.2, ordinal 2022.11-16 from Debian 12's r-cran-ordinal; versions recorded in the file).
// Tolerances: relative 1e-4 on estimates, standard errors, variances, log-likelihoods and the
// LRT; relative 1e-3 on p-values (and on the SEs of the two cases whose R Hessian is noisy,
// "se_tolerance"). Where R's optimiser stops early (separation) our log-likelihood must be at
// least R's. For the cloglog link R's clmm is not a reference (see "exact" in the R script).
#include "analysis/stats/OrdinalMixed.h"
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
                         "/tests/analysis/data/ordinal_mixed_reference.json");
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

void expectClose(double actual, double expected, double rel, double abs, const std::string& what) {
    EXPECT_NEAR(actual, expected, rel * std::fabs(expected) + abs)
        << what << ": expected " << expected << " got " << actual;
}

std::vector<std::string> rWarnings(const json& c) {
    if (!c.contains("warnings") || c.at("warnings").is_null()) return {};
    if (c.at("warnings").is_string()) return {c.at("warnings").get<std::string>()};
    return c.at("warnings").get<std::vector<std::string>>();
}

bool anyWarningContains(const MixedModelResult& r, const std::string& text) {
    for (const auto& w : r.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}

OrdinalMixedResult fitCase(const json& c) {
    MixedModelData d;
    const json& data = c.at("data");
    for (const auto& y : data.at("y")) d.y.push_back(y.get<double>());
    d.condition = data.at("condition").get<std::vector<std::string>>();
    d.participant = data.at("participant").get<std::vector<std::string>>();
    if (data.contains("surface")) d.surface = data.at("surface").get<std::vector<std::string>>();
    OrdinalOptions o;
    o.nAGQ = c.at("nAGQ").get<int>();
    EXPECT_TRUE(parseOrdinalLink(c.at("link").get<std::string>(), o.link));
    if (data.contains("levels")) o.categories = data.at("levels").get<std::vector<double>>();
    return fitOrdinalMixedModel(d, o);
}

class OrdinalMixedReference : public ::testing::TestWithParam<std::string> {};

TEST_P(OrdinalMixedReference, MatchesR) {
    const json& c = findCase(GetParam());
    SCOPED_TRACE(c.at("call").get<std::string>());
    const OrdinalMixedResult r = fitCase(c);
    if (c.contains("error")) { // R stopped: so do we, naming R's message
        ASSERT_FALSE(r.ok()) << "R stopped with: " << c.at("error");
        EXPECT_NE(r.error.find(c.at("error").get<std::string>()), std::string::npos) << r.error;
        return;
    }
    ASSERT_TRUE(r.ok()) << r.error;
    const double rLogLik = value(c.at("loglik"));
    if (c.at("compare") == "loglik") {
        // separation: the estimate diverges; R stops where its optimiser gives up, we must be
        // at least as high, and say why
        EXPECT_GE(r.logLik, rLogLik - 1e-6);
        EXPECT_TRUE(anyWarningContains(r, "separation"));
        return;
    }
    if (c.at("compare") == "exact") {
        // cloglog: R's clmm reports a log-likelihood its estimates do not have (the exact
        // integral there, exact.loglik_at_clmm_estimates, is far lower); the reference is the
        // exact likelihood maximised in R by integrate() and nlminb. Laplace and few quadrature
        // points approximate it; 25 points match it.
        const json& ml = c.at("exact").at("ml");
        const bool tight = c.at("nAGQ").get<int>() >= 20;
        EXPECT_GT(r.logLik, value(c.at("exact").at("loglik_at_clmm_estimates")));
        expectClose(r.logLik, value(ml.at("loglik")), tight ? 1e-7 : 0, tight ? 0 : 0.1,
                    "exact logLik");
        const double rel = tight ? 1e-4 : 3e-2, abs = tight ? 1e-5 : 1e-2;
        for (std::size_t k = 0; k < r.thresholds.size(); ++k)
            expectClose(r.thresholds[k].estimate, value(ml.at("thresholds")[k]), rel, abs,
                        r.thresholds[k].name);
        const json fixed =
            ml.at("fixed").is_array() ? ml.at("fixed") : json::array({ml.at("fixed")});
        for (std::size_t k = 0; k < r.fixed.size(); ++k)
            expectClose(r.fixed[k].estimate, value(fixed[k]), rel, abs, r.fixed[k].name);
        expectClose(r.randomVariance, value(ml.at("random_variance")), tight ? 1e-4 : 0.1, abs,
                    "random variance");
        return;
    }
    const bool tinyVariance = value(c.at("random_variance")) < 1e-6;
    const double seTolerance = c.value("se_tolerance", 1e-4);
    expectClose(r.logLik, rLogLik, 1e-4, 1e-6, "logLik");
    EXPECT_GE(r.logLik, rLogLik - 1e-7) << "ours stops below R's maximum";
    expectClose(r.aic, value(c.at("aic")), 1e-4, 1e-6, "AIC");
    expectClose(r.randomVariance, value(c.at("random_variance")), 1e-4, tinyVariance ? 1e-6 : 0,
                "random variance");
    auto compare = [&](const std::vector<FixedEffect>& ours, const json& theirs, bool withP) {
        ASSERT_EQ(ours.size(), theirs.size());
        for (std::size_t k = 0; k < theirs.size(); ++k) {
            const json& f = theirs[k];
            const std::string name = f.at("name").get<std::string>();
            EXPECT_EQ(ours[k].name, name);
            const double se = value(f.at("se"));
            expectClose(ours[k].estimate, value(f.at("estimate")), 1e-4,
                        std::isnan(se) ? 1e-4 : 1e-4 * se, name + " estimate");
            if (std::isnan(se)) { // R: "Variance-covariance matrix ... not defined"
                EXPECT_TRUE(tinyVariance) << name;
                continue;
            }
            expectClose(ours[k].se, se, seTolerance, 0, name + " se");
            expectClose(ours[k].statistic, value(f.at("statistic")), seTolerance, 1e-4,
                        name + " statistic");
            if (withP) expectClose(ours[k].p, value(f.at("p")), 1e-3, 1e-12, name + " p");
        }
    };
    compare(r.thresholds, c.at("thresholds"), false);
    compare(r.fixed, c.at("fixed"), true);
    if (tinyVariance) {
        EXPECT_TRUE(anyWarningContains(r, "variance estimated at 0"));
    }
    for (const auto& w : rWarnings(c)) {
        if (w.find("Variance-covariance matrix") != std::string::npos) {
            EXPECT_TRUE(anyWarningContains(r, "Variance-covariance matrix")) << w;
        }
    }
    if (c.at("data").contains("levels") &&
        c.at("data").at("levels").size() > c.at("thresholds").size() + 1) {
        EXPECT_TRUE(anyWarningContains(r, "never used"));
    }
    if (c.contains("lrt")) {
        expectClose(r.lrt.statistic, value(c.at("lrt").at("statistic")), 1e-4, 1e-5, "LRT");
        EXPECT_EQ(r.lrt.df, value(c.at("lrt").at("df")));
        expectClose(r.lrt.p, value(c.at("lrt").at("p")), 1e-3, 1e-9, "LRT p");
    }
}

INSTANTIATE_TEST_SUITE_P(R, OrdinalMixedReference, ::testing::ValuesIn(caseNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

TEST(OrdinalMixedReferenceFile, CoversLinksQuadratureAndDegenerateCases) {
    int degenerate = 0, agq = 0, probit = 0, cloglog = 0;
    for (const auto& c : reference().at("cases")) {
        degenerate += c.at("name").get<std::string>().rfind("degenerate", 0) == 0 ? 1 : 0;
        agq += c.at("nAGQ").get<int>() > 1 ? 1 : 0;
        probit += c.at("link") == "probit" ? 1 : 0;
        cloglog += c.at("link") == "cloglog" ? 1 : 0;
    }
    EXPECT_GE(reference().at("cases").size(), 20u);
    EXPECT_GE(degenerate, 7);
    EXPECT_GE(agq, 5);
    EXPECT_GE(probit, 2);
    EXPECT_GE(cloglog, 2);
}

TEST(OrdinalMixed, FitWithoutStandardErrorsGivesTheSameOptimum) {
    const json& c = findCase("within_np10_r3_logit_laplace");
    MixedModelData d;
    for (const auto& y : c.at("data").at("y")) d.y.push_back(y.get<double>());
    d.condition = c.at("data").at("condition").get<std::vector<std::string>>();
    d.participant = c.at("data").at("participant").get<std::vector<std::string>>();
    OrdinalOptions o;
    o.standardErrors = false;
    const auto r = fitOrdinalMixedModel(d, o);
    ASSERT_TRUE(r.ok());
    expectClose(r.logLik, value(c.at("loglik")), 1e-6, 0, "logLik");
    EXPECT_TRUE(std::isnan(r.fixed[0].se));
    expectClose(r.lrt.statistic, value(c.at("lrt").at("statistic")), 1e-4, 1e-5, "LRT");
}

TEST(OrdinalMixedJson, AnswersClmmRequestWithThresholds) {
    const auto& c = findCase("within_np10_r3_probit_laplace");
    json request{{"y", c.at("data").at("y")},
                 {"condition", c.at("data").at("condition")},
                 {"participant", c.at("data").at("participant")},
                 {"link", "probit"},
                 {"levels", {1, 2, 3, 4, 5, 6, 7}}};
    const auto response = runMixedModelRequest("clmm", request.dump());
    ASSERT_TRUE(response.ok) << response.json;
    const json out = json::parse(response.json);
    for (const char* key : {"fixed", "thresholds", "random_variance", "loglik", "aic", "lrt",
                            "warnings", "link", "nAGQ"})
        EXPECT_TRUE(out.contains(key)) << key;
    expectClose(out.at("loglik").get<double>(), value(c.at("loglik")), 1e-4, 0, "loglik");
    ASSERT_EQ(out.at("thresholds").size(), 6u);
    EXPECT_EQ(out.at("thresholds")[0].at("name"), "1|2");
    EXPECT_EQ(out.at("fixed")[0].at("name"), "conditionb");
}

TEST(OrdinalMixedJson, RejectsBadRequestsWithClearMessages) {
    auto error = [](const std::string& body) {
        const auto r = runMixedModelRequest("clmm", body);
        EXPECT_FALSE(r.ok);
        return json::parse(r.json).at("error").get<std::string>();
    };
    const std::string base = R"("condition":["a","b","a","b"],"participant":[1,1,2,2])";
    EXPECT_NE(error(R"({"y":[1,2,3,4],)" + base + R"(,"link":"cauchit"})").find("link"),
              std::string::npos);
    EXPECT_NE(error(R"({"y":[1,2,3,9],)" + base + R"(,"levels":[1,2,3,4]})").find("not one of"),
              std::string::npos);
    EXPECT_NE(error(R"({"y":[1,2,3,4],)" + base + R"(,"levels":[3,2,1]})").find("increasing"),
              std::string::npos);
    EXPECT_NE(error(R"({"y":[3,3,3,3],)" + base + "}").find("one category"), std::string::npos);
    EXPECT_NE(error(R"({"y":[1,2,3,4],)" + base + R"(,"nAGQ":26})").find("nAGQ"),
              std::string::npos);
    // cloglog, every category once and the levels apart: a probability underflows to 0
    const auto r = runMixedModelRequest(
        "clmm", R"({"y":[1,2,3,4,5,6,7,8],"condition":["a","a","a","a","b","b","b","b"],)"
                R"("participant":[1,2,3,4,1,2,3,4],"nAGQ":25,"link":"cloglog"})");
    if (!r.ok) {
        EXPECT_NE(json::parse(r.json).at("error").get<std::string>().find("not finite"),
                  std::string::npos);
    } else {
        EXPECT_TRUE(json::parse(r.json).at("loglik").is_number()) << r.json;
    }
}

} // namespace
