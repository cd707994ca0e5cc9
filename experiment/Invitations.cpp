// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Invitations.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>
#include <openssl/rand.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

namespace underfoot::experiment {

namespace {

std::vector<unsigned char> randomBytes(std::size_t n) {
    std::vector<unsigned char> bytes(n);
    if (RAND_bytes(bytes.data(), static_cast<int>(n)) != 1)
        throw std::runtime_error("OpenSSL RAND_bytes failed: no secure random bytes available");
    return bytes;
}

std::string text(const SQLite::Column& c) {
    return c.isNull() ? std::string() : c.getString();
}

} // namespace

std::string Invitations::newToken() {
    static constexpr char kAlphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
    const auto bytes = randomBytes(32);
    std::string out;
    std::uint32_t acc = 0;
    int bits = 0;
    for (const unsigned char b : bytes) {
        acc = (acc << 8) | b;
        bits += 8;
        while (bits >= 6) {
            bits -= 6;
            out += kAlphabet[(acc >> bits) & 0x3f];
        }
    }
    if (bits > 0) out += kAlphabet[(acc << (6 - bits)) & 0x3f];
    return out;
}

std::string Invitations::tokenHash(const std::string& token) {
    return sha256Hex(token);
}

std::string Invitations::newCompletionCode() {
    static constexpr char kAlphabet[] = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789"; // 32 symbols
    const auto bytes = randomBytes(10);
    std::string out;
    for (const unsigned char b : bytes) out += kAlphabet[b & 31];
    return out;
}

Invitations::Invitations(const StudyStore& store, Clock clock)
    : path_(store.path()),
      db_(std::make_unique<SQLite::Database>(store.path(), SQLite::OPEN_READWRITE)),
      clock_(std::move(clock)) {
    db_->exec("PRAGMA synchronous=FULL");
    db_->exec("PRAGMA foreign_keys=ON");
    db_->setBusyTimeout(5000);
    if (!db_->tableExists("online_invitations"))
        throw StoreError(fmt::format("{}: the study has no online tables (schema {}); open it "
                                     "once with this version of Underfoot to migrate it",
                                     path_, store.info().schemaVersion));
}

Invitations::~Invitations() = default;

std::vector<NewInvitation> Invitations::create(StudyStore& store, int count,
                                               const std::optional<std::string>& groupOverride,
                                               const std::string& prefix) {
    if (count < 1 || count > 10000)
        throw StoreError(
            fmt::format("{}: --count {} is out of range; expected 1 to 10000", path_, count));
    if (groupOverride && !store.protocol().group(*groupOverride)) {
        std::string groups;
        for (const auto& g : store.protocol().groups) groups += (groups.empty() ? "" : ", ") + g.id;
        throw StoreError(fmt::format("{}: group '{}' is not a group of protocol '{}'; expected "
                                     "one of: {}",
                                     path_, *groupOverride, store.protocol().id, groups));
    }
    if (prefix.empty() || prefix.size() > 16 ||
        !std::all_of(prefix.begin(), prefix.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
        }))
        throw StoreError(fmt::format("participant code prefix '{}': expected 1 to 16 letters, "
                                     "digits, '_' or '-'",
                                     prefix));
    std::set<std::string> used;
    for (const auto& p : store.participants()) used.insert(p.code);
    {
        SQLite::Statement q(*db_, "SELECT participant_code FROM online_invitations");
        while (q.executeStep()) used.insert(q.getColumn(0).getString());
    }
    std::vector<NewInvitation> out;
    const std::string at = isoUtc(clock_.now());
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    int n = 1;
    for (int i = 0; i < count; ++i) {
        std::string code;
        do code = fmt::format("{}{:03d}", prefix, n++);
        while (used.count(code));
        used.insert(code);
        NewInvitation inv{code, newToken()};
        SQLite::Statement q(*db_, "INSERT INTO online_invitations (token_sha256, "
                                  "participant_code, group_override, completion_code, created_at) "
                                  "VALUES (?, ?, ?, ?, ?)");
        q.bind(1, tokenHash(inv.token));
        q.bind(2, code);
        if (groupOverride) q.bind(3, *groupOverride);
        q.bind(4, newCompletionCode());
        q.bind(5, at);
        q.exec();
        out.push_back(std::move(inv));
    }
    tx.commit();
    store.journal(JournalEvent::OnlineInvited, "", std::nullopt,
                  jsonObject({{"count", std::to_string(count)},
                              {"first", out.front().participantCode},
                              {"last", out.back().participantCode},
                              {"group", groupOverride.value_or("")}}));
    return out;
}

Invitation Invitations::read(const std::string& where, const std::string& value) const {
    SQLite::Statement q(*db_, "SELECT id, participant_code, group_override, completion_code, "
                              "created_at, consented_at, screening_passed, screening_detail "
                              "FROM online_invitations WHERE " +
                                  where + " = ?");
    q.bind(1, value);
    if (!q.executeStep())
        throw StoreError(fmt::format("{}: no invitation for this participant or link", path_));
    Invitation i;
    i.id = q.getColumn(0).getInt64();
    i.participantCode = q.getColumn(1).getString();
    if (!q.getColumn(2).isNull()) i.groupOverride = q.getColumn(2).getString();
    i.completionCode = q.getColumn(3).getString();
    i.createdAt = q.getColumn(4).getString();
    i.consentedAt = text(q.getColumn(5));
    if (!q.getColumn(6).isNull()) i.screeningPassed = q.getColumn(6).getInt() != 0;
    i.screeningDetail = text(q.getColumn(7));
    return i;
}

std::optional<Invitation> Invitations::find(const std::string& token) const {
    // Only well-formed tokens are hashed and looked up.
    if (token.size() != 43 || !std::all_of(token.begin(), token.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
        }))
        return std::nullopt;
    try {
        return read("token_sha256", tokenHash(token));
    } catch (const StoreError&) {
        return std::nullopt;
    }
}

Invitation Invitations::byCode(const std::string& participantCode) const {
    return read("participant_code", participantCode);
}

std::vector<Invitation> Invitations::all() const {
    std::vector<std::string> codes;
    SQLite::Statement q(*db_, "SELECT participant_code FROM online_invitations ORDER BY id");
    while (q.executeStep()) codes.push_back(q.getColumn(0).getString());
    std::vector<Invitation> out;
    for (const auto& c : codes) out.push_back(byCode(c));
    return out;
}

void Invitations::recordConsent(std::int64_t invitationId) {
    SQLite::Statement q(*db_, "UPDATE online_invitations SET consented_at = ? WHERE id = ? AND "
                              "consented_at IS NULL");
    q.bind(1, isoUtc(clock_.now()));
    q.bind(2, invitationId);
    q.exec();
}

void Invitations::recordScreening(std::int64_t invitationId, bool passed,
                                  const std::string& detailJson) {
    SQLite::Statement q(*db_, "UPDATE online_invitations SET screening_passed = ?, "
                              "screening_detail = ?, screened_at = ? WHERE id = ?");
    q.bind(1, passed ? 1 : 0);
    q.bind(2, detailJson);
    q.bind(3, isoUtc(clock_.now()));
    q.bind(4, invitationId);
    q.exec();
}

void Invitations::recordClient(std::int64_t invitationId, const OnlineClient& client) {
    if (client.audioSampleRateHz &&
        (!std::isfinite(*client.audioSampleRateHz) || *client.audioSampleRateHz <= 0))
        throw StoreError("audio sample rate must be a finite number > 0");
    SQLite::Statement q(*db_, "INSERT OR REPLACE INTO online_sessions (invitation_id, "
                              "session_number, started_at, user_agent, audio_sample_rate_hz) "
                              "VALUES (?, ?, ?, ?, ?)");
    q.bind(1, invitationId);
    q.bind(2, client.sessionNumber);
    q.bind(3, isoUtc(clock_.now()));
    q.bind(4, client.userAgent);
    if (client.audioSampleRateHz) q.bind(5, *client.audioSampleRateHz);
    q.exec();
}

std::vector<OnlineClient> Invitations::clients(std::int64_t invitationId) const {
    SQLite::Statement q(*db_, "SELECT session_number, user_agent, audio_sample_rate_hz FROM "
                              "online_sessions WHERE invitation_id = ? ORDER BY session_number");
    q.bind(1, invitationId);
    std::vector<OnlineClient> out;
    while (q.executeStep()) {
        OnlineClient c;
        c.sessionNumber = q.getColumn(0).getInt();
        c.userAgent = q.getColumn(1).getString();
        if (!q.getColumn(2).isNull()) c.audioSampleRateHz = q.getColumn(2).getDouble();
        out.push_back(c);
    }
    return out;
}

std::optional<AnswerAttempt> Invitations::attempt(std::int64_t invitationId, int trialIndex) const {
    SQLite::Statement q(*db_, "SELECT attempt_id, client_response_time_ms, received_at FROM "
                              "online_answers WHERE invitation_id = ? AND trial_index = ?");
    q.bind(1, invitationId);
    q.bind(2, trialIndex);
    if (!q.executeStep()) return std::nullopt;
    AnswerAttempt a;
    a.attemptId = q.getColumn(0).getString();
    if (!q.getColumn(1).isNull()) a.clientResponseTimeMs = q.getColumn(1).getDouble();
    a.receivedAt = q.getColumn(2).getString();
    return a;
}

void Invitations::recordAttempt(std::int64_t invitationId, int trialIndex,
                                const std::string& attemptId,
                                std::optional<double> clientResponseTimeMs) {
    if (clientResponseTimeMs &&
        (!std::isfinite(*clientResponseTimeMs) || *clientResponseTimeMs < 0))
        throw StoreError("browser response time must be a finite number >= 0 ms");
    SQLite::Statement q(*db_, "INSERT OR REPLACE INTO online_answers (invitation_id, trial_index, "
                              "attempt_id, client_response_time_ms, received_at) VALUES (?, ?, "
                              "?, ?, ?)");
    q.bind(1, invitationId);
    q.bind(2, trialIndex);
    q.bind(3, attemptId);
    if (clientResponseTimeMs) q.bind(4, *clientResponseTimeMs);
    q.bind(5, isoUtc(clock_.now()));
    q.exec();
}

} // namespace underfoot::experiment
