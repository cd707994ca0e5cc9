// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The online participant API of `underfoot serve`, independent of HTTP: every call takes the
/// participant's link token and a JSON body and returns JSON, or throws ApiError (status code
/// and a message for the page). It is an adapter of experiment::TrialFlow, one per participant
/// (the same screen model, progress text, answer and rating validation, commit and replay
/// counts as the terminal session and the console): it renders the flow's participant screen
/// as JSON and forwards the page's answers to it. Each session plays through a
/// ClipPlayer that plays nothing (the browser fetches and plays the clip) but stores, with each
/// trial, the clip's seed, length and samples' SHA-256 from the manifest, as the booth does. A
/// clip is served only while its file matches the manifest.
///
/// Everything is validated against the protocol before it is stored; a refused request of a
/// known participant is journaled ("online_refused"). One mutex serialises the store.
#include "experiment/Clips.h"
#include "experiment/HeadphoneCheck.h"
#include "experiment/Invitations.h"
#include "experiment/Session.h"
#include "experiment/Store.h"
#include "experiment/TrialFlow.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

namespace underfoot::web {

/// A refused request: HTTP status and a message naming what was expected.
struct ApiError : std::runtime_error {
    ApiError(int statusCode, const std::string& message, int retryAfterSeconds = 0)
        : std::runtime_error(message), status(statusCode), retryAfter(retryAfterSeconds) {}
    int status;
    /// Seconds for a Retry-After header (0: none): the request may succeed later as it is.
    int retryAfter;
};

/// What happens when a participant fails the headphone screening.
enum class ScreeningFailure { Flag, End };

struct WebOptions {
    /// Folder of the protocol's clips (`underfoot clips -o DIR`).
    std::string clipsDir;
    ScreeningFailure screeningFailure = ScreeningFailure::Flag;
    /// A headphone-check answer sooner than this after its tones were served is refused
    /// (default: the tones' length, 4 s; `serve --screening-min-response`, for tests).
    double screeningMinResponseS = experiment::HeadphoneCheck::tripletSeconds();
    /// Longest comment / answer text accepted (characters).
    std::size_t maxText = 2000;
};

/// A clip file resolved inside the clips folder.
struct ClipFile {
    std::string path;
    std::string contentType;
    std::uintmax_t size = 0;
};

/// Throws std::runtime_error with a clear message when `protocol` cannot run in a browser
/// (laps, live sensor input, no [clips]).
void checkOnlineProtocol(const experiment::Protocol& protocol);

class WebStudy {
  public:
    /// Opens the study (refusing protocols that cannot run online and missing clip files).
    WebStudy(const std::string& studyPath, WebOptions options);
    ~WebStudy();

    nlohmann::json state(const std::string& token);
    /// Consent with answers to the protocol's participant fields: registers the participant.
    nlohmann::json consent(const std::string& token, const nlohmann::json& body);
    /// The browser's audio output rate (and the user agent header).
    nlohmann::json client(const std::string& token, const nlohmann::json& body,
                          const std::string& userAgent);
    /// Starts the headphone check (idempotent): the server draws and journals its seed, which
    /// lays out every triplet ("online_screening_started").
    nlohmann::json screeningStart(const std::string& token, const nlohmann::json& body);
    /// The tones of triplet `index` of the check (a WAV file), only for the triplet waiting for
    /// an answer; the time it is first served starts that triplet's minimum response time.
    std::string screeningTones(const std::string& token, int index);
    /// The participant's choice for one triplet: `{"triplet": k, "choice": 1..3}`. Scored and
    /// journaled here ("online_screening_answer"); after the last triplet the verdict is stored.
    nlohmann::json screening(const std::string& token, const nlohmann::json& body);
    /// Presents (first time) or replays (counted) the current trial's clip.
    nlohmann::json present(const std::string& token, const nlohmann::json& body);
    /// Commits an answer (idempotent by attempt id).
    nlohmann::json answer(const std::string& token, const nlohmann::json& body);
    nlohmann::json finishBreak(const std::string& token, const nlohmann::json& body);
    /// The clip of the participant's current trial.
    ClipFile clip(const std::string& token, int trialIndex);
    /// Whether `token` opens an invitation of this study (the HTTP layer asks before it reads
    /// a request's body and keys the rate limit by it).
    bool isInvitation(const std::string& token) const;

    /// Closes every open session as interrupted (resumable); the server's clean stop.
    void stop();
    /// Participants with an open session.
    int openSessions() const;
    const std::string& studyPath() const { return studyPath_; }

  private:
    struct Participant {
        experiment::Invitation invitation;
        std::unique_ptr<experiment::Session> session;
    };
    experiment::Invitation invitation(const std::string& token);
    /// The participant's session, opened (or resumed) when needed; null when not registered yet,
    /// dropped, or finished (every trial answered: nothing else counts as finished). A session
    /// that cannot be opened now (its lease held by a live process) is a retryable 503.
    experiment::Session* session(const experiment::Invitation& inv);
    nlohmann::json stateOf(const experiment::Invitation& inv);
    /// The participant's trial flow (made with the session; null when there is none).
    experiment::TrialFlow* flow(const std::string& code);
    /// Drops a participant's flow and session (in that order: the flow refers to the session).
    void close(const std::string& code);
    /// The current trial as TrialFlow's participant screen shows it.
    nlohmann::json trialJson(const experiment::TrialFlow& flow) const;
    [[noreturn]] void refuse(const experiment::Invitation& inv, std::optional<int> trial,
                             const std::string& request, int status, const std::string& reason);
    /// The participant's running check: in memory, else restored from the journal (the last
    /// "online_screening_started" and its answers); null when none was started.
    experiment::HeadphoneCheck* check(const experiment::Invitation& inv);
    int currentTrialChecked(const experiment::Invitation& inv, experiment::Session* s,
                            const nlohmann::json& body, const std::string& request);

    std::string studyPath_;
    WebOptions options_;
    mutable std::mutex mutex_;
    experiment::StudyStore store_;
    std::unique_ptr<experiment::Invitations> invitations_;
    std::unique_ptr<experiment::ClipPlayer> player_;
    std::map<std::string, std::unique_ptr<experiment::Session>> sessions_;
    std::map<std::string, std::unique_ptr<experiment::TrialFlow>> flows_;
    /// The last play id of each participant (trial:attempt), for idempotent presentations.
    std::map<std::string, std::string> lastPresent_;
    /// Running headphone checks and when each one's current triplet was first served.
    struct Screening {
        std::unique_ptr<experiment::HeadphoneCheck> check;
        std::optional<std::chrono::steady_clock::time_point> served;
    };
    std::map<std::string, Screening> checks_;
};

} // namespace underfoot::web
