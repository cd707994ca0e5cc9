// SPDX-License-Identifier: GPL-3.0-or-later
#include "TestSupport.h"
#include "experiment/Store.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <map>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
StudyStore makeStudy(const TempDir& dir, const std::string& protocolFile, std::uint64_t seed = 9) {
    return StudyStore::create(dir.file("study.db"), loadProtocol(shipped(protocolFile)),
                              {"ST1", "lab-a", seed, "test"});
}

NewParticipant person(const std::string& code) {
    return {code, 25, "f", "sneakers", "normal", std::nullopt, ""};
}

TrialAnswer exp2Answer(const std::string& answer, bool soundscape) {
    TrialAnswer a;
    a.answer = answer;
    a.ratings = {{"realism", 5}, {"quality", 4}};
    if (soundscape) a.soundscapeAnswer = "forest";
    return a;
}
} // namespace

TEST(ExperimentStore, CreateThenOpenKeepsStudyAndProtocol) {
    TempDir dir;
    {
        StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml");
        EXPECT_EQ(s.info().code, "ST1");
    }
    StudyStore s = StudyStore::open(dir.file("study.db"));
    const StudyInfo i = s.info();
    EXPECT_EQ(i.site, "lab-a");
    EXPECT_EQ(i.seed, 9u);
    EXPECT_EQ(i.protocolId, "tvcg2011_exp1");
    EXPECT_EQ(i.schemaVersion, kSchemaVersion);
    EXPECT_EQ(s.protocol().stimuli.size(), 13u);
    EXPECT_THROW(makeStudy(dir, "tvcg2011_exp1.toml"), StoreError); // file exists
}

TEST(ExperimentStore, DurabilityPragmas) {
    TempDir dir;
    { StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml"); }
    SQLite::Database db(dir.file("study.db"), SQLite::OPEN_READONLY);
    EXPECT_EQ(db.execAndGet("PRAGMA journal_mode").getString(), "wal");
    EXPECT_EQ(db.execAndGet("PRAGMA user_version").getInt(), kSchemaVersion);
}

TEST(ExperimentStore, ChangedProtocolIsRefused) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml");
    EXPECT_NO_THROW(s.verifyProtocol(loadProtocol(shipped("tvcg2011_exp1.toml"))));
    std::ifstream in(shipped("tvcg2011_exp1.toml"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find("repetitions = 2"), 15, "repetitions = 3");
    const Protocol changed = parseProtocol(text, "edited.toml");
    try {
        s.verifyProtocol(changed);
        FAIL() << "a changed protocol was accepted";
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("differs"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("edited.toml"), std::string::npos);
    }
}

TEST(ExperimentStore, TamperedProtocolTextOrNewerSchemaIsRefused) {
    TempDir dir;
    { StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml"); }
    {
        SQLite::Database db(dir.file("study.db"), SQLite::OPEN_READWRITE);
        db.exec("UPDATE protocol SET text = text || '\n# edited'");
    }
    EXPECT_THROW(StudyStore::open(dir.file("study.db")), StoreError);
    TempDir dir2;
    { StudyStore s = makeStudy(dir2, "tvcg2011_exp1.toml"); }
    {
        SQLite::Database db(dir2.file("study.db"), SQLite::OPEN_READWRITE);
        db.exec("PRAGMA user_version = 99");
    }
    try {
        StudyStore::open(dir2.file("study.db"));
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos);
    }
    EXPECT_THROW(StudyStore::open(dir2.file("absent.db")), StoreError);
    std::ofstream(dir2.file("junk.db")) << "not a database at all, just some text";
    EXPECT_THROW(StudyStore::open(dir2.file("junk.db")), StoreError);
}

TEST(ExperimentStore, JournalIsAppendOnly) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml");
    s.registerParticipant(person("P01"));
    const auto events = s.events();
    ASSERT_GE(events.size(), 2u);
    EXPECT_EQ(events[0].kind, "study_created");
    EXPECT_EQ(events[1].kind, "participant_registered");
    SQLite::Database db(dir.file("study.db"), SQLite::OPEN_READWRITE);
    EXPECT_THROW(db.exec("UPDATE events SET kind = 'x'"), SQLite::Exception);
    EXPECT_THROW(db.exec("DELETE FROM events"), SQLite::Exception);
}

TEST(ExperimentStore, BalancedAssignmentRefillsDroppedSlots) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp2.toml");
    std::map<std::string, int> counts;
    for (int i = 0; i < 9; ++i)
        ++counts[s.registerParticipant(person(fmt::format("P{:02}", i))).groupId];
    // Targets 15/15/13: after 9 registrations every group holds 3.
    EXPECT_EQ(counts["none"], 3);
    EXPECT_EQ(counts["coherent"], 3);
    EXPECT_EQ(counts["incoherent"], 3);
    // Two participants of "coherent" drop out: the next two go to "coherent".
    std::vector<std::string> coherent;
    for (const auto& p : s.participants())
        if (p.groupId == "coherent") coherent.push_back(p.code);
    s.dropParticipant(coherent[0], "felt dizzy");
    s.dropParticipant(coherent[1], "did not show up for session 2");
    EXPECT_EQ(s.registerParticipant(person("P09")).groupId, "coherent");
    EXPECT_EQ(s.registerParticipant(person("P10")).groupId, "coherent");
    const auto gc = s.groupCounts();
    for (const auto& g : gc)
        if (g.groupId == "coherent") {
            EXPECT_EQ(g.active, 3);
            EXPECT_EQ(g.dropped, 2);
        }
    EXPECT_THROW(s.dropParticipant("P00", ""), StoreError);
}

TEST(ExperimentStore, AssignmentFillsTheLeastCompleteGroupRelativeToTarget) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp2.toml");
    std::map<std::string, int> counts;
    for (int i = 0; i < 43; ++i)
        ++counts[s.registerParticipant(person(fmt::format("Q{:02}", i))).groupId];
    EXPECT_EQ(counts["none"], 15);
    EXPECT_EQ(counts["coherent"], 15);
    EXPECT_EQ(counts["incoherent"], 13);
}

TEST(ExperimentStore, OverrideNeedsAReasonAndIsJournaled) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp2.toml");
    NewParticipant np = person("P01");
    np.groupOverride = "incoherent";
    EXPECT_THROW(s.registerParticipant(np), StoreError);
    np.overrideReason = "only lab with the ski-slope recording today";
    const ParticipantInfo p = s.registerParticipant(np);
    EXPECT_EQ(p.groupId, "incoherent");
    EXPECT_EQ(p.assignment, Assignment::Override);
    EXPECT_EQ(s.trials("P01").size(), 12u);
    const auto events = s.events();
    EXPECT_NE(events.back().detail.find("only lab with the ski-slope"), std::string::npos);
    np.code = "P02";
    np.groupOverride = "martians";
    EXPECT_THROW(s.registerParticipant(np), StoreError);
    EXPECT_THROW(s.registerParticipant(person("P01")), StoreError);        // duplicate code
    EXPECT_THROW(s.registerParticipant(person("John Smith")), StoreError); // not a pseudonym
}

TEST(ExperimentStore, StoredPlanMatchesTheGeneratedPlan) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml", 77);
    s.registerParticipant(person("A"));
    const ParticipantInfo b = s.registerParticipant(person("B"));
    const auto plan = generatePlan(s.protocol(), "all", 77, b.index);
    const auto stored = s.trials("B");
    ASSERT_EQ(stored.size(), plan.size());
    for (std::size_t i = 0; i < plan.size(); ++i) {
        EXPECT_EQ(stored[i].stimulus, plan[i].stimulus);
        EXPECT_EQ(stored[i].plannedSeed, plan[i].plannedSeed);
        EXPECT_EQ(stored[i].repetition, plan[i].repetition);
        EXPECT_FALSE(stored[i].answered);
    }
}

// The store's contract: it keeps its schema's constraints and nothing of the protocol. An answer
// the protocol refuses (not on the answer list, a rating off its scale, a question missing) is
// stored when it fits the schema; the trial core (TrialFlow) refuses it before any front end or
// the simulation gets here (TrialFlow.ProtocolRulesAreTheTrialCoresNotTheStores).
TEST(ExperimentStore, KeepsOnlyTheSchemaNotTheProtocol) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp2.toml");
    NewParticipant np = person("P01");
    np.groupOverride = "coherent";
    np.overrideReason = "test";
    s.registerParticipant(np);
    const int session = s.startSession("P01", {"E1", "hp", "mics", "test"});
    // What the schema and the record's order refuse.
    EXPECT_THROW(s.commitAnswer("P01", 0, exp2Answer("gravel", true), 1.0), StoreError)
        << "answer before the stimulus started";
    EXPECT_THROW(s.commitAnswer("P01", 999, exp2Answer("gravel", true), 1.0), StoreError)
        << "no such trial";
    // Any index a request can carry is refused with its 1-based number, computed without
    // overflow.
    for (const int index : {std::numeric_limits<int>::max(), std::numeric_limits<int>::min()}) {
        try {
            s.trial("P01", index);
            ADD_FAILURE() << "trial " << index << " was found";
        } catch (const StoreError& e) {
            EXPECT_NE(
                std::string(e.what()).find(fmt::format("has no trial {}", std::int64_t{index} + 1)),
                std::string::npos)
                << e.what();
        }
    }
    EXPECT_THROW(s.commitAnswer("P99", 0, exp2Answer("gravel", true), 1.0), StoreError)
        << "no such participant";
    s.markTrialStarted("P01", 0, session, 123, std::string("grf/P01-0.wav"));
    EXPECT_THROW(s.commitAnswer("P01", 0, exp2Answer("gravel", true), std::nan("")), StoreError);
    EXPECT_THROW(s.commitAnswer("P01", 0, exp2Answer("gravel", true), -1.0), StoreError);
    TrialAnswer noScale = exp2Answer("gravel", true);
    noScale.ratings[""] = 3;
    EXPECT_THROW(s.commitAnswer("P01", 0, noScale, 1.0), StoreError);
    EXPECT_FALSE(s.trial("P01", 0).answered);
    // What only the protocol refuses is stored as given.
    TrialAnswer offProtocol = exp2Answer("lava", false); // not an option, soundscape missing
    offProtocol.ratings["realism"] = 8;                  // realism is 1-7
    offProtocol.ratings.erase("quality");                // quality is asked
    s.commitAnswer("P01", 0, offProtocol, 2.5);
    TrialRecord t = s.trial("P01", 0);
    EXPECT_TRUE(t.answered);
    EXPECT_EQ(t.answer.answer, "lava");
    EXPECT_EQ(t.answer.ratings.at("realism"), 8);
    EXPECT_EQ(t.answer.ratings.count("quality"), 0u);
    EXPECT_EQ(t.answer.soundscapeAnswer, "");
    EXPECT_DOUBLE_EQ(*t.responseTimeS, 2.5);
    // One answer per trial: a second commit replaces it (ratings included), journaled.
    s.commitAnswer("P01", 0, exp2Answer("gravel", true), 3.0);
    t = s.trial("P01", 0);
    EXPECT_EQ(t.answer.answer, "gravel");
    EXPECT_EQ(t.answer.ratings.at("realism"), 5);
    EXPECT_EQ(t.answer.soundscapeAnswer, "forest");
    SQLite::Database db(dir.file("study.db"), SQLite::OPEN_READONLY);
    EXPECT_EQ(db.execAndGet("SELECT count(*) FROM ratings r JOIN trials t ON t.id = r.trial_id "
                            "WHERE t.trial_index = 0 AND r.scale = 'realism'")
                  .getInt(),
              1);
    int changed = 0;
    for (const auto& e : s.events()) changed += e.kind == "answer_changed" ? 1 : 0;
    EXPECT_EQ(changed, 1);
    EXPECT_EQ(s.firstUnanswered("P01"), 1);
}

// The lock rule is the protocol's, so the trial core keeps it (TrialFlow.LockRule*): the store
// replaces an answer even after a later trial started.
TEST(ExperimentStore, ReplacesAnAnswerWhateverTheLockRule) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml");
    s.registerParticipant(person("P01"));
    const int session = s.startSession("P01", {"E1", "hp", "mics", "test"});
    s.markTrialStarted("P01", 0, session, 1, std::nullopt);
    TrialAnswer a;
    a.answer = "wood";
    s.commitAnswer("P01", 0, a, 1.0);
    s.markTrialStarted("P01", 1, session, 2, std::nullopt);
    a.answer = "gravel";
    EXPECT_NO_THROW(s.commitAnswer("P01", 0, a, 2.0));
    EXPECT_EQ(s.trial("P01", 0).answer.answer, "gravel");
    bool changed = false;
    for (const auto& e : s.events()) changed = changed || e.kind == "answer_changed";
    EXPECT_TRUE(changed);
}

TEST(ExperimentStore, ReplayInfoExclusionAndDroppedSessions) {
    TempDir dir;
    StudyStore s = makeStudy(dir, "tvcg2011_exp1.toml");
    s.registerParticipant(person("P07"));
    EXPECT_THROW(s.trialForReplay("P07", 0), StoreError); // never presented
    const int session = s.startSession("P07", {"E1", "RME Fireface, 44.1 kHz", "4 mics", "t"});
    s.markTrialStarted("P07", 0, session, 0xfeedbeefcafeull, std::string("grf/P07/t00.wav"));
    const ReplayInfo r = s.trialForReplay("P07", 0);
    EXPECT_EQ(r.renderSeed, 0xfeedbeefcafeull);
    EXPECT_EQ(r.grfRecording, "grf/P07/t00.wav");
    EXPECT_EQ(r.stimulus, s.trials("P07")[0].stimulus);
    EXPECT_EQ(r.audioConfig, "RME Fireface, 44.1 kHz");
    EXPECT_EQ(r.protocolHash, s.protocol().hash);
    EXPECT_THROW(s.setExcluded("P07", 0, true, ""), StoreError);
    s.setExcluded("P07", 0, true, "participant stopped walking");
    EXPECT_TRUE(s.trial("P07", 0).excluded);
    EXPECT_THROW(s.setExcluded("P07", 99, true, "x"), StoreError);
    s.dropParticipant("P07", "withdrew consent");
    EXPECT_THROW(s.startSession("P07", {}), StoreError);
}

TEST(ExperimentStore, ForeignSqliteFileIsNotAStudy) {
    TempDir dir;
    {
        SQLite::Database db(dir.file("other.db"), SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
        db.exec("CREATE TABLE notes (text TEXT)");
    }
    try {
        StudyStore::open(dir.file("other.db"));
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("not an Underfoot study"), std::string::npos);
    }
}
