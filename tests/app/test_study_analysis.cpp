// SPDX-License-Identifier: GPL-3.0-or-later
// One analysis set-up for every front end (app/wiring/StudyAnalysis.h): `underfoot analyze
// --study` prints the report the console's Results view computes (wiring::analyzeStudy with the
// simulated participants the console shows), the protocol's design decides the group split, the
// command line only overrides it (--by none), and the per-stimulus caption names only the columns
// the table holds. Studies are made and simulated by the program itself.
#include "analysis/report/Export.h"
#include "app/wiring/StudyAnalysis.h"
#include "base/Plural.h"
#include "experiment/Store.h"
#include "tests/common/ReadFile.h"
#include "tests/common/ScratchDir.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace an = underfoot::analysis;
namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;

using underfoot::test::readFile;

namespace {

/// Runs the program with `args` (stdout to `out`, stderr to `err`); fails the test on a non-zero
/// exit.
void run(const std::string& args, const fs::path& out, const fs::path& err) {
    const std::string command =
        fmt::format("'{}' {} > '{}' 2> '{}'", UNDERFOOT_CLI, args, out.string(), err.string());
    ASSERT_EQ(std::system(command.c_str()), 0) << command << "\n" << readFile(err);
}

/// A study of the shipped protocol `name` with `participants` simulated participants.
fs::path simulatedStudy(const std::string& name, int participants) {
    const fs::path dir = underfoot::test::scratchDir("study_analysis");
    const fs::path db = dir / fmt::format("{}_{}.db", name, participants);
    if (fs::exists(db)) return db;
    const fs::path log = dir / "make.txt";
    run(fmt::format("study create --study '{}' --protocol '{}/protocols/{}.toml' --code X "
                    "--seed 3",
                    db.string(), UNDERFOOT_SOURCE_DIR, name),
        log, log);
    run(fmt::format("session --study '{}' --simulate --participants {}", db.string(), participants),
        log, log);
    return db;
}

std::string cliMarkdown(const fs::path& db, const std::string& extra, fs::path* errOut = nullptr) {
    const fs::path dir = underfoot::test::scratchDir("study_analysis");
    const fs::path out = dir / "analysis.md", err = dir / "analysis.err";
    run(fmt::format("analyze --study '{}' --format markdown {}", db.string(), extra), out, err);
    if (errOut) *errOut = err;
    return readFile(out);
}

wir::StudyAnalysisOverrides withSimulated() {
    wir::StudyAnalysisOverrides o;
    o.includeSimulated = true;
    return o;
}

} // namespace

TEST(StudyAnalysis, CliAndConsoleReportTheSameComparisonsOfABetweenGroupStudy) {
    const fs::path db = simulatedStudy("tvcg2011_exp2", 12);
    const auto store = xp::StudyStore::openForReading(db.string());
    const auto report = wir::analyzeStudy(store, withSimulated());
    // The design is between participants: groups compared, with mixed models on the ratings.
    ASSERT_FALSE(report.comparisons.empty());
    bool clmmRealism = false, clmmQuality = false, glmer = false;
    for (const auto& m : report.mixedModels) {
        const std::string measure = an::measureName(m.measure);
        clmmRealism |= m.model.starts_with("clmm") && measure.find("realism") != std::string::npos;
        clmmQuality |= m.model.starts_with("clmm") && measure.find("quality") != std::string::npos;
        glmer |= m.model.starts_with("glmer");
    }
    EXPECT_TRUE(clmmRealism);
    EXPECT_TRUE(clmmQuality);
    EXPECT_TRUE(glmer);
    // The groups in the protocol's order.
    std::vector<std::string> protocolOrder;
    for (const auto& g : store.protocol().groups) protocolOrder.push_back(g.id);
    EXPECT_EQ(report.groups, protocolOrder);
    // The command line, with no flag but --include-simulated, prints the very same report.
    const std::string cli = cliMarkdown(db, "--include-simulated");
    EXPECT_EQ(cli, an::renderReport(report, an::ReportFormat::Markdown));
    EXPECT_NE(cli.find("| realism | all | none vs coherent | clmm"), std::string::npos) << cli;
    EXPECT_NE(cli.find("| quality | all | none vs coherent | clmm"), std::string::npos) << cli;
}

TEST(StudyAnalysis, CommandLineOverridesTheStudysDefaults) {
    const fs::path db = simulatedStudy("tvcg2011_exp2", 12);
    const auto store = xp::StudyStore::openForReading(db.string());
    auto pooled = withSimulated();
    pooled.byGroup = false;
    pooled.title = "Pooled";
    const auto report = wir::analyzeStudy(store, pooled);
    EXPECT_TRUE(report.comparisons.empty());
    EXPECT_TRUE(report.mixedModels.empty());
    EXPECT_EQ(report.title, "Pooled");
    EXPECT_EQ(cliMarkdown(db, "--include-simulated --by none --title Pooled"),
              an::renderReport(report, an::ReportFormat::Markdown));

    // The defaults: the protocol's design, group order and answer sheet, "I don't know" last.
    const auto options = wir::studyAnalysisOptions(store.protocol());
    EXPECT_TRUE(options.byGroup);
    ASSERT_EQ(options.answers.options.size(), store.protocol().questions.surfaceOptions.size());
    EXPECT_EQ(options.answers.options.back().id, an::kDontKnowId);
    EXPECT_EQ(options.answers.options.front().id,
              store.protocol().questions.surfaceOptions.front().id);
}

TEST(StudyAnalysis, SummaryCaptionNamesOnlyTheColumnsItHolds) {
    // TVCG 2011 exp. 1 asks for the surface only: no realism, no quality, no soundscape.
    const std::string plain =
        cliMarkdown(simulatedStudy("tvcg2011_exp1", 1), "--include-simulated");
    const auto caption = plain.find("**Per-stimulus summary");
    ASSERT_NE(caption, std::string::npos) << plain;
    const std::string line = plain.substr(caption, plain.find('\n', caption) - caption);
    EXPECT_EQ(line.find("realism"), std::string::npos) << line;
    EXPECT_EQ(line.find("quality"), std::string::npos) << line;
    EXPECT_EQ(line.find("soundscape"), std::string::npos) << line;
    // exp. 2 rates realism and quality and asks for the soundscape: all three are named.
    const std::string rated =
        cliMarkdown(simulatedStudy("tvcg2011_exp2", 12), "--include-simulated");
    const auto at = rated.find("**Per-stimulus summary");
    ASSERT_NE(at, std::string::npos);
    const std::string full = rated.substr(at, rated.find('\n', at) - at);
    EXPECT_NE(full.find("realism on correct answers only"), std::string::npos) << full;
    EXPECT_NE(full.find("% soundscape"), std::string::npos) << full;
}

TEST(StudyAnalysis, LeftOutParticipantsAreCountedInWords) {
    for (const int n : {1, 2}) {
        fs::path err;
        cliMarkdown(simulatedStudy("tvcg2011_exp1", n), "", &err);
        const std::string expected =
            fmt::format("analyze: {} left out", underfoot::counted(n, "simulated participant"));
        EXPECT_NE(readFile(err).find(expected), std::string::npos) << readFile(err);
        EXPECT_EQ(readFile(err).find("(s)"), std::string::npos) << readFile(err);
    }
    EXPECT_EQ(underfoot::counted(1, "simulated participant"), "1 simulated participant");
    EXPECT_EQ(underfoot::counted(2, "simulated participant"), "2 simulated participants");
}
