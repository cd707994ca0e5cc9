// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot stats TEST`: one JSON request on stdin, one JSON result on stdout (R-compatible
// tests of analysis/stats; see analysis/io/StatsJson.h for the fields).
#include "analysis/io/StatsJson.h"
#include "app/cli/CommandRegistry.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <cstdio>
#include <iostream>
#include <iterator>
#include <memory>
#include <string>

namespace underfoot::cli::stats_command {
namespace {

using namespace underfoot;

int runStats(const std::string& test) {
    std::string request((std::istreambuf_iterator<char>(std::cin)),
                        std::istreambuf_iterator<char>());
    const auto response = analysis::runStatsRequest(test, request);
    fmt::print("{}\n", response.json);
    std::fflush(stdout);
    return response.ok ? 0 : 2;
}

const cli::CommandRegistrar registrar("stats", [](CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand(
        "stats", "Run one statistical test (R-compatible): JSON request on stdin, JSON result on "
                 "stdout; errors exit non-zero with {\"error\": ...}");
    auto test = std::make_shared<std::string>();
    cmd->add_option("test", *test,
                    fmt::format("Test: {}", fmt::join(analysis::statsTestNames(), ", ")))
        ->required();
    cmd->footer(
        "Examples:\n"
        "  echo '{\"table\": [[8,12],[18,2]]}' | underfoot stats chisq\n"
        "  echo '{\"x\": [1.83,0.50,1.62], \"y\": [0.878,0.647,0.598], \"paired\": true}' | "
        "underfoot stats wilcoxon\n"
        "  echo '{\"y\": [1,0,1,1,0,1,1,1], \"condition\": "
        "[\"a\",\"a\",\"b\",\"b\",\"a\",\"a\",\"b\",\"b\"], "
        "\"participant\": [1,1,2,2,3,3,4,4], \"nAGQ\": 10}' | underfoot stats glmm\n"
        "  echo '{\"y\": [2,5,3,6,1,4,3,7], \"condition\": "
        "[\"a\",\"b\",\"a\",\"b\",\"a\",\"b\",\"a\",\"b\"], "
        "\"participant\": [1,1,2,2,3,3,4,4], \"levels\": [1,2,3,4,5,6,7]}' | underfoot stats clmm\n"
        "  (glmm / lmm / clmm: mixed models with a random intercept per participant, as "
        "lme4::glmer / lmerTest::lmer / ordinal::clmm; see docs/reference/statistics.md)");
    cmd->callback([&exitCode, test] { exitCode = runStats(*test); });
});

} // namespace
} // namespace underfoot::cli::stats_command
