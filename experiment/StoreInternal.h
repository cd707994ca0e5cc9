// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Helpers shared by the store's source files (schema, open modes, participants, sessions and
/// leases, trials, events); not part of the store's interface.
#include "experiment/Store.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

#include <cerrno>
#include <cstdint>
#include <map>
#include <random>
#include <string>

#include <signal.h>
#include <unistd.h>

namespace underfoot::experiment::store_detail {

/// The schema migrations: entry i brings user_version from i to i + 1 (StoreSchema.cpp).
const char* migration(int fromVersion);
/// Number of migrations (equals kSchemaVersion).
int migrationCount();

inline std::int64_t toDb(std::uint64_t v) {
    return static_cast<std::int64_t>(v);
}
inline std::uint64_t fromDb(std::int64_t v) {
    return static_cast<std::uint64_t>(v);
}

inline std::string columnText(const SQLite::Column& c) {
    return c.isNull() ? std::string() : c.getString();
}

inline ParticipantStatus statusFromText(const std::string& s) {
    if (s == "active") return ParticipantStatus::Active;
    if (s == "completed") return ParticipantStatus::Completed;
    if (s == "dropped") return ParticipantStatus::Dropped;
    return ParticipantStatus::Registered;
}

/// Inserts one row (owner id, name, value) per entry of `values` with `insertSql` (three
/// placeholders in that order) and returns the entries as "name=value name=value" for the
/// journal event that records them (participant fields, ratings).
template <typename Value>
std::string insertNamedValues(SQLite::Database& db, const char* insertSql, std::int64_t ownerId,
                              const std::map<std::string, Value>& values) {
    SQLite::Statement ins(db, insertSql);
    std::string text;
    for (const auto& [name, value] : values) {
        ins.reset();
        ins.bind(1, ownerId);
        ins.bind(2, name);
        ins.bind(3, value);
        ins.exec();
        text += fmt::format("{}{}={}", text.empty() ? "" : " ", name, value);
    }
    return text;
}

inline constexpr const char* kParticipantColumns =
    "id, code, idx, age, gender, shoes, hearing, group_id, assignment, override_reason, status, "
    "registered_at, simulated";

inline ParticipantInfo readParticipant(SQLite::Statement& q) {
    ParticipantInfo p;
    p.id = q.getColumn(0).getInt64();
    p.code = q.getColumn(1).getString();
    p.index = q.getColumn(2).getInt();
    if (!q.getColumn(3).isNull()) p.age = q.getColumn(3).getInt();
    p.gender = q.getColumn(4).getString();
    p.shoes = q.getColumn(5).getString();
    p.hearing = q.getColumn(6).getString();
    p.groupId = q.getColumn(7).getString();
    p.assignment =
        q.getColumn(8).getString() == "override" ? Assignment::Override : Assignment::Balanced;
    p.overrideReason = q.getColumn(9).getString();
    p.status = statusFromText(q.getColumn(10).getString());
    p.registeredAt = q.getColumn(11).getString();
    p.simulated = q.getColumn(12).getInt() != 0;
    return p;
}

inline std::string hostName() {
    char buf[256] = {};
    if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown-host";
    return buf;
}

inline std::string newLeaseToken() {
    std::random_device rd;
    return fmt::format("{:08x}{:08x}{:08x}", rd(), rd(), static_cast<unsigned>(::getpid()));
}

} // namespace underfoot::experiment::store_detail
