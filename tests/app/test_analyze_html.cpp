// SPDX-License-Identifier: GPL-3.0-or-later
// "the HTML report shows labelled figures with confidence intervals": the `underfoot`
// program makes two studies with simulated participants (a rating study, wading_listening, and
// an identification study by group, tvcg2011_exp2) and `underfoot analyze --format html` reports
// them. The test reads the same stores through the library, computes what the report must say
// (means and t intervals with Boost.Math's Student t, the tests' statistics) and finds it in the
// page: the protocol's labels (not ids), axis titles, one mean with its interval per condition
// and one point per participant and condition, heat-map cells with counts and row percentages,
// and the tests in words ("χ²(1) = 8.90, p = 0.003") with the values the analysis computed.
#include "analysis/io/TrialCsv.h"
#include "analysis/ratings/RatingAnalysis.h"
#include "analysis/report/Markup.h"
#include "analysis/tables/Tables.h"
#include "experiment/Export.h"
#include "experiment/Store.h"
#include "tests/common/ReadFile.h"
#include "tests/common/ScratchDir.h"

#include <boost/math/distributions/students_t.hpp>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace an = underfoot::analysis;
namespace xp = underfoot::experiment;
namespace fs = std::filesystem;

using underfoot::test::readFile;

namespace {

const fs::path kDir = underfoot::test::scratchDir("analyze_html");

/// Runs the program with `args`; its output goes to a log that a failure shows.
void runUnderfoot(const std::string& args) {
    const auto log = kDir / "log.txt";
    const std::string command =
        fmt::format("'{}' {} > '{}' 2>&1", UNDERFOOT_CLI, args, log.string());
    const int rc = std::system(command.c_str());
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    ASSERT_EQ(rc, 0) << command << "\n" << text.str();
}

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
        ++n;
    return n;
}

/// "p = 0.003" / "p < 0.001", written here independently of the report's code (as HTML text:
/// "p &lt; 0.001").
std::string pWords(double p) {
    return p < 0.001 ? std::string("p &lt; 0.001") : fmt::format("p = {:.3f}", p);
}

std::string makeStudy(const std::string& name, const std::string& protocol, int participants) {
    const auto db = (kDir / (name + ".db")).string();
    fs::remove(db);
    fs::remove(db + "-wal");
    fs::remove(db + "-shm");
    runUnderfoot(fmt::format("study create --study '{}' --protocol '{}/protocols/{}.toml' --code T "
                             "--site test --seed 17",
                             db, UNDERFOOT_SOURCE_DIR, protocol));
    runUnderfoot(
        fmt::format("session --study '{}' --simulate --participants {}", db, participants));
    return db;
}

} // namespace

TEST(AnalyzeHtml, RatingStudyShowsLabelledMeansWithIntervalsPointsAndTestsInWords) {
    std::string db;
    ASSERT_NO_FATAL_FAILURE(db = makeStudy("ratings", "wading_listening", 8));
    const auto html = (kDir / "ratings.html").string();
    ASSERT_NO_FATAL_FAILURE(runUnderfoot(
        fmt::format("analyze --study '{}' --include-simulated --format html -o '{}'", db, html)));
    const std::string page = readFile(html);

    // The same analysis through the library.
    const auto store = xp::StudyStore::openForReading(db);
    std::ostringstream ratings, participants, scales;
    xp::writeRatingsCsv(store, ratings, xp::ExportScope::Answered, xp::SimulatedRows::Include);
    xp::writeParticipantsCsv(store, participants, xp::SimulatedRows::Include);
    xp::writeScalesCsv(store, scales);
    const auto data = an::parseRatingData(ratings.str(), "ratings", participants.str(),
                                          "participants", scales.str(), "scales");
    const auto a = an::analyzeRatingStudy(data);
    ASSERT_FALSE(a.scales.empty());
    EXPECT_EQ(a.participants, 8u);
    // Every participant here is simulated: the report says so at its top.
    EXPECT_NE(page.find("<p class=\"banner simulated\""), std::string::npos);
    EXPECT_NE(page.find(an::markup::xmlEscape(an::markup::simulatedNotice(8, 8))),
              std::string::npos);

    std::size_t cells = 0, points = 0;
    for (const auto& s : a.scales) {
        SCOPED_TRACE(s.scale.id);
        cells += s.cells.size();
        EXPECT_NE(page.find(an::markup::xmlEscape(fmt::format(
                      "Rating: {} ({:g} to {:g})", s.scale.id, s.scale.min, s.scale.max))),
                  std::string::npos)
            << "the value axis's title";
        // The omnibus test in words, from the analysis's numbers.
        const auto& r = s.omnibus.result;
        ASSERT_TRUE(r.ok());
        ASSERT_EQ(r.df.size(), 1u);
        EXPECT_NE(
            page.find(fmt::format("χ²({:.0f}) = {:.2f}, {}", r.df[0], r.statistic, pWords(r.p))),
            std::string::npos)
            << "Friedman: " << r.statistic << ", p " << r.p;
        for (const auto& p : s.planned)
            EXPECT_NE(page.find(fmt::format("Z = {:.2f}, {} (Holm: {})", p.test.z, pWords(p.test.p),
                                            pWords(p.pHolm))),
                      std::string::npos)
                << p.first << " vs " << p.second;
        for (const auto& c : s.cells) {
            points += c.values.size();
            // Mean and 95 % t interval computed here.
            double sum = 0, ss = 0;
            for (const auto& [who, v] : c.values) sum += v;
            const double n = static_cast<double>(c.values.size());
            const double mean = sum / n;
            for (const auto& [who, v] : c.values) ss += (v - mean) * (v - mean);
            const double half = boost::math::quantile(boost::math::students_t(n - 1), 0.975) *
                                std::sqrt(ss / (n - 1) / n);
            // The protocol's label of the stimulus: its [[factorial]]'s "wading clip" and the
            // levels that tell the six apart.
            const xp::Stimulus* stimulus = nullptr;
            for (const auto& st : store.protocol().stimuli)
                if (st.id == c.stimulus) stimulus = &st;
            ASSERT_NE(stimulus, nullptr) << c.stimulus;
            std::string label = stimulus->label;
            std::string levels;
            for (const auto& [f, l] : stimulus->factors)
                levels += (levels.empty() ? "" : ", ") + f + " " + l;
            if (!levels.empty()) label += " (" + levels + ")";
            EXPECT_NE(page.find(an::markup::xmlEscape(
                          fmt::format("{}: mean {:.2f}, 95 % CI {:.2f} to {:.2f}, n {}", label,
                                      mean, mean - half, mean + half, c.values.size()))),
                      std::string::npos)
                << c.stimulus;
            EXPECT_NE(page.find(">" + an::markup::xmlEscape(label) + "<title>" + c.stimulus +
                                "</title></text>"),
                      std::string::npos)
                << "the axis shows the label, the id only as a tooltip: " << c.stimulus;
        }
    }
    EXPECT_EQ(occurrences(page, "class=\"mean\""), cells) << "one mean per condition";
    EXPECT_EQ(occurrences(page, "class=\"point\""), points)
        << "one point per participant and condition";
    EXPECT_EQ(occurrences(page, "class=\"rating-means\""), a.scales.size());
    EXPECT_EQ(occurrences(page, "class=\"rating-boxes\""), a.scales.size());
    EXPECT_EQ(occurrences(page, ">Condition</text>"), 2 * a.scales.size());
}

TEST(AnalyzeHtml, IdentificationStudyShowsHeatMapsWithCountsAndRowPercentsAndTestsInWords) {
    std::string db;
    ASSERT_NO_FATAL_FAILURE(db = makeStudy("identification", "tvcg2011_exp2", 12));
    const auto html = (kDir / "identification.html").string();
    ASSERT_NO_FATAL_FAILURE(runUnderfoot(fmt::format(
        "analyze --study '{}' --include-simulated --by group --format html -o '{}'", db, html)));
    const std::string page = readFile(html);

    const auto store = xp::StudyStore::openForReading(db);
    std::ostringstream csv;
    xp::writeTrialsCsv(store, csv, xp::ExportScope::Answered, xp::SimulatedRows::Include);
    const auto trials = an::parseTrialCsv(csv.str(), "trials");
    an::AnalysisOptions options;
    options.byGroup = true;
    // The groups compared in the protocol's order, as `analyze --study` does by default.
    for (const auto& g : store.protocol().groups) options.groupOrder.push_back(g.id);
    options.answers.options.clear();
    for (const auto& o : store.protocol().questions.surfaceOptions)
        if (o.id != an::kDontKnowId) options.answers.options.push_back({o.id, o.label});
    options.answers.options.push_back(
        {std::string(an::kDontKnowId), an::labelFor(an::kDontKnowId)});
    const auto r = an::analyzeTrials(trials, options);
    ASSERT_FALSE(r.confusions.empty());
    ASSERT_FALSE(r.comparisons.empty());
    EXPECT_EQ(occurrences(page, "<p class=\"banner simulated\""), 1u);
    EXPECT_NE(page.find("Simulated data: "), std::string::npos);

    EXPECT_EQ(occurrences(page, ">Answer given</text>"), r.confusions.size());
    EXPECT_EQ(occurrences(page, ">Presented stimulus</text>"), r.confusions.size());
    // The protocol's answer labels head the columns.
    for (const auto& o : store.protocol().questions.surfaceOptions)
        EXPECT_NE(page.find(">" + an::markup::xmlEscape(o.label) + "<title>" + o.id + "</title>"),
                  std::string::npos)
            << o.id;
    // Every non-empty cell: its count and its row percentage, as computed here.
    std::size_t filled = 0;
    for (const auto& m : r.confusions)
        for (std::size_t i = 0; i < m.rows.size(); ++i) {
            double total = 0;
            for (double v : m.counts[i]) total += v;
            for (std::size_t j = 0; j < m.counts[i].size(); ++j) {
                if (m.counts[i][j] <= 0) continue;
                ++filled;
                EXPECT_NE(page.find(fmt::format(">{:.0f}</text>\n<text class=\"row-percent\"",
                                                m.counts[i][j])),
                          std::string::npos);
                EXPECT_NE(page.find(fmt::format(">{:.1f}%</text>", 100 * m.counts[i][j] / total)),
                          std::string::npos)
                    << m.group << " row " << i << " column " << j;
            }
        }
    EXPECT_EQ(occurrences(page, "class=\"row-percent\""), filled);
    // The tests in words, with the analysis's statistics.
    std::size_t sentences = 0;
    for (const auto& c : r.comparisons) {
        if (!c.test.ok() || c.test.df.empty()) continue;
        const std::string symbol = c.test.statisticName == "t" ? "t" : "χ²";
        const double df = c.test.df[0];
        const std::string dfText =
            df == std::round(df) ? fmt::format("{:.0f}", df) : fmt::format("{:.1f}", df);
        EXPECT_NE(page.find(fmt::format("{}({}) = {:.2f}, {}", symbol, dfText, c.test.statistic,
                                        pWords(c.test.p))),
                  std::string::npos)
            << an::measureName(c.measure) << " " << c.surfaceId;
        ++sentences;
    }
    EXPECT_GT(sentences, 0u);
    EXPECT_EQ(occurrences(page, "<ul class=\"tests\">"), 1u);
    // Ratings of an identification study: per group and scale, each stimulus's mean with its
    // 95 % t interval (computed here) and one dot per answer.
    ASSERT_TRUE(r.hasRatings);
    std::size_t means = 0, points = 0;
    for (const auto& s : r.summary)
        for (const bool realism : {true, false}) {
            const auto& m = realism ? s.realism : s.quality;
            if (m.values.empty()) continue;
            ++means;
            points += m.values.size();
            double sum = 0;
            for (double v : m.values) sum += v;
            const double n = static_cast<double>(m.values.size()), mean = sum / n;
            EXPECT_NEAR(m.mean, mean, 1e-12);
            std::string interval;
            if (m.values.size() >= 2) {
                double ss = 0;
                for (double v : m.values) ss += (v - mean) * (v - mean);
                const double half = boost::math::quantile(boost::math::students_t(n - 1), 0.975) *
                                    std::sqrt(ss / (n - 1) / n);
                interval = fmt::format(", 95 % CI {:.2f} to {:.2f}", mean - half, mean + half);
            }
            EXPECT_NE(page.find(fmt::format("mean {} {:.2f}{}, n {:.0f}</title>",
                                            realism ? "realism" : "quality", mean, interval, n)),
                      std::string::npos)
                << s.group << " " << s.stimulus.surfaceId << (realism ? " realism" : " quality");
        }
    EXPECT_GT(means, 0u);
    EXPECT_EQ(occurrences(page, "<rect class=\"mean\""), means);
    EXPECT_EQ(occurrences(page, "<circle class=\"point\""), points);
    EXPECT_GT(occurrences(page, "Realism rating: mean with 95 % CI (bar), each answer (dot)"), 0u);
}
