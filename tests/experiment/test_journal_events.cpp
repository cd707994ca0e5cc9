// SPDX-License-Identifier: GPL-3.0-or-later
// The journal's events: one enum (experiment/JournalEvent.h) that every writer names, read back
// strictly, and listed in docs/reference/store-schema.md exactly as in the enum.
#include "TestSupport.h"
#include "experiment/JournalEvent.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
std::string schemaDoc() {
    // tests/experiment/data -> the project's docs/reference/store-schema.md
    const std::string path =
        std::string(UNDERFOOT_EXPERIMENT_DATA) + "/../../../docs/reference/store-schema.md";
    std::ifstream in(path);
    EXPECT_TRUE(in) << path;
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}
} // namespace

TEST(JournalEvents, NamesAreUniqueAndReadBack) {
    std::set<std::string_view> names;
    for (const auto& e : kJournalEvents) {
        EXPECT_TRUE(names.insert(e.name).second) << "duplicate " << e.name;
        EXPECT_FALSE(e.meaning.empty()) << e.name;
        for (const char c : e.name) EXPECT_TRUE((c >= 'a' && c <= 'z') || c == '_') << e.name;
        EXPECT_EQ(journalEventFromName(e.name), e.event);
        EXPECT_EQ(journalEventName(e.event), e.name);
    }
    EXPECT_FALSE(journalEventFromName("made_up"));
    EXPECT_FALSE(journalEventFromName(""));
}

// The reference's table lists every event with the enum's meaning and fields, and nothing else.
TEST(JournalEvents, TheReferenceListsExactlyTheEnum) {
    const std::string doc = schemaDoc();
    const auto start = doc.find("## Journal events");
    ASSERT_NE(start, std::string::npos);
    const auto end = doc.find("\n## ", start + 1);
    std::istringstream section(doc.substr(start, end == std::string::npos ? end : end - start));
    std::map<std::string, std::string> listed;
    for (std::string line; std::getline(section, line);) {
        if (line.rfind("| `", 0) != 0) continue;
        const auto close = line.find('`', 3);
        ASSERT_NE(close, std::string::npos) << line;
        EXPECT_TRUE(listed.emplace(line.substr(3, close - 3), line).second) << "twice: " << line;
    }
    for (const auto& e : kJournalEvents) {
        const auto it = listed.find(std::string(e.name));
        if (it == listed.end()) {
            ADD_FAILURE() << "docs/reference/store-schema.md does not list '" << e.name << "'";
            continue;
        }
        const std::string expected = "| `" + std::string(e.name) + "` | " + std::string(e.meaning) +
                                     " | " + (e.fields.empty() ? "—" : std::string(e.fields)) +
                                     " |";
        EXPECT_EQ(it->second, expected);
        listed.erase(it);
    }
    for (const auto& [name, line] : listed)
        ADD_FAILURE() << "docs/reference/store-schema.md lists '" << name
                      << "', which is not a JournalEvent";
}

// A name outside the enum (another program's row, a damaged file) is refused with the file and
// the row; nothing is lost (the row stays, the journal is append-only).
TEST(JournalEvents, AnUnknownStoredNameIsRefusedWithFileAndRow) {
    TempDir dir;
    const std::string path = dir.file("j.db");
    {
        StudyStore store =
            StudyStore::create(path, parseProtocol(miniProtocol(), "m.toml"), {"J", "lab", 3, "t"});
        store.registerParticipant({"P1", {}, "", "", "", {}, ""});
        for (const auto& e : store.events()) EXPECT_EQ(e.kind, journalEventName(e.event));
    }
    std::int64_t row = 0;
    {
        SQLite::Database db(path, SQLite::OPEN_READWRITE);
        db.exec("INSERT INTO events (at, kind, detail) VALUES ('2026-01-01T00:00:00.000Z', "
                "'made_up', '{}')");
        row = db.getLastInsertRowid();
    }
    StudyStore store = StudyStore::open(path);
    try {
        (void)store.events();
        ADD_FAILURE() << "an unknown event name was read";
    } catch (const StoreError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(path), std::string::npos) << m;
        EXPECT_NE(m.find("row " + std::to_string(row)), std::string::npos) << m;
        EXPECT_NE(m.find("'made_up'"), std::string::npos) << m;
    }
}

// Everything a whole simulated study writes (registration, sessions, trials, answers, breaks)
// reads back as a JournalEvent.
TEST(JournalEvents, ASimulatedStudyWritesOnlyEnumEvents) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), loadProtocol(shipped("tvcg2011_exp1.toml")), {"S", "lab", 5, "t"});
    MatrixByGroup m;
    m[""] = loadConfusionMatrix(dataFile("tvcg2011_exp1_confusion.csv"));
    ASSERT_GT(simulateStudy(store, m, 2, SimulationSettings{}), 0);
    std::set<JournalEvent> seen;
    for (const auto& e : store.events()) seen.insert(e.event);
    for (const JournalEvent e : {JournalEvent::StudyCreated, JournalEvent::ParticipantRegistered,
                                 JournalEvent::SessionStarted, JournalEvent::TrialStarted,
                                 JournalEvent::Answered, JournalEvent::SessionEnded})
        EXPECT_TRUE(seen.count(e)) << journalEventName(e);
}
