// SPDX-License-Identifier: GPL-3.0-or-later
// The experimenter's day: a simulation never writes into a real participant and
// flags its own; every shipped protocol simulates end to end from the published data it names;
// a resumed lap trial finishes; sessions store whether sound was played; people read 1-based
// trial numbers; unknown ids get a sorted list and a suggestion.
#include "TestSupport.h"

#include "experiment/Export.h"
#include "experiment/Session.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {

std::vector<std::vector<std::string>> csvRows(const std::string& text) {
    // The exports here have no quoted fields with commas in the columns read below.
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::vector<std::string> cells;
        std::string cell;
        std::istringstream l(line);
        while (std::getline(l, cell, ',')) cells.push_back(cell);
        if (!line.empty() && line.back() == ',') cells.emplace_back();
        rows.push_back(cells);
    }
    return rows;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i)
        if (header[i] == name) return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
}

SimulationSettings settingsFor(const Protocol& p) {
    SimulationSettings s;
    if (!p.simulation.ratingModel.empty())
        s.ratingModel = std::make_shared<RatingModel>(
            loadRatingModel(findProtocolFile(p, p.simulation.ratingModel)));
    return s;
}

MatrixByGroup matricesFor(const Protocol& p) {
    MatrixByGroup m = defaultMatrices(p);
    if (!p.questions.asksSurface()) m.try_emplace("");
    return m;
}

} // namespace

TEST(Honest, SimulationNeverWritesIntoRealParticipants) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"H", "ci", 17, "t"});
    // P01: interrupted after two answers; P02: registered, never started.
    store.registerParticipant({"P01", 30, "", "", "", {}, ""});
    store.registerParticipant({"P02", 31, "", "", "", {}, ""});
    {
        SilentPlayer silent;
        Session session(store, "P01", silent, {"exp", "none", "none", "t", false});
        session.finishBriefing();
        for (int i = 0; i < 2; ++i) {
            session.play();
            session.answer({"wood", {}, "", ""});
        }
        session.interrupt();
    }
    const MatrixByGroup m = matricesFor(store.protocol());
    EXPECT_EQ(simulateStudy(store, m, 3, {}), 3 * 26);
    // The real participants are exactly as they were.
    EXPECT_EQ(store.progressCounts().at("P01").first, 2);
    EXPECT_EQ(store.progressCounts().at("P02").first, 0);
    EXPECT_EQ(store.participant("P02").status, ParticipantStatus::Registered);
    EXPECT_FALSE(store.participant("P01").simulated);
    int simulated = 0;
    for (const auto& p : store.participants())
        if (p.simulated) {
            ++simulated;
            EXPECT_EQ(p.status, ParticipantStatus::Completed) << p.code;
        }
    EXPECT_EQ(simulated, 3);
    // Asked directly, the synthetic answerer refuses a real participant.
    EXPECT_THROW(runSimulatedSession(store, "P01", m.at(""), 1, {}), StoreError);
    EXPECT_EQ(store.progressCounts().at("P01").first, 2);
    // Running again completes nobody real and adds no answers (3 simulated are done).
    EXPECT_EQ(simulateStudy(store, m, 3, {}), 0);
}

TEST(Honest, ExportFlagsSimulatedRowsAndNumbersTrialsFromOne) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"H", "ci", 3, "t"});
    store.registerParticipant({"P01", 30, "", "", "", {}, ""});
    {
        SilentPlayer silent;
        Session session(store, "P01", silent, {"exp", "none", "none", "t", false});
        session.finishBriefing();
        session.play();
        session.answer({"gravel", {}, "", ""});
        session.interrupt();
    }
    simulateStudy(store, matricesFor(store.protocol()), 1, {});

    std::ostringstream all;
    EXPECT_EQ(writeTrialsCsv(store, all), 1 + 26);
    const auto rows = csvRows(all.str());
    const auto& header = rows.front();
    ASSERT_EQ(header.size(), kTrialColumns.size());
    const std::size_t sim = column(header, "simulated"), trial = column(header, "trial"),
                      index = column(header, "trial_index"), who = column(header, "participant");
    int simulatedRows = 0;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        ASSERT_EQ(rows[r].size(), header.size()) << r;
        EXPECT_EQ(rows[r][sim], rows[r][who] == "P01" ? "0" : "1");
        simulatedRows += rows[r][sim] == "1";
        EXPECT_EQ(std::stoi(rows[r][trial]), std::stoi(rows[r][index]) + 1);
    }
    EXPECT_EQ(simulatedRows, 26);

    std::ostringstream real;
    EXPECT_EQ(writeTrialsCsv(store, real, ExportScope::Answered, SimulatedRows::Exclude), 1);
    std::ostringstream participants;
    EXPECT_EQ(writeParticipantsCsv(store, participants, SimulatedRows::Exclude), 1);
    {
        // participants.csv and ratings.csv carry the flag too.
        std::ostringstream everyone;
        EXPECT_EQ(writeParticipantsCsv(store, everyone, SimulatedRows::Include), 2);
        const auto p = csvRows(everyone.str());
        const std::size_t ps = column(p[0], "simulated"), pc = column(p[0], "participant");
        for (std::size_t r = 1; r < p.size(); ++r)
            EXPECT_EQ(p[r][ps], p[r][pc] == "P01" ? "0" : "1") << p[r][pc];
        std::ostringstream ratings;
        writeRatingsCsv(store, ratings, ExportScope::Answered, SimulatedRows::Include);
        const auto q = csvRows(ratings.str());
        const std::size_t qs = column(q[0], "simulated"), qc = column(q[0], "participant");
        // (This protocol has no scales: the header only; test_export checks rated rows.)
        for (std::size_t r = 1; r < q.size(); ++r)
            EXPECT_EQ(q[r][qs], q[r][qc] == "P01" ? "0" : "1") << q[r][qc];
    }

    std::ostringstream codebook;
    writeCodebook(store, codebook);
    EXPECT_NE(codebook.str().find("`simulated`"), std::string::npos);
    EXPECT_NE(codebook.str().find("1-based"), std::string::npos);
}

TEST(Honest, EveryShippedProtocolSimulatesFromTheDataItNames) {
    int protocols = 0;
    for (const auto& entry : std::filesystem::directory_iterator(shippedProtocolDir())) {
        if (entry.path().extension() != ".toml") continue;
        ++protocols;
        SCOPED_TRACE(entry.path().filename().string());
        TempDir dir;
        const Protocol protocol = loadProtocol(entry.path().string());
        StudyStore store = StudyStore::create(dir.file("s.db"), protocol, {"H", "ci", 11, "t"});
        // What it answers from is named by the protocol, and fits every group.
        if (protocol.questions.asksSurface()) {
            ASSERT_FALSE(protocol.simulation.confusion.empty());
        } else {
            ASSERT_FALSE(protocol.simulation.ratingModel.empty());
        }
        const MatrixByGroup m = matricesFor(store.protocol());
        for (const auto& g : store.protocol().groups) {
            if (!protocol.questions.asksSurface()) break;
            Protocol one = store.protocol();
            one.groups = {g};
            const auto it = m.count(g.id) ? m.find(g.id) : m.find("");
            ASSERT_NE(it, m.end()) << g.id;
            EXPECT_TRUE(checkMatrixAgainst(it->second, one).empty()) << g.id;
        }
        // A real participant registered first stays untouched.
        std::map<std::string, std::string> fields;
        for (const auto& f : store.protocol().participantFields)
            fields[f.id] = f.options.empty() ? "x" : f.options.front();
        store.registerParticipant({"P01", 30, "", "", "", {}, ""}, fields);
        const int groups = std::max<int>(1, static_cast<int>(store.protocol().groups.size()));
        const int answers = simulateStudy(store, m, groups, settingsFor(store.protocol()));
        EXPECT_GT(answers, 0);
        for (const auto& p : store.participants()) {
            if (!p.simulated) {
                EXPECT_EQ(p.code, "P01");
                EXPECT_EQ(store.progressCounts().at(p.code).first, 0);
                continue;
            }
            EXPECT_EQ(p.status, ParticipantStatus::Completed) << p.code;
            EXPECT_FALSE(store.firstUnanswered(p.code)) << p.code;
        }
    }
    EXPECT_EQ(protocols, 7); // ls protocols/*.toml
}

TEST(Honest, AResumedLapTrialFinishesInTheSimulation) {
    // The bug: "completeLap(): all 6 laps of trial 0 are done" when a simulated lap trial was
    // resumed after laps had been walked.
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("wading_interactive.toml")), {"H", "ci", 5, "t"});
    ASSERT_GT(store.protocol().laps.total(), 1);
    NewParticipant np{"S001", std::nullopt, "", "", "", {}, ""};
    np.simulated = true;
    store.registerParticipant(np);
    {
        SilentPlayer silent;
        Session session(store, "S001", silent, {"sim", "none", "none", "t", false});
        session.finishBriefing();
        session.play();
        session.completeLap();
        session.completeLap();
        session.interrupt();
    }
    EXPECT_EQ(store.trial("S001", 0).lapsDone, 2);
    const SimulationSettings settings = settingsFor(store.protocol());
    int answers = 0;
    ASSERT_NO_THROW(answers = runSimulatedSession(store, "S001", ConfusionMatrix{}, 9, settings));
    EXPECT_EQ(answers, static_cast<int>(store.trials("S001").size()));
    EXPECT_EQ(store.trial("S001", 0).lapsDone, store.protocol().laps.total());
}

TEST(Honest, TheSessionStoresWhetherSoundWasPlayed) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"H", "ci", 1, "t"});
    store.registerParticipant({"P01", 30, "", "", "", {}, ""});
    SilentPlayer silent;
    {
        Session session(store, "P01", silent, {"exp", "none", "none", "t", false});
        session.interrupt();
    }
    {
        Session session(store, "P01", silent, {"exp", "jack", "none", "t", true});
        session.interrupt();
    }
    {
        Session session(store, "P01", silent, {"exp", "?", "none", "t", std::nullopt});
        session.interrupt();
    }
    const auto sessions = store.sessions("P01");
    ASSERT_EQ(sessions.size(), 3u);
    EXPECT_EQ(sessions[0].soundPlayed, std::optional<bool>(false));
    EXPECT_EQ(sessions[1].soundPlayed, std::optional<bool>(true));
    EXPECT_EQ(sessions[2].soundPlayed, std::nullopt);
    EXPECT_EQ(sessions[0].outcome, "interrupted");
    bool journaled = false;
    for (const auto& e : store.events())
        journaled =
            journaled || (e.kind == "session_started" &&
                          e.detail.find("\"sound\":\"none (data entry)\"") != std::string::npos);
    EXPECT_TRUE(journaled);
}

TEST(Honest, MessagesNumberTrialsFromOne) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"H", "ci", 1, "t"});
    store.registerParticipant({"P01", 30, "", "", "", {}, ""});
    try {
        store.trialForReplay("P01", 2); // the third trial, never presented
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("trial 3 was never presented"), std::string::npos)
            << e.what();
    }
}

TEST(Honest, SimulationTableIsChecked) {
    const std::string bad = miniProtocol("[simulation.confusion]\nnobody = \"data/x.csv\"\n");
    try {
        parseProtocol(bad, "bad.toml");
        FAIL();
    } catch (const ProtocolError& e) {
        EXPECT_NE(std::string(e.what()).find("group 'nobody'"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parseProtocol(miniProtocol("[simulation]\nconfusion = \"../x.csv\"\n"), "b.toml"),
                 ProtocolError);
    const Protocol ok = parseProtocol(miniProtocol("[simulation]\nconfusion = \"m.csv\"\n"),
                                      "/nonexistent/mini.toml");
    EXPECT_EQ(ok.simulation.confusion.at(""), "m.csv");
    try {
        defaultMatrices(ok);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("'m.csv', which is not found"), std::string::npos)
            << e.what();
    }
}

TEST(Honest, UnknownIdsGetASortedListAndTheClosestName) {
    EXPECT_EQ(closestName("gravle", {"wood", "gravel", "metal"}), "gravel");
    EXPECT_EQ(closestName("Wod", {"wood", "gravel", "metal"}), "wood");
    EXPECT_EQ(closestName("xyzzy", {"wood", "gravel", "metal"}), "");
    EXPECT_EQ(sortedIdsWithSuggestion("metl", {"wood", "metal", "gravel"}),
              "gravel, metal, wood (did you mean 'metal'?)");
    try {
        parseProtocol(miniProtocol("[[stimuli]]\nid = \"X\"\nsurface = \"gravle\"\n"), "x.toml");
        FAIL();
    } catch (const ProtocolError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("did you mean 'gravel'?"), std::string::npos) << what;
        EXPECT_NE(what.find("beach_sand, carpet, concrete"), std::string::npos) << what;
    }
}

TEST(Honest, ASimulatedSensorTrialRecordsItsControlStream) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"H", "ci", 2, "t"});
    simulateStudy(store, matricesFor(store.protocol()), 1, {});
    const auto code = store.participants().front().code;
    std::optional<std::string> first;
    for (const auto& t : store.trials(code)) {
        ASSERT_TRUE(t.grfRecording.has_value()) << t.index;
        // Readable text with the walker's parameters, the same for all of the participant's
        // trials, that reads back to what walked.
        if (!first) first = *t.grfRecording;
        EXPECT_EQ(*t.grfRecording, *first) << t.index;
        const auto walker = parseSimulatedWalker(*t.grfRecording);
        ASSERT_TRUE(walker.has_value()) << *t.grfRecording;
        EXPECT_EQ(walker->seconds, 50.0);
        for (const char* key : {"cadence", "mass", "shoe", "variability"})
            EXPECT_EQ(walker->walker.count(key), 1u) << key << " in " << *t.grfRecording;
        EXPECT_EQ(formatSimulatedWalker(*walker), *t.grfRecording);
        EXPECT_EQ(store.trialForReplay(code, t.index).renderSeed, t.plannedSeed);
    }
    ASSERT_TRUE(first.has_value());
    EXPECT_EQ(first->rfind(kSimulatedWalkerTablePrefix, 0), 0u) << *first;
    std::printf("stored control stream: %s\n", first->c_str());
}

TEST(Honest, SimulatedWalkerReferencesParseOrSayWhatWasExpected) {
    const auto w = drawSimulatedWalker(7, 12.5);
    const auto cadence = std::get<double>(w.walker.at("cadence"));
    EXPECT_GE(cadence, 90.0);
    EXPECT_LE(cadence, 120.0);
    const auto back = parseSimulatedWalker(formatSimulatedWalker(w));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->seconds, 12.5);
    EXPECT_EQ(back->walker, w.walker);
    // Studies stored before the parameters were: the default walker.
    const auto old = parseSimulatedWalker(std::string(kSimulatedWalkerPrefix) + "50");
    ASSERT_TRUE(old.has_value());
    EXPECT_EQ(old->seconds, 50.0);
    EXPECT_TRUE(old->walker.empty());
    EXPECT_FALSE(parseSimulatedWalker("recordings/grf_GL_001_seed3.wav").has_value());
    for (const std::string bad :
         {"virtual-walker: { seconds = 0 }", "virtual-walker: { seconds = 5, cadence = \"x\" }",
          "virtual-walker: seconds", "virtual-walker:seconds=abc", "virtual-walker: { }"}) {
        try {
            (void)parseSimulatedWalker(bad);
            ADD_FAILURE() << bad;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("expected"), std::string::npos) << e.what();
        }
    }
}
