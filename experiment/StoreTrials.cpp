// SPDX-License-Identifier: GPL-3.0-or-later
// Trials: starts, answers (durable), replays, laps, audio figures, interruptions, exclusions.
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace underfoot::experiment {

using namespace store_detail;

namespace {
constexpr const char* kTrialColumns =
    "t.id, p.code, t.trial_index, t.block, t.practice, t.stimulus, t.repetition, t.planned_seed, "
    "t.render_seed, t.grf_recording, t.session_number, t.started_at, t.answered_at, "
    "t.response_time_s, t.answer, t.soundscape_answer, t.comment, t.excluded, "
    "t.exclusion_reason, t.break_after, t.replays, t.laps_done, t.audio_sample_rate_hz, "
    "t.audio_block_size, t.audio_frames, t.audio_xruns, t.audio_average_load_percent, "
    "t.audio_max_load_percent, t.audio_max_block_ms, t.audio_dropped_grf_frames, t.sensor_log, "
    "t.interruptions, t.interruption_reason, t.clip_file, t.clip_seconds, t.clip_frames, "
    "t.clip_sample_rate_hz, t.clip_sha256";

TrialRecord readTrial(SQLite::Database& db, SQLite::Statement& q) {
    TrialRecord r;
    const std::int64_t trialId = q.getColumn(0).getInt64();
    r.participant = q.getColumn(1).getString();
    r.index = q.getColumn(2).getInt();
    r.block = q.getColumn(3).getInt();
    r.practice = q.getColumn(4).getInt() != 0;
    try {
        r.stimulus = stimulusFromToml(q.getColumn(5).getString());
    } catch (const std::runtime_error& e) { // a damaged file (found by fuzz_study_db)
        throw StoreError(fmt::format("{}: participant '{}' trial {}: {}; the study file is "
                                     "damaged",
                                     db.getFilename(), r.participant, r.index + 1, e.what()));
    }
    r.repetition = q.getColumn(6).getInt();
    r.plannedSeed = fromDb(q.getColumn(7).getInt64());
    if (!q.getColumn(8).isNull()) r.renderSeed = fromDb(q.getColumn(8).getInt64());
    if (!q.getColumn(9).isNull()) r.grfRecording = q.getColumn(9).getString();
    if (!q.getColumn(10).isNull()) r.sessionNumber = q.getColumn(10).getInt();
    r.startedAt = columnText(q.getColumn(11));
    r.answeredAt = columnText(q.getColumn(12));
    r.answered = !r.answeredAt.empty();
    if (!q.getColumn(13).isNull()) r.responseTimeS = q.getColumn(13).getDouble();
    r.answer.answer = columnText(q.getColumn(14));
    r.answer.soundscapeAnswer = columnText(q.getColumn(15));
    r.answer.comment = columnText(q.getColumn(16));
    r.excluded = q.getColumn(17).getInt() != 0;
    r.exclusionReason = q.getColumn(18).getString();
    r.breakAfter = q.getColumn(19).getInt() != 0;
    r.replays = q.getColumn(20).getInt();
    r.lapsDone = q.getColumn(21).getInt();
    if (!q.getColumn(22).isNull()) {
        TrialAudioStats a;
        a.sampleRateHz = q.getColumn(22).getDouble();
        a.blockSize = q.getColumn(23).getInt();
        a.frames = fromDb(q.getColumn(24).getInt64());
        a.xruns = fromDb(q.getColumn(25).getInt64());
        a.averageLoadPercent = q.getColumn(26).getDouble();
        a.maxLoadPercent = q.getColumn(27).getDouble();
        a.maxBlockMs = q.getColumn(28).getDouble();
        a.droppedGrfFrames = fromDb(q.getColumn(29).getInt64());
        r.audio = a;
    }
    if (!q.getColumn(30).isNull()) r.sensorLog = q.getColumn(30).getString();
    r.interruptions = q.getColumn(31).getInt();
    r.interruptionReason = q.getColumn(32).getString();
    if (!q.getColumn(33).isNull()) {
        PlayedClip c;
        c.file = q.getColumn(33).getString();
        c.seconds = q.getColumn(34).getDouble();
        c.frames = fromDb(q.getColumn(35).getInt64());
        c.sampleRateHz = q.getColumn(36).getDouble();
        c.samplesSha256 = columnText(q.getColumn(37));
        r.clip = c;
    }
    if (r.answered) {
        SQLite::Statement rq(db, "SELECT scale, value FROM ratings WHERE trial_id = ?");
        rq.bind(1, trialId);
        while (rq.executeStep())
            r.answer.ratings[rq.getColumn(0).getString()] = rq.getColumn(1).getInt();
    }
    return r;
}
} // namespace

std::vector<TrialRecord> StudyStore::trials(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    std::vector<TrialRecord> out;
    SQLite::Statement q(*db_, fmt::format("SELECT {} FROM trials t JOIN participants p ON p.id = "
                                          "t.participant_id WHERE t.participant_id = ? ORDER BY "
                                          "t.trial_index",
                                          kTrialColumns));
    q.bind(1, pid);
    while (q.executeStep()) out.push_back(readTrial(*db_, q));
    return out;
}

TrialRecord StudyStore::trial(const std::string& code, int trialIndex) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, fmt::format("SELECT {} FROM trials t JOIN participants p ON p.id = "
                                          "t.participant_id WHERE t.participant_id = ? AND "
                                          "t.trial_index = ?",
                                          kTrialColumns));
    q.bind(1, pid);
    q.bind(2, trialIndex);
    if (!q.executeStep()) noSuchTrial(code, trialIndex);
    return readTrial(*db_, q);
}

std::optional<int> StudyStore::firstUnanswered(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "SELECT min(trial_index) FROM trials WHERE participant_id = ? AND "
                              "answered_at IS NULL");
    q.bind(1, pid);
    q.executeStep();
    if (q.getColumn(0).isNull()) return std::nullopt;
    return q.getColumn(0).getInt();
}

void StudyStore::markTrialStarted(const std::string& code, int trialIndex, int sessionNumber,
                                  std::uint64_t renderSeed,
                                  const std::optional<std::string>& grfRecording,
                                  const std::optional<PlayedClip>& clip) {
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const std::int64_t pid = participantId(code);
        checkLease(pid, code);
        SQLite::Statement check = selectTrial(pid, code, trialIndex, "answered_at, started_at");
        if (!check.getColumn(0).isNull())
            throw StoreError(
                fmt::format("participant '{}' trial {} is already answered", code, trialIndex + 1));
        const bool restarted = !check.getColumn(1).isNull();
        // A restarted trial's earlier sensor log and audio figures belong to the earlier
        // presentation.
        SQLite::Statement q(*db_,
                            "UPDATE trials SET started_at = ?, render_seed = ?, grf_recording = "
                            "?, session_number = ?, sensor_log = NULL, audio_sample_rate_hz = "
                            "NULL, audio_block_size = NULL, audio_frames = NULL, audio_xruns = "
                            "NULL, audio_average_load_percent = NULL, audio_max_load_percent = "
                            "NULL, audio_max_block_ms = NULL, audio_dropped_grf_frames = NULL, "
                            "clip_file = ?, clip_seconds = ?, clip_frames = ?, "
                            "clip_sample_rate_hz = ?, clip_sha256 = ? "
                            "WHERE participant_id = ? AND trial_index = ?");
        q.bind(1, now());
        q.bind(2, toDb(renderSeed));
        if (grfRecording) q.bind(3, *grfRecording);
        q.bind(4, sessionNumber);
        if (clip) {
            q.bind(5, clip->file);
            q.bind(6, clip->seconds);
            q.bind(7, toDb(clip->frames));
            q.bind(8, clip->sampleRateHz);
            q.bind(9, clip->samplesSha256);
        }
        q.bind(10, pid);
        q.bind(11, trialIndex);
        q.exec();
        appendEvent(restarted ? JournalEvent::TrialRestarted : JournalEvent::TrialStarted, pid,
                    trialIndex,
                    jsonObject({{"session", std::to_string(sessionNumber)},
                                {"render_seed", std::to_string(renderSeed)},
                                {"grf", grfRecording.value_or("")},
                                {"clip", clip ? clip->file : std::string()},
                                {"clip_sha256", clip ? clip->samplesSha256 : std::string()}}));
        tx.commit();
    } catch (const SQLite::Exception& e) {
        writeFailed(
            fmt::format("recording the start of participant '{}' trial {}", code, trialIndex + 1),
            e);
    }
}

void StudyStore::commitAnswer(const std::string& code, int trialIndex, const TrialAnswer& answer,
                              std::optional<double> responseTimeS) {
    if (responseTimeS && (!std::isfinite(*responseTimeS) || *responseTimeS < 0))
        throw StoreError(fmt::format("participant '{}' trial {}: response time must be a finite "
                                     "number >= 0",
                                     code, trialIndex + 1));
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const ParticipantInfo p = participant(code);
        checkLease(p.id, code);
        // Only what the schema and the record's order say: the trial exists, its stimulus was
        // presented, one answer row per trial (a second commit replaces it, journaled as a
        // change). The protocol's rules (answer list, scales and ranges, laps, lock) are the
        // trial core's (TrialFlow), which every writer goes through first.
        SQLite::Statement cur = selectTrial(p.id, code, trialIndex, "id, started_at, answered_at");
        const std::int64_t trialId = cur.getColumn(0).getInt64();
        if (cur.getColumn(1).isNull())
            throw StoreError(fmt::format("participant '{}' trial {} has not started; expected its "
                                         "stimulus to be played first",
                                         code, trialIndex + 1));
        const bool changing = !cur.getColumn(2).isNull();
        for (const auto& [scale, value] : answer.ratings)
            if (scale.empty())
                throw StoreError(fmt::format("participant '{}' trial {}: a rating without a "
                                             "scale id (value {})",
                                             code, trialIndex + 1, value));
        SQLite::Statement q(*db_,
                            "UPDATE trials SET answered_at = ?, response_time_s = ?, answer = ?, "
                            "soundscape_answer = ?, comment = ? WHERE id = ?");
        q.bind(1, now());
        if (responseTimeS) q.bind(2, *responseTimeS);
        if (!answer.answer.empty()) q.bind(3, answer.answer);
        if (!answer.soundscapeAnswer.empty()) q.bind(4, answer.soundscapeAnswer);
        if (!answer.comment.empty()) q.bind(5, answer.comment);
        q.bind(6, trialId);
        q.exec();
        SQLite::Statement del(*db_, "DELETE FROM ratings WHERE trial_id = ?");
        del.bind(1, trialId);
        del.exec();
        const std::string ratingsText =
            insertNamedValues(*db_, "INSERT INTO ratings (trial_id, scale, value) VALUES (?, ?, ?)",
                              trialId, answer.ratings);
        appendEvent(changing ? JournalEvent::AnswerChanged : JournalEvent::Answered, p.id,
                    trialIndex,
                    jsonObject({{"answer", answer.answer},
                                {"ratings", ratingsText},
                                {"soundscape", answer.soundscapeAnswer},
                                {"comment", answer.comment},
                                {"response_time_s",
                                 responseTimeS ? fmt::format("{:.3f}", *responseTimeS) : ""}}));
        tx.commit();
    } catch (const SQLite::Exception& e) {
        writeFailed(
            fmt::format("saving the answer of participant '{}' trial {}", code, trialIndex + 1), e);
    }
    // Committed with synchronous=FULL: the answer is durable in the WAL from here on. A failed
    // checkpoint must not look like a lost answer (the caller would ask for it again and store
    // it as a change), so it is reported as what it is.
    try {
        checkpoint();
    } catch (const StoreError& e) {
        throw AnswerSavedButNotCopied(fmt::format(
            "participant '{}' trial {}: the answer IS saved (in {}-wal; keep that file beside the "
            "study and do not delete it), but copying it into the study file then failed: {}",
            code, trialIndex + 1, path_, e.what()));
    }
}

void StudyStore::recordReplay(const std::string& code, int trialIndex) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement cur = selectTrial(pid, code, trialIndex, "started_at, answered_at, replays");
    if (cur.getColumn(0).isNull())
        throw StoreError(fmt::format("participant '{}' trial {}: replay before the first "
                                     "presentation; expected play() first",
                                     code, trialIndex + 1));
    if (!cur.getColumn(1).isNull())
        throw StoreError(
            fmt::format("participant '{}' trial {} is already answered", code, trialIndex + 1));
    const int replays = cur.getColumn(2).getInt() + 1;
    SQLite::Statement q(*db_, "UPDATE trials SET replays = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, replays);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    q.exec();
    appendEvent(JournalEvent::ClipReplayed, pid, trialIndex,
                jsonObject({{"replays", std::to_string(replays)}}));
    tx.commit();
}

void StudyStore::recordLap(const std::string& code, int trialIndex, int lap) {
    // The count of laps walked goes up by one (the protocol's number of laps is TrialFlow's).
    const Laps& laps = protocol_->laps;
    if (lap < 1)
        throw StoreError(fmt::format("participant '{}' trial {}: lap {}; expected a lap number "
                                     ">= 1",
                                     code, trialIndex + 1, lap));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement cur =
        selectTrial(pid, code, trialIndex, "started_at, answered_at, laps_done");
    if (cur.getColumn(0).isNull() || !cur.getColumn(1).isNull())
        throw StoreError(fmt::format("participant '{}' trial {}: laps are recorded between the "
                                     "start of a condition and its answer",
                                     code, trialIndex + 1));
    if (cur.getColumn(2).getInt() != lap - 1)
        throw StoreError(fmt::format("participant '{}' trial {}: lap {} completed after {} laps; "
                                     "expected lap {}",
                                     code, trialIndex + 1, lap, cur.getColumn(2).getInt(),
                                     cur.getColumn(2).getInt() + 1));
    SQLite::Statement q(*db_, "UPDATE trials SET laps_done = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, lap);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    q.exec();
    appendEvent(JournalEvent::LapCompleted, pid, trialIndex,
                jsonObject({{"lap", std::to_string(lap)},
                            {"sound", laps.silent(lap) ? "silent baseline" : "feedback"}}));
    tx.commit();
}

void StudyStore::setSensorLog(const std::string& code, int trialIndex,
                              const std::string& sensorLog) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET sensor_log = ? WHERE participant_id = ? AND "
                              "trial_index = ? AND started_at IS NOT NULL");
    q.bind(1, sensorLog);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    if (q.exec() != 1)
        throw StoreError(fmt::format("{}: participant '{}' has no started trial {}", path_, code,
                                     trialIndex + 1));
    tx.commit();
}

void StudyStore::recordTrialAudio(const std::string& code, int trialIndex,
                                  const TrialAudioStats& a) {
    for (const double v : {a.sampleRateHz, a.averageLoadPercent, a.maxLoadPercent, a.maxBlockMs})
        if (!std::isfinite(v) || v < 0)
            throw StoreError(fmt::format("participant '{}' trial {}: audio figures must be finite "
                                         "numbers >= 0",
                                         code, trialIndex + 1));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET audio_sample_rate_hz = ?, audio_block_size = ?, "
                              "audio_frames = ?, audio_xruns = ?, audio_average_load_percent = ?, "
                              "audio_max_load_percent = ?, audio_max_block_ms = ?, "
                              "audio_dropped_grf_frames = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, a.sampleRateHz);
    q.bind(2, a.blockSize);
    q.bind(3, toDb(a.frames));
    q.bind(4, toDb(a.xruns));
    q.bind(5, a.averageLoadPercent);
    q.bind(6, a.maxLoadPercent);
    q.bind(7, a.maxBlockMs);
    q.bind(8, toDb(a.droppedGrfFrames));
    q.bind(9, pid);
    q.bind(10, trialIndex);
    if (q.exec() != 1) noSuchTrial(code, trialIndex);
    tx.commit();
}

void StudyStore::markTrialInterrupted(const std::string& code, int trialIndex,
                                      const std::string& reason) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET interruptions = interruptions + 1, "
                              "interruption_reason = ? WHERE participant_id = ? AND trial_index = "
                              "? AND answered_at IS NULL");
    q.bind(1, reason);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    if (q.exec() != 1)
        throw StoreError(fmt::format("{}: participant '{}' has no unanswered trial {}", path_, code,
                                     trialIndex + 1));
    appendEvent(JournalEvent::TrialInterrupted, pid, trialIndex, jsonObject({{"reason", reason}}));
    tx.commit();
}

void StudyStore::setExcluded(const std::string& code, int trialIndex, bool excluded,
                             const std::string& reason) {
    if (excluded && reason.empty())
        throw StoreError("excluding a trial needs a reason (journaled and exported)");
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET excluded = ?, exclusion_reason = ? WHERE "
                              "participant_id = ? AND trial_index = ?");
    q.bind(1, excluded ? 1 : 0);
    q.bind(2, excluded ? reason : std::string());
    q.bind(3, pid);
    q.bind(4, trialIndex);
    if (q.exec() != 1) noSuchTrial(code, trialIndex);
    appendEvent(excluded ? JournalEvent::TrialExcluded : JournalEvent::TrialIncluded, pid,
                trialIndex, jsonObject({{"reason", reason}}));
    tx.commit();
}

std::map<std::string, std::pair<int, int>> StudyStore::progressCounts() const {
    std::map<std::string, std::pair<int, int>> out;
    SQLite::Statement q(*db_,
                        "SELECT p.code, count(t.answered_at), count(t.id) FROM participants p "
                        "LEFT JOIN trials t ON t.participant_id = p.id GROUP BY p.id");
    while (q.executeStep())
        out[q.getColumn(0).getString()] = {q.getColumn(1).getInt(), q.getColumn(2).getInt()};
    return out;
}

ReplayInfo StudyStore::trialForReplay(const std::string& code, int trialIndex) const {
    const TrialRecord t = trial(code, trialIndex);
    if (!t.renderSeed || !t.sessionNumber)
        throw StoreError(fmt::format("participant '{}' trial {} was never presented; nothing to "
                                     "replay",
                                     code, trialIndex + 1));
    ReplayInfo r;
    const StudyInfo i = info();
    r.study = i.code;
    r.protocolHash = i.protocolHash;
    r.participant = code;
    r.trialIndex = trialIndex;
    r.stimulus = t.stimulus;
    r.renderSeed = *t.renderSeed;
    r.grfRecording = t.grfRecording;
    r.clip = t.clip;
    SQLite::Statement q(*db_, "SELECT audio_config, sensor_config FROM sessions WHERE "
                              "participant_id = ? AND number = ?");
    q.bind(1, participantId(code));
    q.bind(2, *t.sessionNumber);
    if (q.executeStep()) {
        r.audioConfig = q.getColumn(0).getString();
        r.sensorConfig = q.getColumn(1).getString();
    }
    return r;
}

} // namespace underfoot::experiment
