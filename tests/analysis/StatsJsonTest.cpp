// SPDX-License-Identifier: GPL-3.0-or-later
// The JSON front end of the tests (in process) and the `underfoot stats` / `underfoot analyze`
// commands end to end (the built program, found through UNDERFOOT_BINARY_DIR).
#include "analysis/io/StatsJson.h"
#include "analysis/io/TrialCsv.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

using namespace underfoot::analysis;
using nlohmann::json;

namespace {

json ok(const std::string& test, const std::string& request) {
    const auto r = runStatsRequest(test, request);
    EXPECT_TRUE(r.ok) << test << ": " << r.json;
    return json::parse(r.json);
}

std::string error(const std::string& test, const std::string& request) {
    const auto r = runStatsRequest(test, request);
    EXPECT_FALSE(r.ok) << test << ": " << r.json;
    return json::parse(r.json).at("error").get<std::string>();
}

} // namespace

TEST(StatsJson, ChisqDefaultsToYatesAndCanSwitchItOff) {
    // R: chisq.test(matrix(c(8,12,18,2),2,byrow=TRUE)) and correct=FALSE
    const auto r = ok("chisq", R"({"table": [[8,12],[18,2]]})");
    EXPECT_NEAR(r["statistic"].get<double>(), 8.9010989010989, 1e-12);
    EXPECT_EQ(r["df"].get<double>(), 1);
    EXPECT_NEAR(r["p"].get<double>(), 0.00284999090249869, 1e-15);
    EXPECT_EQ(r["statistic_name"], "X-squared");
    const auto u = ok("chisq", R"({"table": [[8,12],[18,2]], "correct": false})");
    EXPECT_NEAR(u["statistic"].get<double>(), 10.989010989011, 1e-11);
}

TEST(StatsJson, EveryTestAnswersWithRsNumbers) {
    // R: t.test(x, y, paired=TRUE) with the sleep data
    auto t = ok("t", R"({"x": [0.7,-1.6,-0.2,-1.2,-0.1,3.4,3.7,0.8,0.0,2.0],
                         "y": [1.9,0.8,1.1,0.1,-0.1,4.4,5.5,1.6,4.6,3.4], "paired": true})");
    EXPECT_EQ(t["method"], "Paired t-test");
    EXPECT_NEAR(t["p"].get<double>(), 0.00283289019738427, 1e-14);
    EXPECT_NEAR(t["conf_int"][0].get<double>(), -2.45988576327698, 1e-12);
    // R: wilcox.test(dx, dy, paired=TRUE) -> V = 40, p = 0.0390625
    auto w = ok("wilcoxon", R"({"x": [1.83,0.50,1.62,2.48,1.68,1.88,1.55,3.06,1.30],
                                "y": [0.878,0.647,0.598,2.05,1.06,1.29,1.06,3.14,1.29],
                                "paired": true})");
    EXPECT_EQ(w["statistic"].get<double>(), 40);
    EXPECT_NEAR(w["p"].get<double>(), 0.0390625, 1e-15);
    // R: fisher.test(matrix(c(8,12,18,2),2,byrow=TRUE), alternative="greater", conf.level=0.9)
    auto f = ok("fisher", R"({"table": [[8,12],[18,2]], "alternative": "greater",
                              "conf_level": 0.9})");
    EXPECT_NEAR(f["conf_int"][0].get<double>(), 0.0161328146758693, 1e-8);
    EXPECT_EQ(f["conf_int"][1], "Inf");
    // R: kruskal.test(list(k1, k2, k3))
    auto k = ok("kruskal", R"({"groups": [[2.9,3.0,2.5,2.6,3.2],[3.8,2.7,4.0,2.4],
                                          [2.8,3.4,3.7,2.2,2.0]]})");
    EXPECT_NEAR(k["statistic"].get<double>(), 0.771428571428572, 1e-12);
    // levene: df is an array (k - 1, N - k)
    auto l = ok("levene", R"({"groups": [[2.9,3.0,2.5,2.6,3.2],[3.8,2.7,4.0,2.4],
                                         [2.8,3.4,3.7,2.2,2.0]], "center": "mean"})");
    EXPECT_EQ(l["df"], json::array({2.0, 11.0}));
    EXPECT_NEAR(l["statistic"].get<double>(), 4.78146920806927, 1e-11);
    // R: friedman.test(...) 8 x 3 matrix
    auto fr = ok("friedman", R"({"y": [[5,4,7],[6,6,8],[3,5,4],[7,6,9],[4,4,6],[5,7,7],[6,5,8],
                                       [2,3,5]]})");
    EXPECT_NEAR(fr["statistic"].get<double>(), 8.89655172413793, 1e-12);
    // spearman reports rho
    auto s = ok("spearman", R"({"x": [4.1,2.3,5.6,3.3,1.9,6.2,2.8],
                                "y": [3.0,2.9,4.8,3.9,1.1,5.0,2.0]})");
    EXPECT_NEAR(s["rho"].get<double>(), 0.928571428571428, 1e-12);
    EXPECT_NEAR(s["p"].get<double>(), 0.00674603174603175, 1e-14);
    // R: p.adjust(c(0.01, NA, 0.04), "holm") -> 0.02, NA, 0.04
    auto p = ok("p_adjust", R"({"p": [0.01, null, 0.04], "method": "holm"})");
    EXPECT_NEAR(p["adjusted"][0].get<double>(), 0.02, 1e-15);
    EXPECT_TRUE(p["adjusted"][1].is_null());
    // R: shapiro.test(c(1,2,4))
    auto sh = ok("shapiro", R"({"x": [1,2,4]})");
    EXPECT_NEAR(sh["statistic"].get<double>(), 0.964285714285714, 1e-12);
    // R: binom.test(682, 925, p=0.75)
    auto b = ok("binom", R"({"x": 682, "n": 925, "p": 0.75})");
    EXPECT_NEAR(b["conf_int"][1].get<double>(), 0.765406558241525, 1e-12);
    // R: prop.test(c(83,90,129,70), c(86,93,136,82))
    auto pr = ok("prop", R"({"x": [83,90,129,70], "n": [86,93,136,82]})");
    EXPECT_NEAR(pr["statistic"].get<double>(), 12.6004112971276, 1e-11);
    EXPECT_EQ(pr["estimate"].size(), 4u);
    // R: chisq.test(c(89,37,30,28,2), p=c(40,20,20,15,5)/100)
    auto g = ok("chisq_gof", R"({"x": [89,37,30,28,2], "p": [0.40,0.20,0.20,0.15,0.05]})");
    EXPECT_NEAR(g["p"].get<double>(), 0.0405940433447812, 1e-14);
    // R: prop.test(8, 20, correct=FALSE)$conf.int
    auto wi = ok("wilson", R"({"x": 8, "n": 20})");
    EXPECT_NEAR(wi["conf_int"][0].get<double>(), 0.218806532372817, 1e-12);
}

TEST(StatsJson, NaNResultsAreNullAndErrorsCarryRsMessage) {
    // R: wilcox.test(c(0,0,0)) -> p-value NaN
    auto z = ok("wilcoxon", R"({"x": [0,0,0]})");
    EXPECT_TRUE(z["p"].is_null());
    EXPECT_EQ(z["warnings"][0], "cannot compute exact p-value with zeroes");
    EXPECT_EQ(error("t", R"({"x": [2,2,2]})"), "data are essentially constant");
    EXPECT_EQ(error("shapiro", R"({"x": [1,2]})"), "sample size must be between 3 and 5000");
    EXPECT_NE(error("t", R"({"x": [1,2], "sd": 3})").find("unknown field 'sd'"), std::string::npos);
    EXPECT_NE(error("t", R"({"x": [1,"a"]})").find("'x[1]' must be a number"), std::string::npos);
    EXPECT_NE(error("t", R"({"y": [1,2]})").find("missing field 'x'"), std::string::npos);
    EXPECT_NE(error("anova", "{}").find("unknown test 'anova'"), std::string::npos);
    EXPECT_NE(error("t", "[1,2").find("invalid JSON"), std::string::npos);
    EXPECT_NE(error("t", R"({"x": [1,2], "alternative": "both"})").find("'alternative'"),
              std::string::npos);
    EXPECT_NE(error("p_adjust", R"({"p": [0.5, 1.5]})").find("between 0 and 1"), std::string::npos);
}

// ---------------------------------------------------------------- the program, end to end

namespace {

struct Run {
    int exitCode = -1;
    std::string out, err;
};

std::filesystem::path scratch() {
    auto dir = std::filesystem::temp_directory_path() /
               ("underfoot_analysis_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

/// Removes this process's scratch folder after the last test.
struct ScratchCleanup : ::testing::Environment {
    void TearDown() override {
        std::error_code ignored;
        std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                                        ("underfoot_analysis_test_" + std::to_string(::getpid())),
                                    ignored);
    }
};
[[maybe_unused]] const auto* const kCleanup =
    ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Run runProgram(const std::string& args, const std::string& input) {
    const std::filesystem::path program =
        std::filesystem::path(UNDERFOOT_BINARY_DIR) / "app" / "cli" / "underfoot";
    EXPECT_TRUE(std::filesystem::exists(program)) << "build the `underfoot` target first";
    const auto dir = scratch();
    { std::ofstream(dir / "stdin.txt", std::ios::binary) << input; }
    const std::string command =
        "'" + program.string() + "' " + args + " < '" + (dir / "stdin.txt").string() + "' > '" +
        (dir / "stdout.txt").string() + "' 2> '" + (dir / "stderr.txt").string() + "'";
    const int status = std::system(command.c_str());
    Run r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(dir / "stdout.txt");
    r.err = slurp(dir / "stderr.txt");
    return r;
}

} // namespace

TEST(StatsCommand, ReadsJsonOnStdinAndPrintsOneJsonObject) {
    const auto r = runProgram("stats chisq", R"({"table": [[10,10],[18,2]]})");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = json::parse(r.out);
    // R: chisq.test(matrix(c(10,10,18,2),2,byrow=TRUE)) -> 5.8333, p = 0.01573
    EXPECT_NEAR(j["statistic"].get<double>(), 5.83333333333333, 1e-12);
    EXPECT_NEAR(j["p"].get<double>(), 0.0157252997545054, 1e-15);
    EXPECT_EQ(r.out.back(), '\n');
}

TEST(StatsCommand, ErrorsExitNonZeroWithAnErrorObject) {
    const auto r = runProgram("stats t", R"({"x": [1]})");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_EQ(json::parse(r.out).at("error"), "not enough 'x' observations");
    const auto bad = runProgram("stats t", "not json");
    EXPECT_NE(bad.exitCode, 0);
    EXPECT_TRUE(json::parse(bad.out).contains("error"));
}

TEST(AnalyzeCommand, TrialCsvBecomesAnHtmlReport) {
    std::vector<TrialRecord> trials;
    for (int i = 0; i < 20; ++i)
        for (const char* group : {"audio", "audiohaptic"}) {
            TrialRecord t;
            t.participant = std::string(group) + std::to_string(i / 2);
            t.group = group;
            t.surfaceId = "gravel";
            t.stimulusId = "gravel";
            const bool audio = group == std::string("audio");
            t.answerId = (audio ? i < 8 : i < 18) ? "gravel" : "dirt_pebbles";
            t.realism = 3 + (i % 4);
            t.quality = 2 + (i % 5);
            trials.push_back(t);
        }
    const auto dir = scratch();
    std::ofstream(dir / "trials.csv", std::ios::binary) << formatTrialCsv(trials);
    const auto out = dir / "report.html";
    const auto r = runProgram("analyze --trials '" + (dir / "trials.csv").string() +
                                  "' --by group --format html -o '" + out.string() + "'",
                              "");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string html = slurp(out);
    EXPECT_NE(html.find("<svg "), std::string::npos);
    EXPECT_NE(html.find("X² = 8.9011"), std::string::npos);
    EXPECT_NE(html.find("Confusion matrix, audiohaptic"), std::string::npos);
    // tidy CSV on stdout
    const auto csvRun = runProgram(
        "analyze --trials '" + (dir / "trials.csv").string() + "' --by group --format csv", "");
    ASSERT_EQ(csvRun.exitCode, 0) << csvRun.err;
    EXPECT_EQ(csvRun.out.rfind("table,group,stimulus,soundscape,column,statistic,value,note", 0),
              0u);
}

TEST(AnalyzeCommand, BadInputIsReportedWithFileAndLine) {
    const auto dir = scratch();
    std::ofstream(dir / "broken.csv", std::ios::binary) << "participant,group\nP1,A\n";
    const auto r = runProgram("analyze --trials '" + (dir / "broken.csv").string() + "'", "");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("broken.csv:1: missing required columns"), std::string::npos) << r.err;
    const auto none = runProgram("analyze", "");
    EXPECT_NE(none.exitCode, 0);
    const auto format = runProgram("analyze --counts x.csv --format pdf", "");
    EXPECT_NE(format.err.find("--format pdf"), std::string::npos) << format.err;
}

TEST(StatsJson, PairwiseWilcoxonAdjustsAllPairsTogether) {
    // R: pairwise.wilcox.test(x, g, paired=TRUE, p.adjust.method="holm") (see StatTestsTest)
    const auto r = ok("pairwise_wilcoxon", R"({"groups": [[6.1,5.2,7.3,4.8,6.6,5.9,7.0,6.4,5.5,6.8],
        [5.0,5.1,6.2,4.1,6.0,5.3,6.1,5.7,5.6,5.9], [7.2,6.0,7.9,5.5,7.1,6.9,7.6,7.7,6.3,7.4]],
        "paired": true, "method": "holm"})");
    ASSERT_EQ(r["pairs"].size(), 3u);
    EXPECT_EQ(r["pairs"][0]["first"], 1);
    EXPECT_NEAR(r["pairs"][2]["p_adjusted"].get<double>(), 0.0175712972558524, 1e-14);
    EXPECT_NE(error("pairwise_wilcoxon", R"({"groups": [[1,2,3],[1,2]], "paired": true})")
                  .find("same length"),
              std::string::npos);
}

// A parse error says where (line and column), a wrong type or a missing field names
// the key.
TEST(StatsJson, ParseErrorsGiveLineAndColumn) {
    const std::string msg = error("chisq", "{\n  \"table\": [[1, 2],\n            [3, x]]\n}");
    EXPECT_NE(msg.find("line 3, column 17"), std::string::npos) << msg;
    EXPECT_NE(error("chisq", "").find("line 1, column 1"), std::string::npos);
    const auto pos = jsonErrorPosition("ab\ncd", 5);
    EXPECT_EQ(pos.first, 2u);
    EXPECT_EQ(pos.second, 2u);
}

TEST(StatsJson, WrongTypeAndMissingFieldNameTheKey) {
    EXPECT_NE(error("chisq", R"({"table": [[1, 2], [3, "x"]]})").find("'table[1][1]'"),
              std::string::npos);
    EXPECT_NE(error("chisq", R"({"table": 3})").find("'table'"), std::string::npos);
    EXPECT_NE(error("t", R"({"y": [1, 2]})").find("missing field 'x'"), std::string::npos);
    EXPECT_NE(error("binom", R"({"x": 3, "n": "ten"})").find("'n'"), std::string::npos);
    EXPECT_NE(error("t", R"({"x": [1, 2, 3], "paired": 1})").find("'paired'"), std::string::npos);
}
