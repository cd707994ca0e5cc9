// SPDX-License-Identifier: GPL-3.0-or-later
// The runner's listening-test and lap modes (TrialFlow start / replay / setRating / commit /
// completeLap), participant fields, clip rendering through engine/wading and the clip manifest,
// and the migration of version-1 study files.
#include "StudySupport.h"
#include "engine/io/AudioFile.h"
#include "engine/wading/Wading.h"
#include "experiment/Clips.h"
#include "experiment/Session.h"
#include "experiment/TrialFlow.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>

using namespace underfoot;
using namespace underfoot::experiment;
using namespace underfoot::wading::test;

namespace {

/// Records what the session asks of the player.
class RecordingPlayer final : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus& s, std::uint64_t seed) override {
        log.push_back("start " + s.id + (muted ? " muted" : ""));
        return {seed, std::nullopt};
    }
    void stop() override { log.push_back("stop"); }
    void setMuted(bool m) override {
        muted = m;
        log.push_back(m ? "mute" : "unmute");
    }
    std::vector<std::string> log;
    bool muted = false;
};

/// Renders every clip of a protocol as `underfoot clips` does (engine/wading for wading
/// stimuli), shortened to `seconds` to keep the test fast, and writes the manifest.
void renderClips(const Protocol& p, const std::string& dir, double seconds) {
    std::vector<ClipRecord> records;
    for (auto job : clipJobs(p, dir)) {
        ClipRecord r{job.stimulus.id,
                     std::filesystem::path(job.path).lexically_relative(dir).string(),
                     job.source,
                     job.seed,
                     seconds,
                     0,
                     0,
                     {},
                     {}};
        if (job.source == ClipSource::Wading) {
            auto options =
                engine::wadingOptionsFromParameters(parameterStrings(job.stimulus.wading));
            options.seed = job.seed;
            options.sampleRateHz = 16000;
            const auto audio = engine::renderWading(options, seconds);
            engine::writeAudioFile(job.path, audio);
            r.sampleRateHz = audio.sampleRateHz;
            r.frames = audio.frames();
        }
        r.sha256 = fileSha256(job.path);
        records.push_back(r);
    }
    writeClipManifest(dir, records);
}

} // namespace

// A manifest's numbers are whole cells: "7abc" and "-1" were read as 7 and 2^64 - 1, and an
// unknown source as "lab" (found reviewing fuzz_clip_manifest).
TEST(WadingListeningMode, ClipManifestRefusesPartNumbersNegativeSeedsAndUnknownSources) {
    const std::string dir = scratchFile("manifest_numbers");
    std::filesystem::create_directories(dir);
    const auto read = [&](const std::string& row) {
        std::ofstream(dir + "/" + kClipManifest)
            << "stimulus_id,file,source,seed,seconds,sample_rate_hz,frames,sha256\n"
            << row << "\n";
        try {
            const auto m = readClipManifest(dir);
            return fmt::format("(accepted seed {})", m.at(0).seed);
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
    };
    EXPECT_EQ(read("a,a.wav,lab,18446744073709551615,2.5,48000,120000,00"),
              "(accepted seed 18446744073709551615)");
    const auto has = [](const std::string& message, const std::string& part) {
        return message.find(part) != std::string::npos;
    };
    EXPECT_TRUE(has(read("a,a.wav,lab,7abc,2.5,48000,120000,00"),
                    "clips.csv:2: seed '7abc': expected a whole number"))
        << read("a,a.wav,lab,7abc,2.5,48000,120000,00");
    EXPECT_TRUE(has(read("a,a.wav,lab,-1,2.5,48000,120000,00"), "seed '-1'"));
    EXPECT_TRUE(has(read("a,a.wav,lab,1,2.5s,48000,120000,00"), "seconds '2.5s'"));
    EXPECT_TRUE(has(read("a,a.wav,lab,1,2.5,48000,-5,00"), "frames '-5'"));
    EXPECT_TRUE(has(read("a,a.wav,studio,1,2.5,48000,5,00"),
                    "source 'studio': expected wading, footsteps or lab"));
}

TEST(WadingListeningMode, ClipsRenderThroughTheWadingEngineWithStoredSeeds) {
    const Protocol p = loadProtocol(shippedProtocol("wading_listening.toml"));
    const std::string dir = scratchFile("clips");
    std::filesystem::create_directories(dir);
    EXPECT_FALSE(checkClips(p, dir).empty()) << "nothing rendered yet";
    renderClips(p, dir, 1.0);
    EXPECT_TRUE(checkClips(p, dir).empty());
    const auto manifest = readClipManifest(dir);
    ASSERT_EQ(manifest.size(), 6u);
    for (const auto& r : manifest) {
        EXPECT_EQ(r.seed, clipSeed(p, *p.stimulus(r.stimulusId)));
        EXPECT_EQ(r.frames, 16000u);
    }
    // Same protocol, same seed: byte-identical clips (the manifest's SHA-256 matches a rerender).
    const std::string again = scratchFile("clips_again");
    std::filesystem::create_directories(again);
    renderClips(p, again, 1.0);
    EXPECT_EQ(readClipManifest(again)[3].sha256, manifest[3].sha256);
    // Deep is louder than shallow at the same cadence (the clips carry the depth).
    const auto deep = engine::readAudioFile(dir + "/wade_deep_110.wav");
    const auto shallow = engine::readAudioFile(dir + "/wade_shallow_110.wav");
    double eDeep = 0, eShallow = 0;
    for (float v : deep.samples) eDeep += double(v) * v;
    for (float v : shallow.samples) eShallow += double(v) * v;
    EXPECT_GT(eDeep, eShallow);
    // A changed file is caught before a session starts.
    { std::ofstream(dir + "/wade_deep_80.wav", std::ios::app) << "x"; }
    const auto problems = checkClips(p, dir);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].find("wade_deep_80.wav changed since it was rendered"),
              std::string::npos);
    EXPECT_THROW(ClipPlayer(p, dir), StoreError);
}

TEST(WadingListeningMode, ClipsArePlayedOnDemandReplaysCountedAndRatedScaleByScale) {
    const Protocol p = loadProtocol(shippedProtocol("wading_listening.toml"));
    const std::string dir = scratchFile("clips");
    std::filesystem::create_directories(dir);
    renderClips(p, dir, 0.5);
    StudyStore store = StudyStore::create(scratchFile("l.db"), p, {"L", "lab", 4, "t"});
    store.registerParticipant({"P1", 30, "f", "", "", {}, ""});
    std::vector<std::string> played;
    ClipPlayer player(store.protocol(), dir,
                      [&](const std::string& path) { played.push_back(path); });
    Session session(store, "P1", player, {"exp", "headphones", "", "t"});
    TrialFlow flow(store, session);
    session.finishBriefing();
    flow.reset();
    const TrialRecord first = session.current();
    ASSERT_EQ(session.askedScales().size(), 1u);
    EXPECT_EQ(session.askedScales()[0]->id, "depth");
    EXPECT_EQ(flow.commit().refusal, Refusal::NotStarted) << "an answer before the clip played";
    ASSERT_TRUE(flow.start());
    ASSERT_TRUE(flow.replay());
    ASSERT_TRUE(flow.start()); // a second start of a clip replays it
    EXPECT_EQ(session.replayCount(), 2);
    ASSERT_EQ(played.size(), 3u);
    EXPECT_EQ(played[0], dir + "/" + first.stimulus.id + ".wav");
    EXPECT_EQ(flow.setRating("depth", 11).refusal, Refusal::OutOfRange);
    EXPECT_EQ(flow.setRating("speed", 3).refusal, Refusal::NotAllowed)
        << "speed is the next block's scale";
    EXPECT_FALSE(flow.problems().empty());
    ASSERT_TRUE(flow.setRating("depth", 4));
    ASSERT_TRUE(flow.setRating("depth", 6)); // changed before submitting
    EXPECT_TRUE(flow.problems().empty());
    ASSERT_TRUE(flow.commit());
    const TrialRecord stored = store.trial("P1", first.index);
    EXPECT_EQ(stored.replays, 2);
    EXPECT_EQ(stored.answer.ratings.at("depth"), 6);
    EXPECT_EQ(stored.answer.ratings.size(), 1u);
    EXPECT_EQ(*stored.renderSeed, clipSeed(p, first.stimulus)) << "the clip's seed is recorded";
    int replayEvents = 0;
    for (const auto& e : store.events()) replayEvents += e.kind == "clip_replayed" ? 1 : 0;
    EXPECT_EQ(replayEvents, 2);
    // A missing rating is refused by the trial core before anything is stored.
    ASSERT_TRUE(flow.start());
    EXPECT_EQ(flow.commit().refusal, Refusal::Incomplete);
    EXPECT_FALSE(store.trial("P1", session.current().index).answered);
}

TEST(WadingListeningMode, LapsAreWalkedSilentThenWithSoundBeforeTheQuestions) {
    StudyStore store = StudyStore::create(scratchFile("i.db"),
                                          loadProtocol(shippedProtocol("wading_interactive.toml")),
                                          {"I", "lab", 2, "t"});
    store.registerParticipant({"P1", std::nullopt, "", "", "", {}, ""});
    RecordingPlayer player;
    Session session(store, "P1", player, {"exp", "", "gyro", "t"});
    TrialFlow flow(store, session);
    session.finishBriefing();
    flow.reset();
    EXPECT_EQ(session.lapCount(), 6);
    EXPECT_THROW(session.completeLap(), std::logic_error) << "the condition has not started";
    session.play();
    EXPECT_EQ(player.log.front(), "mute");
    EXPECT_TRUE(session.currentLapSilent());
    TrialAnswer a;
    for (const Scale* s : session.askedScales()) a.ratings[s->id] = 4;
    EXPECT_EQ(flow.submit(a).refusal, Refusal::LapsPending)
        << "questions before the laps are walked";
    for (int lap = 1; lap <= 6; ++lap) {
        EXPECT_EQ(session.currentLapSilent(), lap <= 3);
        session.completeLap();
    }
    EXPECT_THROW(session.completeLap(), std::logic_error);
    EXPECT_EQ(std::count(player.log.begin(), player.log.end(), "unmute"), 1);
    ASSERT_TRUE(flow.submit(a));
    const auto t = store.trial("P1", 0);
    EXPECT_EQ(t.lapsDone, 6);
    std::vector<std::string> laps;
    for (const auto& e : store.events())
        if (e.kind == "lap_completed") laps.push_back(e.detail);
    ASSERT_EQ(laps.size(), 6u);
    EXPECT_NE(laps[2].find("silent baseline"), std::string::npos);
    EXPECT_NE(laps[3].find("feedback"), std::string::npos);
}

TEST(WadingListeningMode, ParticipantFieldsAreValidatedStoredAndExported) {
    StudyStore store = StudyStore::create(scratchFile("r.db"),
                                          loadProtocol(shippedProtocol("wading_realism.toml")),
                                          {"R", "lab", 2, "t"});
    const NewParticipant np{"P1", 44, "m", "", "", {}, ""};
    EXPECT_THROW(store.registerParticipant(np), StoreError) << "required fields missing";
    std::map<std::string, std::string> fields{{"music_expertise", "none"},
                                              {"audio_expertise", "professional"},
                                              {"listening_device", "laptop"}};
    try {
        store.registerParticipant(np, fields);
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("'listening_device' is 'laptop'; expected one of"),
                  std::string::npos);
    }
    fields["listening_device"] = "laptop_speakers";
    fields["shoe_size"] = "44";
    EXPECT_THROW(store.registerParticipant(np, fields), StoreError);
    fields.erase("shoe_size");
    EXPECT_EQ(store.registerParticipant(np, fields).fields, fields);
    EXPECT_EQ(store.participant("P1").fields.at("audio_expertise"), "professional");
    std::ostringstream out;
    writeParticipantsCsv(store, out);
    EXPECT_EQ(out.str(), "participant,group,status,simulated,age,gender,shoes,hearing,"
                         "music_expertise,audio_expertise,listening_device\r\n"
                         "P1,all,registered,0,44,m,,,none,professional,laptop_speakers\r\n");
}

TEST(WadingListeningMode, VersionOneStudyFilesAreMigrated) {
    const std::string path = scratchFile("v1.db");
    {
        StudyStore store = StudyStore::create(
            path, loadProtocol(shippedProtocol("wading_listening.toml")), {"M", "lab", 3, "t"});
        store.registerParticipant({"P1", std::nullopt, "", "", "", {}, ""});
    }
    {
        // Turn the file back into schema version 1 (what Underfoot wrote before this version).
        SQLite::Database db(path, SQLite::OPEN_READWRITE);
        for (const char* column :
             {"clip_file", "clip_seconds", "clip_frames", "clip_sample_rate_hz", "clip_sha256"})
            db.exec(std::string("ALTER TABLE trials DROP COLUMN ") + column); // version 7's
        db.exec("DROP TABLE IF EXISTS session_leases");                       // version 6's
        for (const char* column :
             {"audio_sample_rate_hz", "audio_block_size", "audio_frames", "audio_xruns",
              "audio_average_load_percent", "audio_max_load_percent", "audio_max_block_ms",
              "audio_dropped_grf_frames", "sensor_log", "interruptions", "interruption_reason"})
            db.exec(std::string("ALTER TABLE trials DROP COLUMN ") + column); // version 3's
        db.exec("ALTER TABLE participants DROP COLUMN simulated");            // version 4's
        db.exec("ALTER TABLE sessions DROP COLUMN sound_played");
        db.exec("DROP TABLE participant_fields");
        db.exec("ALTER TABLE trials DROP COLUMN replays");
        db.exec("ALTER TABLE trials DROP COLUMN laps_done");
        db.exec("PRAGMA user_version = 1");
    }
    StudyStore store = StudyStore::open(path);
    EXPECT_EQ(store.info().schemaVersion, kSchemaVersion);
    EXPECT_GE(kSchemaVersion, 3);
    const auto trials = store.trials("P1");
    ASSERT_EQ(trials.size(), 24u);
    EXPECT_EQ(trials[0].replays, 0);
    EXPECT_TRUE(store.participant("P1").fields.empty());
    bool journaled = false;
    for (const auto& e : store.events())
        journaled =
            journaled || (e.kind == "schema_migrated" && e.detail == R"({"from":"1","to":"2"})");
    EXPECT_TRUE(journaled);
    EXPECT_FALSE(store.participant("P1").simulated); // migrated participants are real
    // The migrated study runs on: two simulated participants complete it; P1 (real) untouched.
    EXPECT_EQ(simulateStudy(store, {{"", ConfusionMatrix{}}}, 2, {}), 48);
    EXPECT_EQ(store.trials("P1")[0].answered, false);
}
