// SPDX-License-Identifier: GPL-3.0-or-later
// The store's event journal (append-only: triggers refuse UPDATE and DELETE); every name is a
// JournalEvent, written and read back strictly.
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

namespace underfoot::experiment {

using namespace store_detail;

void StudyStore::appendEvent(JournalEvent event, std::optional<std::int64_t> participantId,
                             std::optional<int> trialIndex, const std::string& detail) {
    SQLite::Statement q(*db_, "INSERT INTO events (at, kind, participant_id, trial_index, detail) "
                              "VALUES (?, ?, ?, ?, ?)");
    q.bind(1, now());
    q.bind(2, std::string(journalEventName(event)));
    if (participantId) q.bind(3, *participantId);
    if (trialIndex) q.bind(4, *trialIndex);
    q.bind(5, detail);
    q.exec();
}

void StudyStore::journal(JournalEvent event, const std::string& code, std::optional<int> trialIndex,
                         const std::string& detail) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    appendEvent(event, code.empty() ? std::nullopt : std::optional(participantId(code)), trialIndex,
                detail);
    tx.commit();
}

std::vector<Event> StudyStore::events() const {
    std::vector<Event> out;
    SQLite::Statement q(*db_, "SELECT e.id, e.at, e.kind, p.code, e.trial_index, e.detail FROM "
                              "events e LEFT JOIN participants p ON p.id = e.participant_id "
                              "ORDER BY e.id");
    while (q.executeStep()) {
        Event e;
        e.id = q.getColumn(0).getInt64();
        e.at = q.getColumn(1).getString();
        e.kind = q.getColumn(2).getString();
        const auto known = journalEventFromName(e.kind);
        if (!known)
            throw StoreError(fmt::format("{}: journal row {} (table events): unknown event '{}'; "
                                         "expected one of the {} events this program writes "
                                         "(docs/reference/store-schema.md); the file was written "
                                         "by another program or is damaged",
                                         path_, e.id, e.kind, kJournalEvents.size()));
        e.event = *known;
        e.participant = columnText(q.getColumn(3));
        if (!q.getColumn(4).isNull()) e.trialIndex = q.getColumn(4).getInt();
        e.detail = q.getColumn(5).getString();
        out.push_back(std::move(e));
    }
    return out;
}

} // namespace underfoot::experiment
