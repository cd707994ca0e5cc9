// SPDX-License-Identifier: GPL-3.0-or-later
// Schema 3: per-trial audio figures, the sensor log reference and sensor-fault pauses.
#include "TestSupport.h"
#include "experiment/Export.h"
#include "experiment/Session.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <sstream>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {

/// A live-like player: reports figures after stop(), a sensor log per start, and a settable fault.
class LiveLikePlayer : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus&, std::uint64_t plannedSeed) override {
        ++starts;
        playing = true;
        StimulusStart s{plannedSeed, "grf/" + std::to_string(starts) + ".wav", std::nullopt};
        s.sensorLog = "grf/" + std::to_string(starts) + ".sensors.csv";
        return s;
    }
    void stop() override {
        if (!playing) return;
        playing = false;
        TrialAudioStats a;
        a.sampleRateHz = 48000;
        a.blockSize = 64;
        a.frames = 4800u * static_cast<unsigned>(starts);
        a.xruns = static_cast<unsigned>(starts) - 1u;
        a.averageLoadPercent = 1.25;
        a.maxLoadPercent = 7.5;
        a.maxBlockMs = 0.1;
        a.droppedGrfFrames = 0;
        stats = a;
    }
    std::optional<TrialAudioStats> stoppedTrialStats() const override { return stats; }
    std::optional<std::string> sensorFault() const override { return fault; }

    int starts = 0;
    bool playing = false;
    std::optional<TrialAudioStats> stats;
    std::optional<std::string> fault;
};

TrialAnswer answerFor(const TrialRecord& t) {
    TrialAnswer a;
    a.answer = t.stimulus.surface == "wood_reverb" ? "wood" : t.stimulus.surface;
    a.ratings["realism"] = 4;
    return a;
}

/// Turns a current file back into what version `version` (1 or 2) wrote.
void downgrade(const std::string& path, int version) {
    SQLite::Database db(path, SQLite::OPEN_READWRITE);
    for (const char* column : // version 7's: the clip a listening-test trial played
         {"clip_file", "clip_seconds", "clip_frames", "clip_sample_rate_hz", "clip_sha256"})
        db.exec(std::string("ALTER TABLE trials DROP COLUMN ") + column);
    db.exec("DROP TABLE IF EXISTS session_leases"); // version 6's
    db.exec("DROP TABLE IF EXISTS online_answers"); // version 5's
    db.exec("DROP TABLE IF EXISTS online_sessions");
    db.exec("DROP TABLE IF EXISTS online_invitations");
    db.exec("ALTER TABLE participants DROP COLUMN simulated"); // version 4's
    db.exec("ALTER TABLE sessions DROP COLUMN sound_played");
    for (const char* column :
         {"audio_sample_rate_hz", "audio_block_size", "audio_frames", "audio_xruns",
          "audio_average_load_percent", "audio_max_load_percent", "audio_max_block_ms",
          "audio_dropped_grf_frames", "sensor_log", "interruptions", "interruption_reason"})
        db.exec(std::string("ALTER TABLE trials DROP COLUMN ") + column);
    if (version == 1) {
        db.exec("DROP TABLE participant_fields");
        db.exec("ALTER TABLE trials DROP COLUMN replays");
        db.exec("ALTER TABLE trials DROP COLUMN laps_done");
    }
    db.exec("PRAGMA user_version = " + std::to_string(version));
}

} // namespace

TEST(ExperimentTrialAudio, VersionOneAndTwoStudiesAreMigratedToThree) {
    ASSERT_GE(kSchemaVersion, 3);
    for (const int from : {1, 2}) {
        TempDir dir;
        const std::string path = dir.file("old.db");
        {
            StudyStore store = StudyStore::create(path, parseProtocol(miniProtocol(), "m.toml"),
                                                  {"M", "lab", 3, "t"});
            store.registerParticipant({"P1", {}, "", "", "", {}, ""});
            store.markTrialStarted("P1", 0, store.startSession("P1", {}), 11, "grf/a.wav");
        }
        downgrade(path, from);
        {
            SQLite::Database db(path, SQLite::OPEN_READONLY);
            EXPECT_EQ(db.execAndGet("PRAGMA user_version").getInt(), from);
        }
        StudyStore store = StudyStore::open(path);
        EXPECT_EQ(store.info().schemaVersion, kSchemaVersion) << "from " << from;
        const TrialRecord t = store.trial("P1", 0);
        EXPECT_EQ(t.grfRecording, "grf/a.wav");
        EXPECT_FALSE(t.audio);
        EXPECT_FALSE(t.sensorLog);
        EXPECT_EQ(t.interruptions, 0);
        int migrations = 0;
        for (const auto& e : store.events())
            if (e.kind == "schema_migrated") ++migrations;
        EXPECT_EQ(migrations, kSchemaVersion - from);
        // The migrated file stores the new figures.
        TrialAudioStats a;
        a.sampleRateHz = 44100;
        a.blockSize = 128;
        a.frames = 1000;
        a.xruns = 2;
        store.recordTrialAudio("P1", 0, a);
        store.setSensorLog("P1", 0, "grf/a.sensors.csv");
        const TrialRecord u = store.trial("P1", 0);
        ASSERT_TRUE(u.audio);
        EXPECT_EQ(u.audio->blockSize, 128);
        EXPECT_EQ(u.audio->xruns, 2u);
        EXPECT_EQ(u.sensorLog, "grf/a.sensors.csv");
    }
}

TEST(ExperimentTrialAudio, SessionStoresFiguresAndPausesOnSensorFaults) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("s.db"), parseProtocol(miniProtocol("", "repetitions = 1\n"), "m.toml"),
        {"S", "lab", 3, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    LiveLikePlayer player;
    double now = 10.0;
    Session session(store, "P1", player, {"E", "a", "s", "t"}, [&] { return now; });
    session.finishBriefing();

    // Trial 0 runs cleanly: its figures and sensor log are stored with it.
    session.play();
    EXPECT_FALSE(session.checkSensors());
    now += 2.0;
    session.answer(answerFor(session.current()));
    TrialRecord t0 = store.trial("P1", 0);
    ASSERT_TRUE(t0.audio);
    EXPECT_EQ(t0.audio->frames, 4800u);
    EXPECT_EQ(t0.audio->blockSize, 64);
    EXPECT_DOUBLE_EQ(t0.audio->sampleRateHz, 48000.0);
    EXPECT_EQ(t0.sensorLog, "grf/1.sensors.csv");

    // Trial 1: the sensor fails while it plays; the poll pauses the session.
    session.play();
    const int faulted = session.current().index;
    player.fault = "disconnected: port closed";
    EXPECT_TRUE(session.checkSensors());
    EXPECT_TRUE(session.paused());
    EXPECT_FALSE(player.playing);
    EXPECT_EQ(session.pauseReason(), "disconnected: port closed");
    EXPECT_THROW(session.answer(answerFor(session.current())), std::logic_error);
    EXPECT_THROW(session.play(), std::logic_error);
    EXPECT_THROW(session.resumeAfterFault(), std::logic_error); // still failing
    TrialRecord t1 = store.trial("P1", faulted);
    EXPECT_FALSE(t1.answered);
    EXPECT_EQ(t1.interruptions, 1);
    EXPECT_EQ(t1.interruptionReason, "disconnected: port closed");
    ASSERT_TRUE(t1.audio); // the broken presentation's figures are kept for the record
    EXPECT_EQ(t1.audio->frames, 9600u);

    // The sensor is back: the same trial is presented again and answered.
    player.fault.reset();
    session.resumeAfterFault();
    EXPECT_FALSE(session.paused());
    EXPECT_EQ(session.current().index, faulted);
    session.play();
    // A fault between two polls is caught at answer time: no broken trial is committed.
    player.fault = "silent: no frame for 420 ms";
    EXPECT_THROW(session.answer(answerFor(session.current())), StoreError);
    EXPECT_TRUE(session.paused());
    EXPECT_FALSE(store.trial("P1", faulted).answered);
    EXPECT_EQ(store.trial("P1", faulted).interruptions, 2);
    player.fault.reset();
    session.resumeAfterFault();
    session.play();
    session.answer(answerFor(session.current()));
    t1 = store.trial("P1", faulted);
    EXPECT_TRUE(t1.answered);
    EXPECT_EQ(t1.interruptions, 2);
    ASSERT_TRUE(t1.audio);
    EXPECT_EQ(t1.audio->frames, 4800u * 4u); // the fourth start's figures (the valid one)
    EXPECT_EQ(t1.sensorLog, "grf/4.sensors.csv");

    bool interrupted = false, restored = false;
    for (const auto& e : store.events()) {
        interrupted = interrupted || (e.kind == "trial_interrupted" && e.trialIndex == faulted);
        restored = restored || e.kind == "sensor_restored";
    }
    EXPECT_TRUE(interrupted);
    EXPECT_TRUE(restored);

    // The audio CSV carries the figures; trials.csv keeps its contract columns.
    std::ostringstream out;
    EXPECT_EQ(writeAudioCsv(store, out), 2);
    std::istringstream lines(out.str());
    std::string header, row0, row1;
    std::getline(lines, header);
    std::getline(lines, row0);
    std::getline(lines, row1);
    EXPECT_EQ(header.substr(0, header.find("\r")),
              "study,participant,trial_index,stimulus_id,session,answered,excluded,sample_rate_hz,"
              "block_size,frames,xruns,average_load_percent,max_load_percent,max_block_ms,"
              "dropped_grf_frames,grf_recording,sensor_log,interruptions,interruption_reason,"
              "started_at,answered_at");
    EXPECT_NE(
        row0.find(",1,0,48000,64,4800,0,1.250,7.500,0.1000,0,grf/1.wav,grf/1.sensors.csv,0,,"),
        std::string::npos)
        << row0;
    EXPECT_NE(row1.find(",19200,3,1.250,7.500,0.1000,0,grf/4.wav,grf/4.sensors.csv,2,silent: no "
                        "frame for 420 ms,"),
              std::string::npos)
        << row1;
}

TEST(ExperimentTrialAudio, PlayersWithoutLiveOutputReportNothing) {
    SilentPlayer silent;
    EXPECT_FALSE(silent.stoppedTrialStats());
    EXPECT_FALSE(silent.sensorFault());
}
