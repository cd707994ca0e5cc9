// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The study store: one SQLite file per study (schema with a version and explicit migrations).
///
/// Durability: WAL journal, synchronous=FULL, and every answer committed in its own transaction
/// before the call returns, so an acknowledged answer survives a crash or a power loss. The event
/// journal is append-only (triggers refuse UPDATE and DELETE). The protocol's full text and
/// SHA-256 are stored; a different protocol text is refused for an existing study.
#include "experiment/JournalEvent.h"
#include "experiment/Plan.h"
#include "experiment/Protocol.h"

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace SQLite {
class Database;
class Statement;
} // namespace SQLite

namespace underfoot::experiment {

/// An error about a study file (wrong schema, protocol hash mismatch, unknown participant,
/// locked answer...). The message names the file and what was expected.
struct StoreError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// The participant's session lease is held by a live process on this host (which may still
/// write): the session cannot start now; it can once that process ends.
struct LeaseHeld : StoreError {
    using StoreError::StoreError;
};

/// The answer was committed (durably, in the study's write-ahead log `<study>-wal`), but copying
/// it into the study file failed afterwards. The answer counts: a session advances past it and
/// must not ask for it again (asking again would store it as a changed answer). The message
/// says so, names the file and the cause, and says to keep the -wal file beside the study.
struct AnswerSavedButNotCopied : StoreError {
    using StoreError::StoreError;
};

/// Current schema version written by this code.
/// Version 2 adds clip replay counts and laps walked per trial, and participant fields
/// (expertise, listening device...); version 3 adds per-trial audio figures (TrialAudioStats),
/// the sensor log reference and sensor-fault interruptions; version 4 flags simulated
/// participants and stores with each session whether sound was played; version 5 adds the
/// online tables of `underfoot serve` (experiment/Invitations.h); version 6 adds
/// session leases: one live session per participant; version 7 stores the clip each
/// listening-test trial played (PlayedClip); version 8 names a lease's holder by PID, process
/// start time and boot id (experiment/LeaseHolder.h). Older studies are migrated when opened
/// (docs/reference/store-schema.md).
inline constexpr int kSchemaVersion = 8;

/// Time source (injectable for tests).
struct Clock {
    std::function<std::chrono::system_clock::time_point()> now = [] {
        return std::chrono::system_clock::now();
    };
};

/// ISO 8601 UTC with milliseconds, e.g. "2026-11-21T20:45:34.123Z".
std::string isoUtc(std::chrono::system_clock::time_point t);

/// Study-level settings given at creation.
struct StudySettings {
    std::string code;
    std::string site;
    std::uint64_t seed = 1;
    std::string appVersion;
};

/// Study-level information read back.
struct StudyInfo {
    std::string code;
    std::string site;
    std::uint64_t seed = 0;
    std::string createdAt;
    std::string appVersion;
    std::string protocolId;
    int protocolVersion = 0;
    std::string protocolHash;
    int schemaVersion = 0;
};

/// How a participant got its group.
enum class Assignment { Balanced, Override };
/// Where a participant is in the study.
enum class ParticipantStatus { Registered, Active, Completed, Dropped };
const char* toString(ParticipantStatus status);

/// Pseudonymous participant data (no names).
struct NewParticipant {
    std::string code;
    std::optional<int> age;
    std::string gender;
    std::string shoes;
    std::string hearing;
    /// Experimenter override of the balanced assignment (needs a reason).
    std::optional<std::string> groupOverride;
    std::string overrideReason;
    /// A synthetic participant of `underfoot session --simulate` (never a real person).
    bool simulated = false;
};

struct ParticipantInfo {
    std::int64_t id = 0;
    std::string code;
    int index = 0;
    std::optional<int> age;
    std::string gender;
    std::string shoes;
    std::string hearing;
    std::string groupId;
    Assignment assignment = Assignment::Balanced;
    std::string overrideReason;
    ParticipantStatus status = ParticipantStatus::Registered;
    std::string registeredAt;
    /// Answers to the protocol's [[participant_fields]] (field id -> answer).
    std::map<std::string, std::string> fields;
    /// A synthetic participant created by a simulation (its answers are not a person's).
    bool simulated = false;
};

/// Participants per group (dropouts excluded) against the target.
struct GroupCount {
    std::string groupId;
    int active = 0;
    int completed = 0;
    int dropped = 0;
    int target = 0;
};

/// Configuration recorded with a session.
struct SessionSettings {
    std::string experimenter;
    std::string audioConfig;
    std::string sensorConfig;
    std::string appVersion;
    /// Whether the stimuli are played as sound (true), not at all (false: data entry, answers
    /// typed in without sound), or unknown (nullopt).
    std::optional<bool> soundPlayed = std::nullopt;
    /// Take over the participant's session lease even when another live process holds it
    /// (`underfoot session --take-over`, after a crash on another machine); journaled.
    bool takeOver = false;
    /// Also take over leases of another host name (a re-created container, a moved study
    /// file); `underfoot serve` sets it: it is the only writer of an online study. Leases of
    /// dead processes, reused PIDs and earlier boots of this host are always taken over.
    bool takeOverForeign = false;
};

/// A stored session of a participant.
struct SessionRecord {
    int number = 0;
    std::string experimenter;
    std::string audioConfig;
    std::string sensorConfig;
    std::string startedAt;
    std::string endedAt;
    std::string outcome; ///< "completed", "interrupted" or "" while open
    std::optional<bool> soundPlayed = std::nullopt;
};

/// An answer to one trial.
struct TrialAnswer {
    /// Answer option id (surface id or "dont_know"); empty when not asked.
    std::string answer;
    /// Scale id -> value.
    std::map<std::string, int> ratings;
    /// Soundscape option id; empty when not asked.
    std::string soundscapeAnswer;
    std::string comment;
};

/// What the audio engine measured while a trial's stimulus played (from start to stop).
struct TrialAudioStats {
    double sampleRateHz = 0;            ///< the audio settings' sample rate
    int blockSize = 0;                  ///< the audio settings' block size (frames)
    std::uint64_t frames = 0;           ///< audio frames the device ran
    std::uint64_t xruns = 0;            ///< device over/underflows
    double averageLoadPercent = 0;      ///< callback time / audio time
    double maxLoadPercent = 0;          ///< worst callback's load
    double maxBlockMs = 0;              ///< worst callback time
    std::uint64_t droppedGrfFrames = 0; ///< GRF frames lost by the recording (0 = complete)
};

/// The clip a listening-test trial played: what replay renders again and compares.
struct PlayedClip {
    std::string file;          ///< relative to the clip folder
    double seconds = 0;        ///< the file's length (frames / rate)
    std::uint64_t frames = 0;  ///< frames of the file
    double sampleRateHz = 0;   ///< the file's rate
    std::string samplesSha256; ///< SHA-256 of its float32 samples (wiring::samplesSha256)
    bool operator==(const PlayedClip&) const = default;
};

/// A stored trial.
struct TrialRecord {
    std::string participant;
    int index = 0;
    int block = 1;
    bool practice = false;
    Stimulus stimulus;
    int repetition = 1;
    std::uint64_t plannedSeed = 0;
    std::optional<std::uint64_t> renderSeed;
    std::optional<std::string> grfRecording;
    std::optional<int> sessionNumber;
    std::string startedAt;
    std::string answeredAt;
    std::optional<double> responseTimeS;
    bool answered = false;
    TrialAnswer answer;
    bool excluded = false;
    std::string exclusionReason;
    bool breakAfter = false;
    /// How many times the clip was played again after its first presentation.
    int replays = 0;
    /// Laps completed (interactive tests with [laps]).
    int lapsDone = 0;
    /// The audio figures of the trial's last presentation (live players only).
    std::optional<TrialAudioStats> audio;
    /// Reference of the trial's sensor log (frames, step events, GRFs), when one was written.
    std::optional<std::string> sensorLog;
    /// Times a presentation of this trial was interrupted by a sensor fault.
    int interruptions = 0;
    /// The last interruption's fault reason ("" when never interrupted).
    std::string interruptionReason;
    /// The clip played (listening tests; nullopt otherwise).
    std::optional<PlayedClip> clip;
};

/// Everything needed to re-render a trial exactly.
struct ReplayInfo {
    std::string study;
    std::string protocolHash;
    std::string participant;
    int trialIndex = 0;
    Stimulus stimulus;
    std::uint64_t renderSeed = 0;
    std::optional<std::string> grfRecording;
    std::string audioConfig;
    std::string sensorConfig;
    /// The clip the trial played (listening tests).
    std::optional<PlayedClip> clip;
};

/// One journal entry.
struct Event {
    std::int64_t id = 0;
    std::string at;
    JournalEvent event = JournalEvent::StudyCreated;
    /// The stored name of `event` (journalEventName).
    std::string kind;
    std::string participant;
    std::optional<int> trialIndex;
    std::string detail;
};

class StudyStore {
  public:
    /// Creates a new study file (refuses an existing file).
    static StudyStore create(const std::string& path, const Protocol& protocol,
                             const StudySettings& settings, Clock clock = {},
                             const Catalogue& catalogue = defaultCatalogue());
    /// Opens an existing study (migrating an older schema; refusing a newer one).
    static StudyStore open(const std::string& path, Clock clock = {},
                           const Catalogue& catalogue = defaultCatalogue());
    /// Opens an existing study read-only (an archived study, read-only as a file or as a
    /// folder for this user, still exports and analyzes): no write, no lease, no migration,
    /// no -wal/-shm created where they cannot be. The integrity check (quick_check) still runs.
    /// A study of an older schema is refused, saying that it needs a migration (a write). When
    /// the file or its folder is not writable and no committed data waits in `<file>-wal`, the
    /// file is opened as immutable (no locks: archived files are not written meanwhile);
    /// otherwise as a read-only SQLite connection that shares the writers' locks. Every write
    /// through this store is refused with the file name.
    static StudyStore openReadOnly(const std::string& path, Clock clock = {},
                                   const Catalogue& catalogue = defaultCatalogue());
    /// The open of the commands that only read (export, analyze, study info/participants/...):
    /// openReadOnly(), except that a study of an older schema that this user may write is
    /// opened with open() and migrated, as before.
    static StudyStore openForReading(const std::string& path, Clock clock = {},
                                     const Catalogue& catalogue = defaultCatalogue());
    /// True when opened with openReadOnly().
    bool readOnly() const { return readOnly_; }

    StudyStore(StudyStore&&) noexcept;
    StudyStore& operator=(StudyStore&&) noexcept;
    ~StudyStore();

    const std::string& path() const { return path_; }
    StudyInfo info() const;
    /// The protocol stored in the study (parsed from its stored text).
    const Protocol& protocol() const { return *protocol_; }
    /// Throws StoreError when `fileProtocol` is not the exact text the study was started with.
    void verifyProtocol(const Protocol& fileProtocol) const;

    /// Registers a participant: assigns a group (balanced, or the override with its reason),
    /// generates and stores the plan, journals it; all in one transaction.
    ParticipantInfo registerParticipant(const NewParticipant& participant);
    /// Registers a participant with answers to the protocol's [[participant_fields]]; unknown
    /// fields, answers outside a field's options and missing required fields are refused.
    ParticipantInfo registerParticipant(const NewParticipant& participant,
                                        const std::map<std::string, std::string>& fields);
    /// Problems of participant field answers against the protocol (empty: valid).
    std::vector<std::string>
    checkParticipantFields(const std::map<std::string, std::string>& fields) const;
    /// Marks a participant as dropped out (frees its group slot); journaled.
    void dropParticipant(const std::string& code, const std::string& reason);
    ParticipantInfo participant(const std::string& code) const;
    std::vector<ParticipantInfo> participants() const;
    std::vector<GroupCount> groupCounts() const;
    /// The group a new participant would get now (balanced assignment).
    std::string nextGroup(int participantIndex) const;

    /// Opens a session for a participant; returns its number (1, 2, ... per participant).
    /// A participant's session is exclusive: it takes the participant's lease (a row in the
    /// store naming process (PID, start time, boot id), host, experimenter and since when). A
    /// lease held by another live process is refused (LeaseHeld) with who holds it and since
    /// when, unless settings.takeOver; a lease of a dead process, a reused PID or an earlier
    /// boot of this host is recovered, one of another host is taken over with
    /// settings.takeOverForeign (else refused); each is journaled with the holder's state. While
    /// another store holds the lease, markTrialStarted and commitAnswer of this store are refused.
    int startSession(const std::string& code, const SessionSettings& settings);
    /// The sessions of a participant, in order.
    std::vector<SessionRecord> sessions(const std::string& code) const;
    /// Closes a session (and releases the lease); `completed` also marks the participant
    /// completed.
    void endSession(const std::string& code, int sessionNumber, bool completed);

    /// Marks a participant whose every trial is answered as completed (recovers a crash between
    /// the last answer and the end of the session); journaled. No-op when already completed.
    void markCompleted(const std::string& code);

    std::vector<TrialRecord> trials(const std::string& code) const;
    TrialRecord trial(const std::string& code, int trialIndex) const;
    /// Index of the first unanswered trial, or nullopt when all are answered.
    std::optional<int> firstUnanswered(const std::string& code) const;

    /// Records that a trial's stimulus started (render seed, GRF recording reference, the clip
    /// of a listening test); locks the previous trial's answer under the "next_trial" rule.
    void markTrialStarted(const std::string& code, int trialIndex, int sessionNumber,
                          std::uint64_t renderSeed, const std::optional<std::string>& grfRecording,
                          const std::optional<PlayedClip>& clip = std::nullopt);
    /// Records the sensor log reference of a started trial (the path like grfRecording).
    void setSensorLog(const std::string& code, int trialIndex, const std::string& sensorLog);
    /// Stores the audio figures of a trial's last presentation (replacing earlier ones).
    void recordTrialAudio(const std::string& code, int trialIndex, const TrialAudioStats& stats);
    /// Marks the presentation of a started, unanswered trial as interrupted by a sensor fault
    /// (counted, reason kept, journaled as "trial_interrupted"); the trial stays unanswered so
    /// the participant resumes at it. Throws StoreError for an answered or unknown trial.
    void markTrialInterrupted(const std::string& code, int trialIndex, const std::string& reason);
    /// Commits an answer in its own durable transaction. The store checks only what its schema
    /// and record order say: the participant and trial exist, the trial's stimulus started,
    /// the response time is a finite number >= 0, ratings name a scale, the participant's lease
    /// is this store's; a second commit replaces the answer (journaled "answer_changed"). It
    /// does NOT check the answer against the protocol (answer list, scales and their ranges,
    /// laps, lock rule): that is the trial core's (TrialFlow), which every front end and the
    /// simulation go through first.
    /// Throws AnswerSavedButNotCopied (a StoreError) when the answer was stored but the
    /// checkpoint after it failed.
    void commitAnswer(const std::string& code, int trialIndex, const TrialAnswer& answer,
                      std::optional<double> responseTimeS);
    /// Counts one more replay of a started, unanswered trial's clip; journaled. Throws StoreError
    /// when the trial has not started or is answered (whether the protocol allows replays is
    /// TrialFlow's rule).
    void recordReplay(const std::string& code, int trialIndex);
    /// Records that lap `lap` (1-based) of a started trial was completed (silent or with sound);
    /// journaled. Laps are counted in order (lap = laps done + 1); how many the protocol walks
    /// is TrialFlow's rule.
    void recordLap(const std::string& code, int trialIndex, int lap);
    /// Excludes (or re-includes with an empty reason) a trial from analysis; journaled.
    void setExcluded(const std::string& code, int trialIndex, bool excluded,
                     const std::string& reason);
    /// Appends an event to the journal (`detail`: a JSON object with the event's fields).
    void journal(JournalEvent event, const std::string& code, std::optional<int> trialIndex,
                 const std::string& detail);
    /// The journal, in order. Throws StoreError naming the file and the row for a stored name
    /// that is not a JournalEvent (docs/decisions/journal-event-enum.md).
    std::vector<Event> events() const;

    /// Answered and planned trial counts per participant code (one aggregate query).
    std::map<std::string, std::pair<int, int>> progressCounts() const;

    /// What replay needs for one trial (throws StoreError if the trial never started).
    ReplayInfo trialForReplay(const std::string& code, int trialIndex) const;

  private:
    StudyStore(std::string path, std::unique_ptr<SQLite::Database> db, Clock clock);
    void configure();
    void loadProtocol(const Catalogue& catalogue);
    std::int64_t participantId(const std::string& code) const;
    /// `SELECT <columns> FROM trials` for one trial, stepped onto its row; throws
    /// noSuchTrial() when the participant has no such trial.
    SQLite::Statement selectTrial(std::int64_t participantId, const std::string& code,
                                  int trialIndex, const std::string& columns) const;
    [[noreturn]] void noSuchTrial(const std::string& code, int trialIndex) const;
    /// Refuses a write for a participant whose lease another store holds.
    void checkLease(std::int64_t participantId, const std::string& code) const;
    /// Re-throws a failed write as a StoreError naming the file, what was being written and
    /// the cause (disk full, read-only file or folder, I/O error), with what to do.
    [[noreturn]] void writeFailed(const std::string& what, const std::exception& e) const;
    /// Copies the WAL into the main file so that nothing acknowledged lives only in -wal.
    void checkpoint();
    void appendEvent(JournalEvent event, std::optional<std::int64_t> participantId,
                     std::optional<int> trialIndex, const std::string& detail);
    std::string now() const;

    std::string path_;
    std::unique_ptr<SQLite::Database> db_;
    Clock clock_;
    std::unique_ptr<Protocol> protocol_;
    std::string leaseToken_; ///< identifies this store's session leases
    bool readOnly_ = false;  ///< opened with openReadOnly(): every write is refused
};

/// Minimal JSON object writer for journal details: {"k":"v",...} with escaping.
std::string jsonObject(std::initializer_list<std::pair<std::string_view, std::string>> fields);

} // namespace underfoot::experiment
