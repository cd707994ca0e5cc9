// SPDX-License-Identifier: GPL-3.0-or-later
// Participants: registration with balanced group assignment and plan, fields, dropouts.
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

namespace underfoot::experiment {

using namespace store_detail;

std::int64_t StudyStore::participantId(const std::string& code) const {
    SQLite::Statement q(*db_, "SELECT id FROM participants WHERE code = ?");
    q.bind(1, code);
    if (!q.executeStep())
        throw StoreError(
            fmt::format("{}: no participant '{}'; expected a registered code", path_, code));
    return q.getColumn(0).getInt64();
}

SQLite::Statement StudyStore::selectTrial(std::int64_t pid, const std::string& code, int trialIndex,
                                          const std::string& columns) const {
    SQLite::Statement q(*db_, "SELECT " + columns +
                                  " FROM trials WHERE participant_id = ? AND trial_index = ?");
    q.bind(1, pid);
    q.bind(2, trialIndex);
    if (!q.executeStep()) noSuchTrial(code, trialIndex);
    return q;
}

void StudyStore::noSuchTrial(const std::string& code, int trialIndex) const {
    // Any int from a request reaches here (INT_MAX included): the 1-based number is computed wide.
    throw StoreError(fmt::format("{}: participant '{}' has no trial {}", path_, code,
                                 std::int64_t{trialIndex} + 1));
}

namespace {
void readFields(SQLite::Database& db, ParticipantInfo& p) {
    SQLite::Statement q(db, "SELECT name, value FROM participant_fields WHERE participant_id = ?");
    q.bind(1, p.id);
    while (q.executeStep()) p.fields[q.getColumn(0).getString()] = q.getColumn(1).getString();
}
} // namespace

ParticipantInfo StudyStore::participant(const std::string& code) const {
    SQLite::Statement q(
        *db_, fmt::format("SELECT {} FROM participants WHERE code = ?", kParticipantColumns));
    q.bind(1, code);
    if (!q.executeStep())
        throw StoreError(
            fmt::format("{}: no participant '{}'; expected a registered code", path_, code));
    ParticipantInfo p = readParticipant(q);
    readFields(*db_, p);
    return p;
}

std::vector<ParticipantInfo> StudyStore::participants() const {
    std::vector<ParticipantInfo> out;
    SQLite::Statement q(
        *db_, fmt::format("SELECT {} FROM participants ORDER BY idx", kParticipantColumns));
    while (q.executeStep()) out.push_back(readParticipant(q));
    for (auto& p : out) readFields(*db_, p);
    return out;
}

std::vector<std::string>
StudyStore::checkParticipantFields(const std::map<std::string, std::string>& fields) const {
    std::vector<std::string> problems;
    for (const auto& [name, value] : fields) {
        const ParticipantField* f = protocol_->participantField(name);
        if (!f) {
            std::string known;
            for (const auto& pf : protocol_->participantFields)
                known += (known.empty() ? "" : ", ") + pf.id;
            problems.push_back(fmt::format("unknown participant field '{}'; expected one of: {}",
                                           name, known.empty() ? "(none declared)" : known));
            continue;
        }
        if (!f->options.empty() && !value.empty() &&
            std::find(f->options.begin(), f->options.end(), value) == f->options.end()) {
            std::string allowed;
            for (const auto& o : f->options) allowed += (allowed.empty() ? "" : ", ") + o;
            problems.push_back(fmt::format("participant field '{}' is '{}'; expected one of: {}",
                                           name, value, allowed));
        }
    }
    for (const auto& f : protocol_->participantFields) {
        const auto it = fields.find(f.id);
        if (f.required && (it == fields.end() || it->second.empty()))
            problems.push_back(
                fmt::format("participant field '{}' ({}) is required", f.id, f.label));
    }
    return problems;
}

std::vector<GroupCount> StudyStore::groupCounts() const {
    std::vector<GroupCount> out;
    for (const auto& g : protocol_->groups) out.push_back({g.id, 0, 0, 0, g.target});
    SQLite::Statement q(*db_, "SELECT group_id, status, count(*) FROM participants GROUP BY "
                              "group_id, status");
    while (q.executeStep()) {
        const std::string gid = q.getColumn(0).getString();
        const auto status = statusFromText(q.getColumn(1).getString());
        const int n = q.getColumn(2).getInt();
        auto it = std::find_if(out.begin(), out.end(),
                               [&](const GroupCount& c) { return c.groupId == gid; });
        if (it == out.end()) continue;
        if (status == ParticipantStatus::Dropped)
            it->dropped += n;
        else if (status == ParticipantStatus::Completed)
            it->completed += n;
        else
            it->active += n;
    }
    return out;
}

std::string StudyStore::nextGroup(int participantIndex) const {
    const auto counts = groupCounts();
    // Least-complete group: smallest share of its target (or smallest count without targets);
    // dropouts do not count, so their slot is filled again. Ties are broken at random from the
    // study seed and the participant index, so the order of groups is not predictable.
    std::vector<std::size_t> best;
    double bestShare = 0.0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const int filled = counts[i].active + counts[i].completed;
        const double share = counts[i].target > 0 ? static_cast<double>(filled) / counts[i].target
                                                  : static_cast<double>(filled);
        if (best.empty() || share < bestShare - 1e-12) {
            best = {i};
            bestShare = share;
        } else if (std::fabs(share - bestShare) <= 1e-12) {
            best.push_back(i);
        }
    }
    Rng rng(deriveSeed(info().seed, {static_cast<std::uint64_t>(participantIndex), 3}));
    return counts[best[static_cast<std::size_t>(rng.below(best.size()))]].groupId;
}

ParticipantInfo StudyStore::registerParticipant(const NewParticipant& np) {
    return registerParticipant(np, {});
}

ParticipantInfo StudyStore::registerParticipant(const NewParticipant& np,
                                                const std::map<std::string, std::string>& fields) {
    if (const auto problems = checkParticipantFields(fields); !problems.empty()) {
        std::string all;
        for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
        throw StoreError(fmt::format("participant {}: {}", np.code, all));
    }
    if (np.code.empty() || np.code.size() > 32 ||
        !std::all_of(np.code.begin(), np.code.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
        }))
        throw StoreError(fmt::format("participant code '{}': expected 1 to 32 letters, digits, "
                                     "'_' or '-' (a pseudonym, never a name)",
                                     np.code));
    if (np.age && (*np.age < 0 || *np.age > 130))
        throw StoreError(
            fmt::format("participant {}: age {} is out of range 0-130", np.code, *np.age));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    {
        SQLite::Statement exists(*db_, "SELECT 1 FROM participants WHERE code = ?");
        exists.bind(1, np.code);
        if (exists.executeStep())
            throw StoreError(
                fmt::format("{}: participant '{}' is already registered", path_, np.code));
    }
    const int index = db_->execAndGet("SELECT count(*) FROM participants").getInt();
    std::string groupId;
    Assignment assignment = Assignment::Balanced;
    if (np.groupOverride) {
        if (!protocol_->group(*np.groupOverride))
            throw StoreError(fmt::format("group override '{}' is not a group of protocol '{}'",
                                         *np.groupOverride, protocol_->id));
        if (np.overrideReason.empty())
            throw StoreError("a group override needs a reason (it is journaled)");
        groupId = *np.groupOverride;
        assignment = Assignment::Override;
    } else {
        groupId = nextGroup(index);
    }
    const std::uint64_t seed = info().seed;
    const std::vector<PlannedTrial> plan = generatePlan(*protocol_, groupId, seed, index);
    const std::string at = now();
    SQLite::Statement ins(*db_, "INSERT INTO participants (code, idx, age, gender, shoes, hearing, "
                                "group_id, assignment, override_reason, status, seed, "
                                "registered_at, simulated) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, "
                                "'registered', ?, ?, ?)");
    ins.bind(1, np.code);
    ins.bind(2, index);
    if (np.age) ins.bind(3, *np.age);
    ins.bind(4, np.gender);
    ins.bind(5, np.shoes);
    ins.bind(6, np.hearing);
    ins.bind(7, groupId);
    ins.bind(8, assignment == Assignment::Override ? "override" : "balanced");
    ins.bind(9, np.overrideReason);
    ins.bind(10, toDb(participantSeed(seed, index)));
    ins.bind(11, at);
    ins.bind(12, np.simulated ? 1 : 0);
    ins.exec();
    const std::int64_t pid = db_->getLastInsertRowid();
    const std::string fieldsText = insertNamedValues(
        *db_, "INSERT INTO participant_fields (participant_id, name, value) VALUES (?, ?, ?)", pid,
        fields);
    SQLite::Statement trial(*db_, "INSERT INTO trials (participant_id, trial_index, block, "
                                  "practice, stimulus_id, stimulus, repetition, break_after, "
                                  "planned_seed) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (const auto& t : plan) {
        trial.reset();
        trial.bind(1, pid);
        trial.bind(2, t.index);
        trial.bind(3, t.block);
        trial.bind(4, t.practice ? 1 : 0);
        trial.bind(5, t.stimulus.id);
        trial.bind(6, stimulusToToml(t.stimulus));
        trial.bind(7, t.repetition);
        trial.bind(8, t.breakAfter ? 1 : 0);
        trial.bind(9, toDb(t.plannedSeed));
        trial.exec();
    }
    appendEvent(
        JournalEvent::ParticipantRegistered, pid, std::nullopt,
        jsonObject({{"code", np.code},
                    {"index", std::to_string(index)},
                    {"group", groupId},
                    {"assignment", assignment == Assignment::Override ? "override" : "balanced"},
                    {"reason", np.overrideReason},
                    {"fields", fieldsText},
                    {"simulated", np.simulated ? "1" : "0"},
                    {"trials", std::to_string(plan.size())}}));
    tx.commit();
    return participant(np.code);
}

void StudyStore::dropParticipant(const std::string& code, const std::string& reason) {
    if (reason.empty()) throw StoreError("dropping a participant needs a reason (journaled)");
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE participants SET status = 'dropped' WHERE id = ?");
    q.bind(1, pid);
    q.exec();
    appendEvent(JournalEvent::ParticipantDropped, pid, std::nullopt,
                jsonObject({{"reason", reason}}));
    tx.commit();
}

} // namespace underfoot::experiment
