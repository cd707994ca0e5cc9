// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/TrialCsv.h"
#include "analysis/io/Csv.h"
#include "analysis/model/Catalog.h"
#include "analysis/tables/ScoringRules.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace underfoot::analysis;

namespace {

std::string header() {
    std::string h;
    for (const auto& c : trialCsvColumns()) h += (h.empty() ? "" : ",") + c;
    return h;
}

std::string expectError(const std::string& text) {
    try {
        parseTrialCsv(text, "trials.csv");
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return {};
}

} // namespace

TEST(Csv, QuotedFieldsKeepCommasQuotesAndLineBreaks) {
    const auto records = csv::parse("a,b\n\"x, y\",\"say \"\"hi\"\"\"\n\"two\nlines\",z\r\n", "t");
    ASSERT_EQ(records.size(), 3u);
    EXPECT_EQ(records[1].fields[0], "x, y");
    EXPECT_EQ(records[1].fields[1], "say \"hi\"");
    EXPECT_EQ(records[2].fields[0], "two\nlines");
    EXPECT_EQ(records[2].line, 3u);
    EXPECT_EQ(csv::escape("a,\"b\""), "\"a,\"\"b\"\"\"");
}

TEST(Csv, UnclosedQuoteNamesTheLineWhereItOpened) {
    try {
        csv::parse("a,b\n1,\"open\n2,3\n", "f.csv");
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("f.csv:2"), std::string::npos) << e.what();
    }
}

TEST(TrialCsv, ReadsTheExportFormatByHeaderName) {
    const std::string text =
        header() + ",extra_column\n" +
        "exp2,lab,p2,abc,P01,2_coherent,1,3,main,0,gravel_farm,gravel,farm_courtyard,audio,0,1,42,"
        "gravel,Gravel,1,5,4.5,farm_courtyard,1,3.25,0,,\"note, with comma\",t0,t1,4,1,,,,,x\n" +
        "exp2,lab,p2,abc,P01,2_coherent,1,4,main,0,snow,deep_snow,,audio,0,2,43,dont_know,"
        "\"I don't know\",0,,,,,,1,noise,,t0,t1,5,0,,,,,y\n";
    const auto trials = parseTrialCsv(text, "trials.csv");
    ASSERT_EQ(trials.size(), 2u);
    const auto& t = trials[0];
    EXPECT_EQ(t.participant, "P01");
    EXPECT_EQ(t.group, "2_coherent");
    EXPECT_EQ(t.trialIndex, 3);
    EXPECT_EQ(t.surfaceId, "gravel");
    EXPECT_EQ(t.soundscapeId, "farm_courtyard");
    EXPECT_EQ(t.answerId, "gravel");
    EXPECT_EQ(t.recordedCorrect, std::optional<bool>(true));
    EXPECT_EQ(t.realism, 5);
    EXPECT_EQ(t.quality, 4.5);
    EXPECT_EQ(t.responseTimeSeconds, 3.25);
    EXPECT_FALSE(t.excluded);
    const auto& u = trials[1];
    EXPECT_TRUE(std::isnan(u.realism));
    EXPECT_TRUE(std::isnan(u.quality));
    EXPECT_FALSE(u.recordedSoundscapeCorrect.has_value());
    EXPECT_TRUE(u.excluded);
    EXPECT_EQ(u.exclusionReason, "noise");
    EXPECT_TRUE(t.simulated); // the `simulated` column
    EXPECT_FALSE(u.simulated);
}

TEST(TrialCsv, EmptyParticipantOrSurfaceIsNamedWithFileAndLine) {
    // Messages as the reader wrote them before its checks shared one helper.
    const std::string required = "participant,group,practice,stimulus_id,surface,soundscape,"
                                 "answer,realism,quality,soundscape_answer,excluded\n";
    EXPECT_EQ(
        expectError(required + "P1,A,0,s1,gravel,,gravel,,,,0\n,A,0,s1,gravel,,gravel,,,,0\n"),
        "trials.csv:3: empty participant (expected a participant code)");
    EXPECT_EQ(expectError(required + "P1,A,0,s1,,,gravel,,,,0\n"),
              "trials.csv:2: empty surface (expected the presented surface id)");
}

TEST(TrialCsv, MissingRequiredColumnsAreNamedWithFileAndLine) {
    const std::string msg = expectError("participant,group,surface\nP1,A,gravel\n");
    EXPECT_NE(msg.find("trials.csv:1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("answer"), std::string::npos) << msg;
    EXPECT_NE(msg.find("excluded"), std::string::npos) << msg;
}

TEST(TrialCsv, MalformedCellsNameLineColumnAndExpectation) {
    std::string row = "s,,,,P1,A,,1,,2,st,gravel,,,,,,gravel,,,5,5,,,,0,,,,,,,,,,";
    std::string msg = expectError(header() + "\n" + row + "\n");
    EXPECT_NE(msg.find("trials.csv:2: column 10 ('practice')"), std::string::npos) << msg;
    row = "s,,,,P1,A,,1,,0,st,gravel,,,,,,gravel,,,NaN,5,,,,0,,,,,,,,,,";
    msg = expectError(header() + "\n" + row + "\n");
    EXPECT_NE(msg.find("'realism'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("finite number"), std::string::npos) << msg;
    msg = expectError(header() + "\ns,P1\n");
    EXPECT_NE(msg.find("trials.csv:2: 2 fields, expected 36"), std::string::npos) << msg;
}

TEST(TrialCsv, FormattedRecordsReadBackUnchanged) {
    TrialRecord t;
    t.participant = "P,7";
    t.group = "3_incoherent";
    t.surfaceId = "wood_reverb";
    t.stimulusId = "wr";
    t.soundscapeId = "forest";
    t.answerId = "wood";
    t.realism = 6;
    t.quality = NAN;
    t.soundscapeAnswer = "forest";
    t.practice = true;
    t.trialIndex = 12;
    const auto back = parseTrialCsv(formatTrialCsv({t}), "mem");
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(back[0].participant, "P,7");
    EXPECT_EQ(back[0].surfaceId, "wood_reverb");
    EXPECT_EQ(back[0].answerId, "wood");
    EXPECT_EQ(back[0].realism, 6);
    EXPECT_TRUE(std::isnan(back[0].quality));
    EXPECT_TRUE(back[0].practice);
    EXPECT_EQ(back[0].trialIndex, 12);
}

TEST(TrialCsv, ExperimentLayerExportAgreesWithTheScoringRules) {
    // First 120 trials of `underfoot export` on a study of protocols/tvcg2011_exp2.toml with
    // participants simulated from the published confusion matrices (`underfoot session
    // --simulate`): CRLF line ends, the full header, recorded correctness.
    const auto trials = readTrialCsv(std::string(UNDERFOOT_SOURCE_DIR) +
                                     "/tests/analysis/data/export_tvcg2011_exp2_simulated.csv");
    ASSERT_EQ(trials.size(), 120u);
    int soundscapeChecked = 0;
    for (const auto& t : trials) {
        ASSERT_TRUE(t.recordedCorrect.has_value());
        EXPECT_EQ(*t.recordedCorrect, answerIsCorrect(t.surfaceId, t.answerId))
            << t.participant << " " << t.trialIndex;
        if (t.recordedSoundscapeCorrect) {
            TrialRecord derived = t;
            derived.recordedSoundscapeCorrect.reset();
            EXPECT_EQ(rules::soundscapeCorrect(derived), t.recordedSoundscapeCorrect);
            ++soundscapeChecked;
        }
    }
    EXPECT_GT(soundscapeChecked, 0);
}

// The analysis's CSV writer makes formula-leading cells inert and its reader gives the text back
// exactly (base/CsvCell.h); numbers such as -1.5 are written as they are.
TEST(Csv, FormulaLeadingCellsRoundTrip) {
    const std::vector<std::string> cells = {"=1+2", "@x", "-x", "'=y", "\tz", "-1.5", "+3", "a,b"};
    const std::string line = underfoot::analysis::csv::joinLine(cells);
    EXPECT_EQ(line, "'=1+2,'@x,'-x,''=y,'\tz,-1.5,+3,\"a,b\"");
    const auto records = underfoot::analysis::csv::parse(line + "\n", "round.csv");
    ASSERT_EQ(records.size(), 1u);
    EXPECT_EQ(records[0].fields, cells);
}
