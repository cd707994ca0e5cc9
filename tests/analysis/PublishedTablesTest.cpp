// SPDX-License-Identifier: GPL-3.0-or-later
// The published count tables (tests/analysis/data/published, transcribed from the papers' tables)
// import and reproduce their own percentages; rows that do not add up are flagged.
#include "analysis/io/CountTables.h"
#include "analysis/io/Csv.h"
#include "analysis/tables/Tables.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>

using namespace underfoot::analysis;

namespace {

const std::string kDir = std::string(UNDERFOOT_SOURCE_DIR) + "/tests/analysis/data/published/";

const SummaryRow* find(const AnalysisReport& r, const std::string& surface,
                       const std::string& soundscape) {
    for (const auto& s : r.summary)
        if (s.stimulus.surfaceId == surface && s.stimulus.soundscapeId == soundscape) return &s;
    return nullptr;
}

} // namespace

TEST(PublishedTables, EveryConfusionFileImports) {
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kDir)) {
        const auto name = entry.path().filename().string();
        if (!name.ends_with("_confusion.csv")) continue;
        ++files;
        const auto m = readCountTable(entry.path().string(), NAN);
        EXPECT_FALSE(m.rows.empty()) << name;
        EXPECT_EQ(m.columns.options.back().id, "dont_know") << name;
        EXPECT_FALSE(m.group.ends_with("_confusion")) << name;
    }
    EXPECT_EQ(files, 7);
}

TEST(PublishedTables, Exp2ConfusionTablesReproduceThePublishedSummary) {
    const std::map<std::string, std::pair<std::string, double>> files{
        {"1_none", {"tvcg2011_exp2_cond1_no_soundscape_confusion.csv", 30}},
        {"2_coherent", {"tvcg2011_exp2_cond2_coherent_confusion.csv", 30}},
        {"3_incoherent", {"tvcg2011_exp2_cond3_incoherent_confusion.csv", 26}}};
    std::map<std::string, AnalysisReport> reports;
    for (const auto& [condition, file] : files)
        reports[condition] =
            analyzeConfusions({readCountTable(kDir + file.first, file.second)}, AnalysisOptions{});
    const auto summary = csv::readFile(kDir + "tvcg2011_exp2_summary.csv");
    int checked = 0, flagged = 0;
    for (std::size_t i = 1; i < summary.size(); ++i) {
        const auto& f = summary[i].fields;
        const std::string condition = f[0];
        std::string surface = f[1] == "snow" ? "deep_snow" : f[1];
        // only the incoherent condition's table is split by soundscape
        std::string soundscape;
        if (condition == "3_incoherent") soundscape = *findSoundscapeId(f[2]);
        const auto* row = find(reports[condition], surface, soundscape);
        ASSERT_NE(row, nullptr) << condition << " " << surface << " " << soundscape;
        const double nominal = files.at(condition).second;
        if (row->n != nominal) {
            // e.g. condition 1, forest underbrush: 31 answers for 30 presentations (README)
            ++flagged;
            bool noted = false;
            for (const auto& note : reports[condition].notes)
                noted = noted || note.find(labelFor(surface)) != std::string::npos;
            EXPECT_TRUE(noted) << condition << " " << surface;
            continue;
        }
        ++checked;
        // the paper rounds (and sometimes truncates) to two decimals
        EXPECT_NEAR(row->correct.percent, std::stod(f[3]), 0.02) << condition << " " << surface;
        EXPECT_NEAR(row->wrong.percent, std::stod(f[4]), 0.02) << condition << " " << surface;
        EXPECT_NEAR(row->dontKnow.percent, std::stod(f[5]), 0.02) << condition << " " << surface;
    }
    EXPECT_EQ(checked, 15);
    EXPECT_EQ(flagged, 1);
}

TEST(PublishedTables, Exp1RowsThatDoNotAddUpAreFlaggedAndDiagonalsMatchTheReadme) {
    const auto r = analyzeConfusions({readCountTable(kDir + "tvcg2011_exp1_confusion.csv", 30)},
                                     AnalysisOptions{});
    // README: DR=28, DL=25, MT=28, WR=32
    ASSERT_EQ(r.notes.size(), 4u);
    EXPECT_NE(r.notes[0].find("Dirt (pebbles) sums to 28"), std::string::npos) << r.notes[0];
    EXPECT_NE(r.notes[3].find("Wood (reverb) sums to 32"), std::string::npos) << r.notes[3];
    // reverb rows: the published WR/CR/MR answers are the correct ones
    EXPECT_EQ(find(r, "creaking_wood_reverb", "")->correct.count, 28);
    EXPECT_EQ(find(r, "metal_reverb", "")->correct.count, 25);
}

TEST(PublishedTables, EurohapticsGravelAndWoodTestsMatchThePaper) {
    const auto r =
        analyzeConfusions({readCountTable(kDir + "eurohaptics2010_audio_confusion.csv", 20),
                           readCountTable(kDir + "eurohaptics2010_audiohaptic_confusion.csv", 20)},
                          AnalysisOptions{});
    EXPECT_TRUE(r.notes.empty());
    int found = 0;
    for (const auto& c : r.comparisons) {
        if (c.measure != Measure::Correct) continue;
        if (c.surfaceId == "gravel") {
            // paper: chi2 = 8.9011, df = 1, p = 0.00285
            EXPECT_NEAR(c.test.statistic, 8.9011, 5e-5);
            EXPECT_EQ(c.test.df, std::vector<double>{1});
            EXPECT_NEAR(c.test.p, 0.00285, 5e-6);
            ++found;
        }
        if (c.surfaceId == "wood") {
            // paper: chi2 = 5.8333, df = 1, p = 0.01573
            EXPECT_NEAR(c.test.statistic, 5.8333, 5e-5);
            EXPECT_NEAR(c.test.p, 0.01573, 5e-6);
            ++found;
        }
    }
    EXPECT_EQ(found, 2);
}

TEST(PublishedTables, BadCountTablesGiveFileLineColumnErrors) {
    auto message = [](const std::string& text) {
        try {
            parseCountTable(text, "counts.csv", "g", NAN);
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("stimulus,BS,XX\nBS,1,2\n").find("counts.csv:1:3: unknown answer code 'XX'"),
              std::string::npos);
    EXPECT_NE(message("stimulus,BS,DK\nBS,1,-2\n").find("counts.csv:2:3"), std::string::npos);
    EXPECT_NE(message("stimulus,BS,DK\nQQ,1,2\n").find("counts.csv:2:1: unknown stimulus"),
              std::string::npos);
    EXPECT_NE(message("stimulus,soundscape,BS,DK\nBS,Moon,1,2\n").find("unknown soundscape 'Moon'"),
              std::string::npos);
    EXPECT_NE(message("stim,BS\n").find("expected 'stimulus'"), std::string::npos);
}
