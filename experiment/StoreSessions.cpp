// SPDX-License-Identifier: GPL-3.0-or-later
// Sessions and their leases (one live session per participant).
#include "experiment/LeaseHolder.h"
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

namespace underfoot::experiment {

using namespace store_detail;

void StudyStore::checkLease(std::int64_t participantId, const std::string& code) const {
    SQLite::Statement q(*db_, "SELECT token, pid, host, experimenter, since FROM session_leases "
                              "WHERE participant_id = ?");
    q.bind(1, participantId);
    if (!q.executeStep() || q.getColumn(0).getString() == leaseToken_) return;
    throw StoreError(fmt::format(
        "{}: participant '{}': the session lease is now held by process {} on host {} "
        "(experimenter '{}') since {}; this session was taken over and writes nothing more",
        path_, code, q.getColumn(1).getInt64(), q.getColumn(2).getString(),
        q.getColumn(3).getString(), q.getColumn(4).getString()));
}

int StudyStore::startSession(const std::string& code, const SessionSettings& settings) {
    if (readOnly_)
        throw StoreError(fmt::format("{}: participant '{}': a session cannot start on a study "
                                     "opened read-only; open it for writing",
                                     path_, code));
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const ParticipantInfo p = participant(code);
        if (p.status == ParticipantStatus::Dropped)
            throw StoreError(
                fmt::format("participant '{}' dropped out; a session cannot start", code));
        if (p.status == ParticipantStatus::Completed)
            throw StoreError(fmt::format("participant '{}' has completed every trial", code));
        SQLite::Statement n(*db_, "SELECT coalesce(max(number), 0) + 1 FROM sessions WHERE "
                                  "participant_id = ?");
        n.bind(1, p.id);
        n.executeStep();
        const int number = n.getColumn(0).getInt();
        // The participant's lease: one live session per participant.
        const LeaseHolder me = thisProcess();
        {
            SQLite::Statement lease(*db_, "SELECT token, pid, host, experimenter, since, "
                                          "session_number, start_ticks, boot_id FROM "
                                          "session_leases WHERE participant_id = ?");
            lease.bind(1, p.id);
            if (lease.executeStep() && lease.getColumn(0).getString() != leaseToken_) {
                LeaseHolder holder;
                holder.pid = lease.getColumn(1).getInt64();
                holder.host = lease.getColumn(2).getString();
                if (!lease.getColumn(6).isNull())
                    holder.startTicks = fromDb(lease.getColumn(6).getInt64());
                holder.bootId = columnText(lease.getColumn(7));
                const HolderState state = classifyHolder(holder, me);
                const bool recoverable = state == HolderState::Self || state == HolderState::Dead ||
                                         state == HolderState::Reused ||
                                         state == HolderState::OtherBoot;
                const bool takeOver = settings.takeOver ||
                                      (state == HolderState::OtherHost && settings.takeOverForeign);
                if (!recoverable && !takeOver) {
                    const std::string what = fmt::format(
                        "{}: participant '{}' is in session {} held by process {} on host {} "
                        "(experimenter '{}') since {}; one session per participant at a time",
                        path_, code, lease.getColumn(5).getInt(), holder.pid, holder.host,
                        lease.getColumn(3).getString(), lease.getColumn(4).getString());
                    const std::string hint =
                        ". If that session crashed or its machine is gone, take the session "
                        "over with `underfoot session ... --take-over`";
                    if (state == HolderState::Live) throw LeaseHeld(what + hint);
                    throw StoreError(what + hint);
                }
                appendEvent(recoverable ? JournalEvent::LeaseRecovered
                                        : JournalEvent::LeaseTakenOver,
                            p.id, std::nullopt,
                            jsonObject({{"pid", std::to_string(holder.pid)},
                                        {"host", holder.host},
                                        {"holder", toString(state)},
                                        {"experimenter", lease.getColumn(3).getString()},
                                        {"since", lease.getColumn(4).getString()},
                                        {"session", std::to_string(lease.getColumn(5).getInt())}}));
            }
        }
        SQLite::Statement take(*db_,
                               "INSERT OR REPLACE INTO session_leases (participant_id, token, "
                               "pid, host, experimenter, session_number, since, start_ticks, "
                               "boot_id) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
        take.bind(1, p.id);
        take.bind(2, leaseToken_);
        take.bind(3, me.pid);
        take.bind(4, me.host);
        take.bind(5, settings.experimenter);
        take.bind(6, number);
        take.bind(7, now());
        if (me.startTicks) take.bind(8, toDb(*me.startTicks));
        take.bind(9, me.bootId);
        take.exec();
        SQLite::Statement ins(*db_, "INSERT INTO sessions (participant_id, number, group_id, seed, "
                                    "app_version, audio_config, sensor_config, experimenter, "
                                    "started_at, sound_played) VALUES (?, ?, ?, ?, ?, ?, ?, ?, "
                                    "?, ?)");
        ins.bind(1, p.id);
        ins.bind(2, number);
        ins.bind(3, p.groupId);
        ins.bind(4, toDb(participantSeed(info().seed, p.index)));
        ins.bind(5, settings.appVersion);
        ins.bind(6, settings.audioConfig);
        ins.bind(7, settings.sensorConfig);
        ins.bind(8, settings.experimenter);
        ins.bind(9, now());
        if (settings.soundPlayed) ins.bind(10, *settings.soundPlayed ? 1 : 0);
        ins.exec();
        SQLite::Statement st(*db_, "UPDATE participants SET status = 'active' WHERE id = ?");
        st.bind(1, p.id);
        st.exec();
        appendEvent(JournalEvent::SessionStarted, p.id, std::nullopt,
                    jsonObject({{"session", std::to_string(number)},
                                {"experimenter", settings.experimenter},
                                {"audio", settings.audioConfig},
                                {"sensor", settings.sensorConfig},
                                {"sound", !settings.soundPlayed   ? "unknown"
                                          : *settings.soundPlayed ? "played"
                                                                  : "none (data entry)"},
                                {"app_version", settings.appVersion}}));
        tx.commit();
        return number;
    } catch (const SQLite::Exception& e) {
        writeFailed(fmt::format("starting a session of participant '{}'", code), e);
    }
}

std::vector<SessionRecord> StudyStore::sessions(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "SELECT number, experimenter, audio_config, sensor_config, "
                              "started_at, ended_at, outcome, sound_played FROM sessions WHERE "
                              "participant_id = ? ORDER BY number");
    q.bind(1, pid);
    std::vector<SessionRecord> out;
    while (q.executeStep()) {
        SessionRecord r;
        r.number = q.getColumn(0).getInt();
        r.experimenter = q.getColumn(1).getString();
        r.audioConfig = q.getColumn(2).getString();
        r.sensorConfig = q.getColumn(3).getString();
        r.startedAt = q.getColumn(4).getString();
        r.endedAt = columnText(q.getColumn(5));
        r.outcome = columnText(q.getColumn(6));
        if (!q.getColumn(7).isNull()) r.soundPlayed = q.getColumn(7).getInt() != 0;
        out.push_back(std::move(r));
    }
    return out;
}

void StudyStore::endSession(const std::string& code, int sessionNumber, bool completed) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE sessions SET ended_at = ?, outcome = ? WHERE "
                              "participant_id = ? AND number = ?");
    q.bind(1, now());
    q.bind(2, completed ? "completed" : "interrupted");
    q.bind(3, pid);
    q.bind(4, sessionNumber);
    q.exec();
    if (completed) {
        SQLite::Statement st(*db_, "UPDATE participants SET status = 'completed' WHERE id = ?");
        st.bind(1, pid);
        st.exec();
    }
    SQLite::Statement release(*db_, "DELETE FROM session_leases WHERE participant_id = ? AND "
                                    "token = ?");
    release.bind(1, pid);
    release.bind(2, leaseToken_);
    release.exec();
    appendEvent(JournalEvent::SessionEnded, pid, std::nullopt,
                jsonObject({{"session", std::to_string(sessionNumber)},
                            {"outcome", completed ? "completed" : "interrupted"}}));
    tx.commit();
}

void StudyStore::markCompleted(const std::string& code) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const ParticipantInfo p = participant(code);
    if (p.status == ParticipantStatus::Completed) return;
    if (p.status == ParticipantStatus::Dropped)
        throw StoreError(fmt::format("participant '{}' dropped out; not marked completed", code));
    if (firstUnanswered(code))
        throw StoreError(fmt::format("participant '{}' still has unanswered trials", code));
    SQLite::Statement st(*db_, "UPDATE participants SET status = 'completed' WHERE id = ?");
    st.bind(1, p.id);
    st.exec();
    appendEvent(JournalEvent::ParticipantCompleted, p.id, std::nullopt,
                jsonObject({{"note", "every trial answered; the session had not been closed"}}));
    tx.commit();
}

} // namespace underfoot::experiment
