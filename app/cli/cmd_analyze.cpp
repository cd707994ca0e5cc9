// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot analyze`: confusion matrices, summaries and between-group tests of a study, from the
// long-format trial CSV of `underfoot export` or from published count tables.
#include "analysis/io/CountTables.h"
#include "analysis/io/TrialCsv.h"
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/Export.h"
#include "analysis/report/Markup.h"
#include "analysis/report/MixedModelReport.h"
#include "analysis/report/RatingReport.h"
#include "analysis/tables/Tables.h"
#include "app/cli/CommandRegistry.h"
#include "app/wiring/StudyAnalysis.h"
#include "base/Plural.h"

#include "experiment/Export.h"
#include "experiment/Store.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

namespace underfoot::cli::analyze_command {
namespace {

using namespace underfoot;

struct AnalyzeOptions {
    std::string study;
    std::string trials;
    std::vector<std::string> counts;
    std::vector<double> presentations;
    std::string by;
    std::string format = "markdown";
    std::string output;
    std::string title;
    std::vector<std::string> groupOrder;
    std::vector<std::string> answers;
    bool poolSoundscapes = false;
    double confLevel = 0.95;
    std::string form = "auto";
    std::string ratings;
    std::string participants;
    std::string scales;
    std::vector<std::string> groupFields;
    bool includeSimulated = false;
};

/// Says on standard error who of the study's participants are simulated and whether they are
/// analysed.
void noteSimulated(const AnalyzeOptions& o, const experiment::StudyStore& store, int analysed,
                   int total) {
    if (o.includeSimulated) {
        if (analysed > 0)
            fmt::print(stderr, "analyze: {}\n", analysis::markup::simulatedNotice(analysed, total));
        return;
    }
    const int simulated = wiring::simulatedParticipants(store);
    if (simulated > 0)
        fmt::print(stderr, "analyze: {} left out (--include-simulated keeps them)\n",
                   counted(simulated, "simulated participant"));
}

/// The study's defaults with what the command line asked for.
wiring::StudyAnalysisOverrides overridesOf(const AnalyzeOptions& o) {
    wiring::StudyAnalysisOverrides w;
    if (o.by == "group") w.byGroup = true;
    if (o.by == "none") w.byGroup = false;
    w.groupOrder = o.groupOrder;
    w.poolSoundscapes = o.poolSoundscapes;
    w.confLevel = o.confLevel;
    w.includeSimulated = o.includeSimulated;
    w.title = o.title;
    w.ratingGroupFields = o.groupFields;
    return w;
}

void writeText(const std::string& output, const std::string& text) {
    if (output.empty() || output == "-") {
        fmt::print("{}", text);
        return;
    }
    std::ofstream out(output, std::ios::binary);
    if (!out) throw cli::UserError(fmt::format("{}: cannot open for writing", output));
    out << text;
    if (!out.flush()) throw cli::UserError(fmt::format("{}: write failed", output));
}

/// Rating studies (the wading studies and any protocol of scales): the paper's form.
int analyzeRatings(const AnalyzeOptions& o, analysis::ReportFormat format) {
    try {
        auto overrides = overridesOf(o);
        wiring::StudyRatings ratings;
        if (!o.study.empty()) {
            const auto store = experiment::StudyStore::openForReading(o.study);
            ratings = wiring::studyRatings(store, overrides);
            noteSimulated(o, store, ratings.labels.simulatedParticipants, 0);
        } else if (!o.ratings.empty()) {
            ratings.data = analysis::readRatingData(o.ratings, o.participants, o.scales);
            if (!o.title.empty()) ratings.data.title = o.title;
        } else {
            throw cli::UserError("--form ratings needs --study FILE or --ratings FILE (the "
                                 "ratings CSV of `underfoot export`)");
        }
        const auto result = wiring::analyzeRatings(ratings, overrides);
        writeText(o.output, analysis::renderRatingReport(result, format, ratings.labels));
    } catch (const std::runtime_error& e) {
        throw cli::UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw cli::UserError(e.what());
    }
    return 0;
}

int analyze(const AnalyzeOptions& o) {
    if (o.form != "auto" && o.form != "identification" && o.form != "ratings" && o.form != "wading")
        throw cli::UserError(fmt::format("--form {}: expected auto, identification, ratings or "
                                         "wading",
                                         o.form));
    bool ratingsForm = o.form == "ratings" || o.form == "wading" || !o.ratings.empty();
    if (o.form == "auto" && !o.study.empty()) {
        // A protocol that only rates (no surface question) is analysed in the paper's form.
        try {
            const auto store = experiment::StudyStore::openForReading(o.study);
            ratingsForm = wiring::isRatingStudy(store.protocol());
        } catch (const std::runtime_error& e) {
            throw cli::UserError(e.what());
        }
    }
    if (ratingsForm) {
        const auto format = analysis::parseReportFormat(o.format);
        if (!format)
            throw cli::UserError(
                fmt::format("--format {}: expected csv, latex, markdown or html", o.format));
        if (int(!o.study.empty()) + int(!o.ratings.empty()) != 1 || !o.trials.empty() ||
            !o.counts.empty())
            throw cli::UserError("a rating analysis takes one source: --study FILE or --ratings "
                                 "FILE [--participants FILE] [--scales FILE]");
        return analyzeRatings(o, *format);
    }
    if (int(!o.study.empty()) + int(!o.trials.empty()) + int(!o.counts.empty()) != 1)
        throw cli::UserError(
            "give one source: --study FILE (a study store), --trials FILE or --counts FILE...");
    if (!o.by.empty() && o.by != "group" && o.by != "none")
        throw cli::UserError(fmt::format("--by {}: expected group or none", o.by));
    const auto format = analysis::parseReportFormat(o.format);
    if (!format)
        throw cli::UserError(
            fmt::format("--format {}: expected csv, latex, markdown or html", o.format));
    if (!(o.confLevel > 0 && o.confLevel < 1))
        throw cli::UserError(
            fmt::format("--conf-level {}: expected a number in (0, 1)", o.confLevel));
    if (!o.presentations.empty() && o.presentations.size() != 1 &&
        o.presentations.size() != o.counts.size())
        throw cli::UserError(
            "--presentations: give one value for all --counts files or one per file");
    for (double p : o.presentations)
        if (!(p > 0) || p != std::floor(p))
            throw cli::UserError(fmt::format("--presentations {}: expected a positive integer", p));

    auto overrides = overridesOf(o);
    if (!o.answers.empty()) {
        analysis::AnswerList answers;
        answers.options.clear();
        for (const auto& id : o.answers) {
            if (id.empty() || answers.indexOf(id) ||
                std::count(o.answers.begin(), o.answers.end(), id) > 1)
                throw cli::UserError(fmt::format(
                    "--answers: '{}' is empty or listed twice (expected answer ids)", id));
            if (id != analysis::kDontKnowId)
                answers.options.push_back({id, analysis::labelFor(id)});
        }
        // "I don't know" is always the last column
        answers.options.push_back(
            {std::string(analysis::kDontKnowId), analysis::labelFor(analysis::kDontKnowId)});
        overrides.answers = std::move(answers);
    }
    // A trial CSV or count tables have no protocol: no split unless --by group, the TVCG 2011
    // answer sheet unless --answers.
    analysis::AnalysisOptions options;
    options.byGroup = o.by == "group";
    options.split = o.poolSoundscapes ? analysis::SoundscapeSplit::Pooled
                                      : analysis::SoundscapeSplit::BySoundscape;
    options.confLevel = o.confLevel;
    options.groupOrder = o.groupOrder;
    if (overrides.answers) options.answers = *overrides.answers;
    analysis::AnalysisReport report;
    try {
        if (!o.study.empty()) {
            // Straight from the study store, set up as the console sets it up.
            const auto store = experiment::StudyStore::openForReading(o.study);
            report = wiring::analyzeStudy(store, overrides);
            report.source = o.study;
            noteSimulated(o, store, report.simulatedParticipants, report.participants);
        } else if (!o.trials.empty()) {
            auto trials = analysis::readTrialCsv(o.trials);
            if (!o.includeSimulated) {
                const auto before = trials.size();
                std::erase_if(trials, [](const analysis::TrialRecord& t) { return t.simulated; });
                if (trials.size() != before)
                    fmt::print(stderr,
                               "analyze: {} of simulated participants left out "
                               "(--include-simulated keeps them)\n",
                               counted(before - trials.size(), "trial"));
            }
            report = analysis::analyzeTrials(trials, options);
            analysis::addMixedModelComparisons(report, trials, options);
            report.source = o.trials;
            if (report.simulatedParticipants > 0)
                fmt::print(stderr, "analyze: {}\n",
                           analysis::markup::simulatedNotice(report.simulatedParticipants,
                                                             report.participants));
        } else {
            std::vector<analysis::ConfusionMatrix> tables;
            for (std::size_t i = 0; i < o.counts.size(); ++i) {
                const double nominal = o.presentations.empty()       ? std::nan("")
                                       : o.presentations.size() == 1 ? o.presentations[0]
                                                                     : o.presentations[i];
                tables.push_back(analysis::readCountTable(o.counts[i], nominal));
            }
            report = analysis::analyzeConfusions(std::move(tables), options);
            report.source = fmt::format("{}", fmt::join(o.counts, ", "));
        }
    } catch (const std::runtime_error& e) {
        throw cli::UserError(e.what());
    }
    if (o.study.empty()) report.title = o.title.empty() ? "Underfoot analysis" : o.title;
    const std::string text = analysis::renderReport(report, *format);
    if (o.output.empty() || o.output == "-") {
        fmt::print("{}", text);
        return 0;
    }
    std::ofstream out(o.output, std::ios::binary);
    if (!out) throw cli::UserError(fmt::format("{}: cannot open for writing", o.output));
    out << text;
    if (!out.flush()) throw cli::UserError(fmt::format("{}: write failed", o.output));
    return 0;
}

const cli::CommandRegistrar registrar("analyze", [](CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand(
        "analyze", "Confusion matrices, per-stimulus summaries and between-group tests of a "
                   "study (trial CSV or published count tables)");
    auto o = std::make_shared<AnalyzeOptions>();
    cmd->add_option("--study", o->study, "A study store (.db): analyse its answered trials");
    cmd->add_option("--trials", o->trials, "Long-format trial CSV written by `underfoot export`");
    cmd->add_option("--counts", o->counts,
                    "Count table(s) in the format of protocols/data/*_confusion.csv; one group "
                    "per file");
    cmd->add_option("--presentations", o->presentations,
                    "Presentations per stimulus row of the --counts tables (one value, or one "
                    "per file), to flag rows that do not add up");
    cmd->add_option("--by", o->by,
                    "Split tables and compare between: group, or none (default for --study: "
                    "group when the protocol's design is between participants)");
    cmd->add_option("--format", o->format, "csv (tidy), latex (booktabs), markdown or html")
        ->capture_default_str();
    cmd->add_option("-o,--output", o->output, "Output file (default: standard output)");
    cmd->add_option("--title", o->title,
                    "Report title (default for --study: the protocol's title)");
    cmd->add_option("--conf-level", o->confLevel, "Confidence level of the intervals")
        ->capture_default_str();
    cmd->add_option("--group-order", o->groupOrder,
                    "Order of the groups (e.g. none,coherent,incoherent); others follow "
                    "(default for --study: the protocol's order)")
        ->delimiter(',');
    cmd->add_option("--answers", o->answers,
                    "Answer-list order of the protocol for --trials (comma-separated ids; "
                    "dont_know is put last when missing); default: the TVCG 2011 answer sheet")
        ->delimiter(',');
    cmd->add_option("--form", o->form,
                    "auto (rating analysis for protocols that only rate), identification "
                    "(confusion matrices), ratings or wading (the gait sonification paper's "
                    "form: medians/IQRs, Friedman, Holm-corrected Wilcoxon, Kruskal-Wallis, "
                    "Spearman, box plots)")
        ->capture_default_str();
    cmd->add_option("--ratings", o->ratings, "Ratings CSV written by `underfoot export`");
    cmd->add_option("--participants", o->participants,
                    "Participants CSV written by `underfoot export` (grouping fields)");
    cmd->add_option("--scales", o->scales, "Scales CSV written by `underfoot export`");
    cmd->add_option("--group-by", o->groupFields,
                    "Participant fields to compare groups on (default: every field)")
        ->delimiter(',');
    cmd->add_flag("--include-simulated", o->includeSimulated,
                  "Also analyse simulated participants (`session --simulate`), left out by "
                  "default");
    cmd->add_flag("--pool-soundscapes", o->poolSoundscapes,
                  "One row per surface instead of one per surface and soundscape");
    cmd->callback([&exitCode, o] { exitCode = analyze(*o); });
});

} // namespace
} // namespace underfoot::cli::analyze_command
