// SPDX-License-Identifier: GPL-3.0-or-later
#include "TestSupport.h"
#include "experiment/Clips.h"
#include "experiment/Export.h"
#include "experiment/Session.h"
#include "experiment/Simulation.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
/// Minimal RFC 4180 reader for the checks (quoted fields, doubled quotes, CRLF).
std::vector<std::vector<std::string>> readCsv(const std::string& text) {
    std::vector<std::vector<std::string>> rows(1);
    std::string cell;
    bool quoted = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"' && i + 1 < text.size() && text[i + 1] == '"')
                cell += '"', ++i;
            else if (c == '"')
                quoted = false;
            else
                cell += c;
        } else if (c == '"')
            quoted = true;
        else if (c == ',')
            rows.back().push_back(cell), cell.clear();
        else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
            rows.back().push_back(cell);
            cell.clear();
            rows.emplace_back();
            ++i;
        } else
            cell += c;
    }
    if (rows.back().empty()) rows.pop_back();
    return rows;
}
} // namespace

TEST(ExperimentExport, HeaderIsTheAnalysisContract) {
    const std::string expected =
        "study,site,protocol_id,protocol_hash,participant,group,session,trial_index,block,"
        "practice,stimulus_id,surface,soundscape,modalities,reverb,repetition,render_seed,answer,"
        "answer_label,correct,realism,quality,soundscape_answer,soundscape_correct,"
        "response_time_s,excluded,exclusion_reason,comment,started_at,answered_at,trial,simulated,"
        "clip_file,clip_frames,clip_rate,clip_sha256";
    std::string joined;
    for (auto c : kTrialColumns) joined += (joined.empty() ? "" : ",") + std::string(c);
    EXPECT_EQ(joined, expected);
}

TEST(ExperimentExport, CsvFieldQuoting) {
    EXPECT_EQ(csvField("plain"), "plain");
    EXPECT_EQ(csvField("a,b"), "\"a,b\"");
    EXPECT_EQ(csvField("say \"hi\""), "\"say \"\"hi\"\"\"");
    EXPECT_EQ(csvField("two\nlines"), "\"two\nlines\"");
}

namespace {
/// The column names of the trials.csv table of a codebook (Markdown rows "| `name` | ... |"
/// between "## trials.csv" and the next "## " heading), in order.
std::vector<std::string> codebookTrialColumns(const std::string& markdown) {
    std::vector<std::string> names;
    std::istringstream in(markdown);
    std::string line;
    bool inTrials = false;
    while (std::getline(in, line)) {
        if (line.starts_with("## ")) inTrials = line.starts_with("## trials.csv");
        if (!inTrials || !line.starts_with("| `")) continue;
        const std::size_t end = line.find('`', 3);
        if (end != std::string::npos) names.push_back(line.substr(3, end - 3));
    }
    return names;
}
} // namespace

TEST(ExperimentExport, BothCodebooksListExactlyTheTrialColumnsInOrder) {
    // kTrialColumns (base/TrialColumns.h) is what the export writes and the analysis reads; the
    // codebook of every export and docs/reference/codebook.md say what each column means.
    const std::vector<std::string> columns(kTrialColumns.begin(), kTrialColumns.end());
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("c.db"), parseProtocol(miniProtocol(), "m.toml"),
                                          {"EXP", "A", 5, "t"});
    std::ostringstream written;
    writeCodebook(store, written);
    EXPECT_EQ(codebookTrialColumns(written.str()), columns) << "experiment/Export.cpp codebook";
    std::ifstream doc(std::string(UNDERFOOT_SOURCE_DIR) + "/docs/reference/codebook.md");
    ASSERT_TRUE(doc) << "docs/reference/codebook.md";
    std::ostringstream text;
    text << doc.rdbuf();
    EXPECT_EQ(codebookTrialColumns(text.str()), columns) << "docs/reference/codebook.md";
}

TEST(ExperimentExport, RowsCarryAnswersCorrectnessAndQuotedComments) {
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("e.db"), parseProtocol(miniProtocol(), "m.toml"),
                                          {"EXP", "site \"A\"", 5, "t"});
    store.registerParticipant({"P1", 30, "", "", "", {}, ""});
    SilentPlayer player;
    Session session(store, "P1", player, {"E", "a", "s", "t"});
    session.finishBriefing();
    int k = 0;
    while (session.phase() != SessionPhase::Finished) {
        const TrialRecord t = session.current();
        session.play();
        TrialAnswer a;
        // Answer "wood" to everything: correct for WD and for WR (wood with reverb).
        a.answer = k == 0 ? "dont_know" : "wood";
        a.ratings["realism"] = 3;
        a.comment = k == 1 ? "steps, \"crunchy\"\nthen quiet" : "";
        session.answer(a);
        ++k;
    }
    store.setExcluded("P1", 2, true, "walked off the board");
    std::ostringstream out;
    EXPECT_EQ(writeTrialsCsv(store, out), 6);
    const auto rows = readCsv(out.str());
    ASSERT_EQ(rows.size(), 7u);
    std::map<std::string, std::size_t> col;
    for (std::size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        const auto& row = rows[r];
        ASSERT_EQ(row.size(), kTrialColumns.size());
        EXPECT_EQ(row[col["study"]], "EXP");
        EXPECT_EQ(row[col["site"]], "site \"A\"");
        EXPECT_EQ(row[col["group"]], ""); // within-subject design
        EXPECT_EQ(row[col["protocol_hash"]], store.protocol().hash);
        EXPECT_EQ(row[col["realism"]], "3");
        EXPECT_EQ(row[col["quality"]], "");
        EXPECT_EQ(row[col["soundscape_correct"]], "");
        const std::string surface = row[col["surface"]];
        const std::string answer = row[col["answer"]];
        const std::string expectCorrect =
            answer == "wood" && (surface == "wood" || surface == "wood_reverb") ? "1" : "0";
        EXPECT_EQ(row[col["correct"]], expectCorrect) << surface << " " << answer;
        if (surface == "wood_reverb") {
            EXPECT_EQ(row[col["reverb"]], "hall");
        }
        EXPECT_EQ(row[col["answered_at"]].size(), 24u); // 2026-11-21T20:45:34.123Z
        EXPECT_EQ(row[col["answered_at"]].back(), 'Z');
    }
    EXPECT_EQ(rows[1][col["answer"]], "dont_know");
    EXPECT_EQ(rows[1][col["answer_label"]], "I don't know");
    EXPECT_EQ(rows[2][col["comment"]], "steps, \"crunchy\"\nthen quiet");
    EXPECT_EQ(rows[3][col["excluded"]], "1");
    EXPECT_EQ(rows[3][col["exclusion_reason"]], "walked off the board");
    std::ostringstream codebook;
    writeCodebook(store, codebook);
    for (auto c : kTrialColumns)
        EXPECT_NE(codebook.str().find("`" + std::string(c) + "`"), std::string::npos) << c;
}

TEST(ExperimentExport, SimulatedExp1StudyReproducesThePublishedDiagonal) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("sim.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"SIM1", "ci", 2011, "t"});
    MatrixByGroup m;
    m[""] = loadConfusionMatrix(dataFile("tvcg2011_exp1_confusion.csv"));
    EXPECT_TRUE(checkMatrixAgainst(m[""], store.protocol()).empty());
    const int answers = simulateStudy(store, m, 30, {});
    EXPECT_EQ(answers, 30 * 26);
    std::ostringstream out;
    ASSERT_EQ(writeTrialsCsv(store, out), 30 * 26);
    const auto rows = readCsv(out.str());
    std::map<std::string, std::size_t> col;
    for (std::size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
    std::map<std::string, std::pair<int, int>> bySurface; // correct, total
    for (std::size_t r = 1; r < rows.size(); ++r) {
        auto& c = bySurface[rows[r][col["surface"]]];
        c.first += rows[r][col["correct"]] == "1";
        ++c.second;
    }
    // Creaking wood: 28 of 30 correct in the published matrix (p = 0.933); 60 draws give a
    // binomial sd of 0.032, so the 0.80 bound is 4 sd away. High grass: 0 of 30 correct.
    EXPECT_GT(bySurface["creaking_wood"].first, 0.80 * bySurface["creaking_wood"].second);
    EXPECT_EQ(bySurface["high_grass"].first, 0);
    EXPECT_EQ(bySurface["high_grass"].second, 60);
}

TEST(ExperimentSimulation, MatrixMustCoverTheProtocol) {
    const Protocol exp2 = loadProtocol(shipped("tvcg2011_exp2.toml"));
    const ConfusionMatrix cond1 =
        loadConfusionMatrix(dataFile("tvcg2011_exp2_cond1_no_soundscape_confusion.csv"));
    Protocol onlyNone = exp2;
    onlyNone.groups = {*exp2.group("none")};
    EXPECT_TRUE(checkMatrixAgainst(cond1, onlyNone).empty());
    const ConfusionMatrix cond3 =
        loadConfusionMatrix(dataFile("tvcg2011_exp2_cond3_incoherent_confusion.csv"));
    EXPECT_TRUE(cond3.hasSoundscape);
    Protocol onlyIncoherent = exp2;
    onlyIncoherent.groups = {*exp2.group("incoherent")};
    EXPECT_TRUE(checkMatrixAgainst(cond3, onlyIncoherent).empty());
    // The incoherent matrix has no row for gravel, so it cannot drive the coherent group.
    Protocol onlyCoherent = exp2;
    onlyCoherent.groups = {*exp2.group("coherent")};
    EXPECT_FALSE(checkMatrixAgainst(cond3, onlyCoherent).empty());
    // Exp 1's matrix names reverb variants, which are not options of exp 2's answer list.
    const ConfusionMatrix exp1 = loadConfusionMatrix(dataFile("tvcg2011_exp1_confusion.csv"));
    EXPECT_FALSE(checkMatrixAgainst(exp1, onlyNone).empty());
}

TEST(ExperimentSimulation, BadMatricesAreReportedWithLine) {
    EXPECT_THROW(parseConfusionMatrix("stimulus,BS,DK\nBS,1\n", "m.csv"), std::runtime_error);
    EXPECT_THROW(parseConfusionMatrix("stimulus,BS,XX\nBS,1,2\n", "m.csv"), std::runtime_error);
    EXPECT_THROW(parseConfusionMatrix("stimulus,BS,DK\nBS,1,nan\n", "m.csv"), std::runtime_error);
    EXPECT_THROW(parseConfusionMatrix("stimulus,BS,DK\nBS,0,0\n", "m.csv"), std::runtime_error);
    try {
        parseConfusionMatrix("stimulus,BS,DK\nBS,1,2\nGL,x,1\n", "m.csv");
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("m.csv:3:"), std::string::npos) << e.what();
    }
}

TEST(ExperimentExport, RatingsCarryFactorLevels) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("w.db"), loadProtocol(dataFile("wading_factorial.toml")), {"WAD", "lab", 8, "t"});
    EXPECT_EQ(simulateStudy(store, {{"", ConfusionMatrix{}}}, 1, {}), 13);
    std::ostringstream out;
    EXPECT_EQ(writeRatingsCsv(store, out), 13 * 5);
    const auto rows = readCsv(out.str());
    EXPECT_EQ(rows[0], (std::vector<std::string>{"study", "participant", "group", "trial_index",
                                                 "stimulus_id", "practice", "excluded", "cadence",
                                                 "depth", "scale", "value", "simulated"}));
    for (std::size_t r = 1; r < rows.size(); ++r) {
        const auto& row = rows[r];
        if (row[4] == "practice_normal") {
            EXPECT_EQ(row[7], "");
            continue;
        }
        EXPECT_EQ(row[4], "wade_" + row[8] + "_" + row[7]);
        const int value = std::stoi(row[10]);
        EXPECT_GE(value, row[9] == "realism" ? 1 : 0);
        EXPECT_LE(value, row[9] == "realism" ? 7 : 10);
        EXPECT_EQ(row[11], "1") << "every participant of simulateStudy is simulated";
    }
}

// Every CSV the project writes makes formula-leading cells inert (base/CsvCell.h): =, +, -, @,
// tab and CR get a leading apostrophe, except whole numbers such as -1.5 (read as numbers).
TEST(Export, FormulaLeadingCellsAreInertAndNumbersStayNumbers) {
    EXPECT_EQ(csvField("=HYPERLINK(\"http://x\")"), "\"'=HYPERLINK(\"\"http://x\"\")\"");
    EXPECT_EQ(csvField("=1+2"), "'=1+2");
    EXPECT_EQ(csvField("@SUM(A1)"), "'@SUM(A1)");
    EXPECT_EQ(csvField("+x"), "'+x");
    EXPECT_EQ(csvField("-x"), "'-x");
    EXPECT_EQ(csvField("-"), "'-");
    EXPECT_EQ(csvField("\tx"), "'\tx");
    EXPECT_EQ(csvField("\rx"), "\"'\rx\"");
    EXPECT_EQ(csvField("-nan"), "'-nan");
    EXPECT_EQ(csvField("-inf"), "'-inf");
    EXPECT_EQ(csvField("-0x10"), "'-0x10");
    EXPECT_EQ(csvField("'=x"), "''=x"); // protected again, so reading back is exact
    for (const char* number : {"-1.5", "+3", "-2e-05", "-0", "12", "0.25"})
        EXPECT_EQ(csvField(number), number);
    EXPECT_EQ(csvField("a,b"), "\"a,b\"");
    EXPECT_EQ(csvField("plain"), "plain");
}

TEST(Export, AFormulaInAParticipantCommentIsExportedInert) {
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("s.db"), parseProtocol(miniProtocol(), "m"),
                                          {"S", "lab", 1, "t"});
    store.registerParticipant({"P1", {}, "=cmd|' /C calc'!A0", "", "", {}, ""});
    std::ostringstream out;
    writeParticipantsCsv(store, out, SimulatedRows::Include);
    EXPECT_NE(out.str().find(",'=cmd|' /C calc'!A0,"), std::string::npos) << out.str();
    EXPECT_EQ(out.str().find(",=cmd"), std::string::npos) << out.str();
}

// The clip columns of trials.csv are the clip each trial stored (schema 7): a listening test run
// by simulated participants from a clip folder, exported and read back. The clip files are
// stand-in bytes (experiment/ renders nothing); the manifest names one of them with quotes (the
// manifest takes no comma), so that its cell must come back through RFC 4180 quoting.
TEST(ExperimentExport, ClipColumnsEqualTheClipsStoredWithEachTrial) {
    TempDir dir;
    const Protocol p = loadProtocol(shipped("tvcg2011_exp2_clips.toml"));
    const std::string clipDir = dir.file("clips");
    std::filesystem::create_directories(clipDir);
    std::vector<ClipRecord> records;
    for (const ClipJob& job : clipJobs(p, clipDir)) {
        std::ofstream(job.path, std::ios::binary) << "stand-in clip " << job.stimulus.id;
        ClipRecord r;
        r.stimulusId = job.stimulus.id;
        r.file = records.empty() ? "take \"quiet\".wav" : job.stimulus.id + ".wav";
        r.source = job.source;
        r.seed = job.seed;
        r.sampleRateHz = records.empty() ? 44100.0 : 48000.0;
        r.frames = 1000 + records.size();
        r.seconds = static_cast<double>(r.frames) / r.sampleRateHz;
        r.sha256 = fileSha256(job.path);
        r.samplesSha256 =
            fileSha256(job.path).substr(0, 60) + fmt::format("{:04x}", records.size());
        records.push_back(r);
    }
    ASSERT_GE(records.size(), 2u);
    writeClipManifest(clipDir, records);
    StudyStore store = StudyStore::create(dir.file("c.db"), p, {"CLIP", "lab", 7, "t"});
    SimulationSettings settings;
    settings.clipDir = clipDir;
    const MatrixByGroup m = defaultMatrices(p, shipped("tvcg2011_exp2_clips.toml"));
    ASSERT_GT(simulateStudy(store, m, 2, settings), 0);

    std::ostringstream out;
    const int written = writeTrialsCsv(store, out);
    const auto rows = readCsv(out.str());
    ASSERT_EQ(rows.size(), static_cast<std::size_t>(written) + 1);
    std::map<std::string, std::size_t> col;
    for (std::size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
    int withClip = 0;
    bool quotedSeen = false;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        const auto& row = rows[r];
        ASSERT_EQ(row.size(), kTrialColumns.size());
        const TrialRecord t =
            store.trial(row[col["participant"]], std::stoi(row[col["trial_index"]]));
        ASSERT_TRUE(t.clip) << "every answered trial of a listening test stored its clip";
        ++withClip;
        EXPECT_EQ(row[col["clip_file"]], t.clip->file);
        EXPECT_EQ(row[col["clip_frames"]], std::to_string(t.clip->frames));
        EXPECT_EQ(std::stod(row[col["clip_rate"]]), t.clip->sampleRateHz);
        EXPECT_EQ(row[col["clip_sha256"]], t.clip->samplesSha256);
        EXPECT_EQ(row[col["render_seed"]], std::to_string(clipSeed(p, t.stimulus)))
            << "the clip's seed is the render_seed column";
        const auto rec = std::find_if(records.begin(), records.end(), [&](const ClipRecord& c) {
            return c.stimulusId == t.stimulus.id;
        });
        ASSERT_NE(rec, records.end());
        EXPECT_EQ(t.clip->file, rec->file);
        EXPECT_EQ(t.clip->samplesSha256, rec->samplesSha256);
        quotedSeen = quotedSeen || t.clip->file == records.front().file;
    }
    EXPECT_GT(withClip, 0);
    EXPECT_TRUE(quotedSeen) << "the clip named with quotes was played";
    EXPECT_NE(out.str().find("\"take \"\"quiet\"\".wav\""), std::string::npos);
}

// A trial without a clip (booth / live footsteps) leaves the four clip cells empty.
TEST(ExperimentExport, ClipColumnsAreEmptyWithoutAClip) {
    TempDir dir;
    StudyStore store = StudyStore::create(dir.file("n.db"), parseProtocol(miniProtocol(), "m.toml"),
                                          {"NC", "lab", 5, "t"});
    store.registerParticipant({"P1", 30, "", "", "", {}, ""});
    std::ostringstream out;
    writeTrialsCsv(store, out, ExportScope::All);
    const auto rows = readCsv(out.str());
    ASSERT_GE(rows.size(), 2u);
    std::map<std::string, std::size_t> col;
    for (std::size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
    for (const char* c : {"clip_file", "clip_frames", "clip_rate", "clip_sha256"})
        EXPECT_EQ(rows[1].at(col.at(c)), "") << c;
}
