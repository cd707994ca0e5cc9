// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Online participation (`underfoot study invite`, `underfoot serve`): secret links, online
/// sessions and answer attempts, kept in the study file beside the booth's data.
///
/// A link carries a token of 256 random bits (OpenSSL RAND_bytes, base64url); the study stores
/// only its SHA-256. An invitation names the pseudonymous participant code it will register
/// (and an optional group override); the participant is registered, like in the booth (group,
/// seeded plan, participant fields), when the page submits the consent form, so participant
/// fields the protocol requires are answered by the participant. No HTTP here.
#include "experiment/Store.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace SQLite {
class Database;
}

namespace underfoot::experiment {

/// One invitation as stored (never the token itself).
struct Invitation {
    std::int64_t id = 0;
    std::string participantCode;
    std::optional<std::string> groupOverride;
    std::string completionCode;
    std::string createdAt;
    /// When the participant consented and was registered ("" before).
    std::string consentedAt;
    /// The headphone screening's result (nullopt: not done yet) and its details (JSON).
    std::optional<bool> screeningPassed;
    std::string screeningDetail;
};

/// A freshly created link: shown once (links.csv), then only its hash is known.
struct NewInvitation {
    std::string participantCode;
    std::string token;
};

/// What the browser reported about one online session.
struct OnlineClient {
    int sessionNumber = 0;
    std::string userAgent;
    std::optional<double> audioSampleRateHz;
};

/// An answer attempt recorded before the answer is committed (idempotent submissions).
struct AnswerAttempt {
    std::string attemptId;
    std::optional<double> clientResponseTimeMs;
    std::string receivedAt;
};

class Invitations {
  public:
    /// Opens the online tables of `store`'s study file (a second connection to the same file).
    explicit Invitations(const StudyStore& store, Clock clock = {});
    ~Invitations();
    Invitations(const Invitations&) = delete;
    Invitations& operator=(const Invitations&) = delete;

    /// Creates `count` invitations (participant codes `<prefix>001`, ... not used yet by a
    /// participant or an invitation), all in one transaction; journaled. `groupOverride` must
    /// be a group of the protocol. Throws StoreError.
    std::vector<NewInvitation> create(StudyStore& store, int count,
                                      const std::optional<std::string>& groupOverride,
                                      const std::string& prefix = "W");

    /// The invitation a token opens, or nullopt (wrong, malformed or unknown token).
    std::optional<Invitation> find(const std::string& token) const;
    Invitation byCode(const std::string& participantCode) const;
    std::vector<Invitation> all() const;

    /// Records consent (once; later calls keep the first time).
    void recordConsent(std::int64_t invitationId);
    /// Records the headphone screening (the last result counts).
    void recordScreening(std::int64_t invitationId, bool passed, const std::string& detailJson);
    /// Records the browser of one session (insert or replace).
    void recordClient(std::int64_t invitationId, const OnlineClient& client);
    std::vector<OnlineClient> clients(std::int64_t invitationId) const;

    /// The attempt recorded for a trial, if any.
    std::optional<AnswerAttempt> attempt(std::int64_t invitationId, int trialIndex) const;
    /// Records (or replaces) the attempt of a trial, durably, before its answer is committed.
    void recordAttempt(std::int64_t invitationId, int trialIndex, const std::string& attemptId,
                       std::optional<double> clientResponseTimeMs);

    /// A new random link token (256 bits, base64url without padding: 43 characters).
    static std::string newToken();
    /// SHA-256 (hex) of a token, as stored.
    static std::string tokenHash(const std::string& token);
    /// A completion code (10 characters from an unambiguous alphabet).
    static std::string newCompletionCode();

  private:
    Invitation read(const std::string& where, const std::string& value) const;

    std::string path_;
    std::unique_ptr<SQLite::Database> db_;
    Clock clock_;
};

} // namespace underfoot::experiment
