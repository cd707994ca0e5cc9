// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/WebStudy.h"
#include "base/Version.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace underfoot::web {

using namespace underfoot::experiment;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// Correct answers needed in the headphone screening (Woods et al. 2017: 5 of 6).
int screeningPassMark(int total) {
    return static_cast<int>(std::ceil(total * 5.0 / 6.0));
}

std::string contentTypeOf(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".wav") return "audio/wav";
    if (ext == ".flac") return "audio/flac";
    if (ext == ".ogg" || ext == ".oga") return "audio/ogg";
    if (ext == ".mp3") return "audio/mpeg";
    return "application/octet-stream";
}

/// Reads an optional member of the expected type; throws ApiError 400 otherwise.
template <typename T>
std::optional<T> member(const json& body, const char* name, const std::string& request) {
    if (!body.is_object())
        throw ApiError(400, fmt::format("{}: expected a JSON object as the request body", request));
    const auto it = body.find(name);
    if (it == body.end() || it->is_null()) return std::nullopt;
    bool ok = false;
    if constexpr (std::is_same_v<T, std::string>)
        ok = it->is_string();
    else if constexpr (std::is_same_v<T, bool>)
        ok = it->is_boolean();
    else if constexpr (std::is_integral_v<T>)
        ok = it->is_number_integer();
    else if constexpr (std::is_floating_point_v<T>)
        ok = it->is_number();
    else
        ok = true;
    if (!ok)
        throw ApiError(400, fmt::format("{}: '{}' has the wrong type; expected {}", request, name,
                                        std::is_same_v<T, std::string> ? "a string"
                                        : std::is_same_v<T, bool>      ? "true or false"
                                        : std::is_integral_v<T>        ? "an integer"
                                                                       : "a number"));
    if constexpr (std::is_floating_point_v<T>) {
        const double v = it->get<double>();
        if (!std::isfinite(v))
            throw ApiError(400, fmt::format("{}: '{}' must be a finite number", request, name));
        return v;
    } else {
        return it->get<T>();
    }
}

json optionsJson(const std::vector<AnswerOption>& options) {
    json out = json::array();
    for (const auto& o : options)
        out.push_back({{"id", o.id}, {"label", o.label}, {"key", std::string(1, o.letter)}});
    return out;
}

} // namespace

void checkOnlineProtocol(const Protocol& protocol) {
    if (protocol.laps.total() > 0)
        throw std::runtime_error(fmt::format(
            "protocol '{}' walks {} laps per condition ([laps]): interactive walking tests need "
            "the booth's sensors and cannot run online; run them with `underfoot session --live` "
            "or the console",
            protocol.id, protocol.laps.total()));
    if (!protocol.clips.enabled)
        throw std::runtime_error(fmt::format(
            "protocol '{}' has no [clips] section: only listening tests of pre-rendered clips run "
            "online (add [clips] and render them with `underfoot clips`)",
            protocol.id));
    for (const auto& s : protocol.stimuli)
        if (s.modalities == Modalities::Haptic)
            throw std::runtime_error(
                fmt::format("protocol '{}': stimulus '{}' is haptic only; a browser plays sound "
                            "only",
                            protocol.id, s.id));
}

WebStudy::WebStudy(const std::string& studyPath, WebOptions options)
    : studyPath_(studyPath), options_(std::move(options)), store_(StudyStore::open(studyPath)) {
    checkOnlineProtocol(store_.protocol());
    std::error_code ec;
    if (!fs::is_directory(options_.clipsDir, ec))
        throw std::runtime_error(
            fmt::format("{}: the clips folder does not exist; expected the folder written by "
                        "`underfoot clips --protocol ... -o DIR`",
                        options_.clipsDir));
    // Every clip must be there before the first participant comes.
    std::string missing;
    for (const auto& s : store_.protocol().stimuli) {
        const fs::path p = clipPath(s, options_.clipsDir);
        if (!fs::is_regular_file(p, ec))
            missing += fmt::format("\n  {} (stimulus {})", p.string(), s.id);
    }
    if (!missing.empty())
        throw std::runtime_error(fmt::format("{}: clips missing (render them with `underfoot "
                                             "clips --protocol ... -o {}`):{}",
                                             options_.clipsDir, options_.clipsDir, missing));
    invitations_ = std::make_unique<Invitations>(store_);
}

WebStudy::~WebStudy() {
    stop();
}

void WebStudy::stop() {
    std::lock_guard lock(mutex_);
    for (auto& [code, s] : sessions_) {
        try {
            if (s && s->phase() != SessionPhase::Finished) s->interrupt();
        } catch (const std::exception&) {
            // The session row stays open; the next start resumes at the first unanswered trial.
        }
    }
    sessions_.clear();
}

int WebStudy::openSessions() const {
    std::lock_guard lock(mutex_);
    return static_cast<int>(sessions_.size());
}

Invitation WebStudy::invitation(const std::string& token) {
    auto inv = invitations_->find(token);
    if (!inv)
        throw ApiError(403, "this link is not valid (unknown or mistyped token); please use the "
                            "exact link you received");
    return *inv;
}

void WebStudy::refuse(const Invitation& inv, std::optional<int> trial, const std::string& request,
                      int status, const std::string& reason) {
    const std::string detail = jsonObject({{"participant", inv.participantCode},
                                           {"request", request},
                                           {"status", std::to_string(status)},
                                           {"reason", reason}});
    try {
        try {
            store_.journal("online_refused", inv.participantCode, trial, detail);
        } catch (const StoreError&) {
            store_.journal("online_refused", "", trial, detail); // not registered yet
        }
    } catch (const std::exception&) {
        // A journal failure must not turn a refusal into an acceptance.
    }
    throw ApiError(status, reason);
}

Session* WebStudy::session(const Invitation& inv) {
    const std::string& code = inv.participantCode;
    if (auto it = sessions_.find(code); it != sessions_.end()) {
        if (it->second->phase() != SessionPhase::Finished) return it->second.get();
        sessions_.erase(it);
    }
    ParticipantInfo p;
    try {
        p = store_.participant(code);
    } catch (const StoreError&) {
        return nullptr; // not registered yet (consent pending)
    }
    if (p.status == ParticipantStatus::Dropped || p.status == ParticipantStatus::Completed)
        return nullptr;
    SessionSettings settings;
    settings.experimenter = "online";
    settings.audioConfig = "browser";
    settings.sensorConfig = "none";
    settings.appVersion = underfoot::base::version();
    std::unique_ptr<Session> s;
    try {
        s = std::make_unique<Session>(store_, code, player_, settings);
    } catch (const StoreError&) {
        return nullptr; // every trial answered: marked completed by the session
    }
    // Consent is the briefing: a participant who consented goes straight to the trials.
    if (s->phase() == SessionPhase::Briefing) s->finishBriefing();
    Session* raw = s.get();
    sessions_[code] = std::move(s);
    return raw;
}

json WebStudy::trialJson(const Session& s) const {
    const Protocol& protocol = store_.protocol();
    const Questions& q = protocol.questions;
    const TrialRecord& t = s.current();
    json j;
    j["index"] = t.index;
    j["practice"] = t.practice;
    j["presented"] = s.playing();
    j["replays"] = t.replays;
    j["replayAllowed"] = protocol.clips.replay;
    if (q.asksSurface()) {
        j["surface"] = {
            {"prompt", q.surfacePrompt.empty() ? "Which surface is it?" : q.surfacePrompt},
            {"options", optionsJson(q.surfaceOptions)}};
    }
    json scales = json::array();
    for (const Scale* sc : s.askedScales()) {
        json anchors = json::array();
        for (const auto& [v, label] : sc->anchors)
            anchors.push_back({{"value", v}, {"label", label}});
        scales.push_back({{"id", sc->id},
                          {"prompt", sc->prompt},
                          {"min", sc->min},
                          {"max", sc->max},
                          {"minLabel", sc->minLabel},
                          {"maxLabel", sc->maxLabel},
                          {"anchors", anchors}});
    }
    j["scales"] = scales;
    if (q.asksSoundscape(s.participant().groupId) && !q.soundscapeOptions.empty())
        j["soundscape"] = {{"prompt", q.soundscapePrompt.empty() ? "Which environment is it?"
                                                                 : q.soundscapePrompt},
                           {"options", optionsJson(q.soundscapeOptions)}};
    j["comment"] = q.comment;
    return j;
}

json WebStudy::stateOf(const Invitation& inv) {
    const Protocol& protocol = store_.protocol();
    json j;
    j["participant"] = inv.participantCode;
    j["study"] = {{"title", protocol.title}, {"description", protocol.description}};
    std::optional<ParticipantInfo> p;
    try {
        p = store_.participant(inv.participantCode);
    } catch (const StoreError&) {
    }
    if (!p) {
        j["phase"] = "consent";
        json fields = json::array();
        for (const auto& f : protocol.participantFields)
            fields.push_back({{"id", f.id},
                              {"label", f.label},
                              {"options", f.options},
                              {"required", f.required}});
        j["fields"] = fields;
        return j;
    }
    if (inv.screeningPassed) j["screening"] = {{"passed", *inv.screeningPassed}};
    if (p->status == ParticipantStatus::Dropped) {
        j["phase"] = "ended";
        j["reason"] = inv.screeningPassed == false ? "screening" : "dropped";
        return j;
    }
    Session* s = session(inv);
    if (!s) {
        const auto trials = store_.trials(p->code);
        j["progress"] = {{"answered", std::count_if(trials.begin(), trials.end(),
                                                    [](const auto& t) { return t.answered; })},
                         {"total", trials.size()}};
        j["phase"] = "finished";
        j["completionCode"] = inv.completionCode;
        return j;
    }
    j["progress"] = {{"answered", s->answeredCount()}, {"total", s->trialCount()}};
    if (!inv.screeningPassed) {
        j["phase"] = "screening";
        return j;
    }
    switch (s->phase()) {
    case SessionPhase::Break:
        j["phase"] = "break";
        break;
    case SessionPhase::Practice:
    case SessionPhase::Trial:
        j["phase"] = s->phase() == SessionPhase::Practice ? "practice" : "trial";
        j["trial"] = trialJson(*s);
        break;
    default:
        j["phase"] = "finished";
        j["completionCode"] = inv.completionCode;
        break;
    }
    return j;
}

json WebStudy::state(const std::string& token) {
    std::lock_guard lock(mutex_);
    return stateOf(invitation(token));
}

json WebStudy::consent(const std::string& token, const json& body) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    const std::string request = "consent";
    if (member<bool>(body, "consent", request) != true)
        throw ApiError(400, "consent: expected \"consent\": true (the participant agreed)");
    bool registered = true;
    try {
        store_.participant(inv.participantCode);
    } catch (const StoreError&) {
        registered = false;
    }
    if (!registered) {
        std::map<std::string, std::string> fields;
        if (const auto f = body.find("fields"); f != body.end() && !f->is_null()) {
            if (!f->is_object() || f->size() > 64)
                throw ApiError(400, "consent: 'fields' must be an object of field id -> answer");
            for (const auto& [k, v] : f->items()) {
                if (!v.is_string() || v.get<std::string>().size() > options_.maxText)
                    throw ApiError(400, fmt::format("consent: field '{}' must be a text of at "
                                                    "most {} characters",
                                                    k, options_.maxText));
                if (!v.get<std::string>().empty()) fields[k] = v.get<std::string>();
            }
        }
        if (const auto problems = store_.checkParticipantFields(fields); !problems.empty()) {
            std::string all;
            for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
            throw ApiError(422, "consent: " + all);
        }
        NewParticipant np;
        np.code = inv.participantCode;
        if (inv.groupOverride) {
            np.groupOverride = inv.groupOverride;
            np.overrideReason = "online invitation for this group (study invite --group)";
        }
        try {
            store_.registerParticipant(np, fields);
        } catch (const StoreError& e) {
            throw ApiError(422, fmt::format("consent: {}", e.what()));
        }
    }
    invitations_->recordConsent(inv.id);
    return stateOf(invitations_->byCode(inv.participantCode));
}

json WebStudy::client(const std::string& token, const json& body, const std::string& userAgent) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    if (!s) return stateOf(inv); // before consent or after the end: nothing to attach it to
    OnlineClient c;
    c.sessionNumber = s->sessionNumber();
    c.userAgent = userAgent.substr(0, 512);
    c.audioSampleRateHz = member<double>(body, "sampleRate", "client");
    if (c.audioSampleRateHz && (*c.audioSampleRateHz < 1000 || *c.audioSampleRateHz > 768000))
        throw ApiError(400, fmt::format("client: sampleRate {} Hz is out of range; expected "
                                        "1000 to 768000",
                                        *c.audioSampleRateHz));
    invitations_->recordClient(inv.id, c);
    return stateOf(inv);
}

json WebStudy::screening(const std::string& token, const json& body) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    if (!s) refuse(inv, std::nullopt, "screening", 409, "screening: no running session");
    if (inv.screeningPassed)
        return stateOf(inv); // already screened (a retry or a reload): the first result counts
    const auto correct = member<int>(body, "correct", "screening");
    const auto total = member<int>(body, "total", "screening");
    if (!correct || !total || *total < 1 || *total > 100 || *correct < 0 || *correct > *total)
        refuse(inv, std::nullopt, "screening", 400,
               "screening: expected integers 'correct' and 'total' with 0 <= correct <= total <= "
               "100");
    const bool passed = *correct >= screeningPassMark(*total);
    const std::string detail = json({{"test", "woods2017_antiphase"},
                                     {"correct", *correct},
                                     {"total", *total},
                                     {"passMark", screeningPassMark(*total)}})
                                   .dump();
    invitations_->recordScreening(inv.id, passed, detail);
    store_.journal(passed ? "online_screening_passed" : "online_screening_failed",
                   inv.participantCode, std::nullopt, detail);
    if (!passed && options_.screeningFailure == ScreeningFailure::End) {
        s->interrupt();
        sessions_.erase(inv.participantCode);
        store_.dropParticipant(inv.participantCode, "failed the headphone screening (online)");
    }
    return stateOf(invitations_->byCode(inv.participantCode));
}

int WebStudy::currentTrialChecked(const Invitation& inv, Session* s, const json& body,
                                  const std::string& request) {
    const auto trial = member<int>(body, "trial", request);
    if (!trial) throw ApiError(400, fmt::format("{}: expected an integer 'trial'", request));
    if (const auto who = member<std::string>(body, "participant", request);
        who && *who != inv.participantCode)
        refuse(inv, trial, request, 403,
               fmt::format("{}: trial of participant '{}' refused; this link belongs to another "
                           "participant",
                           request, *who));
    if (!s) refuse(inv, trial, request, 409, fmt::format("{}: no running session", request));
    if (!inv.screeningPassed)
        refuse(inv, trial, request, 409,
               fmt::format("{}: the headphone screening comes first", request));
    if (s->phase() != SessionPhase::Trial && s->phase() != SessionPhase::Practice)
        refuse(inv, trial, request, 409,
               fmt::format("{}: trial index {} refused; the session is in phase '{}'", request,
                           *trial, toString(s->phase())));
    if (*trial != s->current().index)
        refuse(inv, trial, request, 409,
               fmt::format("{}: trial index {} refused; the current trial index is {}", request,
                           *trial, s->current().index));
    return *trial;
}

json WebStudy::present(const std::string& token, const json& body) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    const int trial = currentTrialChecked(inv, s, body, "present");
    // The page names each play with an id: a retry after a lost reply is not another replay.
    const auto playAttempt = member<std::string>(body, "attempt", "present");
    if (playAttempt && playAttempt->size() > 64)
        throw ApiError(400, "present: 'attempt' is longer than 64 characters");
    const std::string playId = playAttempt ? fmt::format("{}:{}", trial, *playAttempt) : "";
    std::string& last = lastPresent_[inv.participantCode];
    if (playId.empty() || playId != last) {
        try {
            s->presentClip();
        } catch (const StoreError& e) {
            refuse(inv, trial, "present", 409, fmt::format("present: {}", e.what()));
        }
        last = playId;
    }
    json j = stateOf(inv);
    j["replays"] = s->replayCount();
    return j;
}

json WebStudy::answer(const std::string& token, const json& body) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    const std::string request = "answer";
    const auto attempt = member<std::string>(body, "attempt", request);
    if (!attempt || attempt->empty() || attempt->size() > 64 ||
        !std::all_of(attempt->begin(), attempt->end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
        }))
        throw ApiError(400, "answer: expected 'attempt', 1 to 64 letters, digits, '-' or '_' "
                            "(one id per trial attempt)");
    const auto trialIndex = member<int>(body, "trial", request);
    if (!trialIndex) throw ApiError(400, "answer: expected an integer 'trial'");
    // A retry of an acknowledged answer: acknowledged again, never stored twice.
    bool registered = true;
    try {
        store_.participant(inv.participantCode);
    } catch (const StoreError&) {
        registered = false;
    }
    if (registered) {
        std::optional<TrialRecord> t;
        try {
            t = store_.trial(inv.participantCode, *trialIndex);
        } catch (const StoreError&) {
            // not a trial of this participant: refused below
        }
        if (t) {
            if (t->answered) {
                const auto previous = invitations_->attempt(inv.id, *trialIndex);
                if (previous && previous->attemptId == *attempt) {
                    json j = stateOf(inv);
                    j["stored"] = true;
                    j["duplicate"] = true;
                    return j;
                }
                refuse(inv, *trialIndex, request, 409,
                       fmt::format("answer: trial index {} is already answered", *trialIndex));
            }
        }
    }
    Session* s = session(inv);
    const int trial = currentTrialChecked(inv, s, body, request);
    const TrialRecord& t = s->current();
    TrialAnswer a;
    a.answer = member<std::string>(body, "answer", request).value_or("");
    a.soundscapeAnswer = member<std::string>(body, "soundscape", request).value_or("");
    a.comment = member<std::string>(body, "comment", request).value_or("");
    if (a.answer.size() > options_.maxText || a.soundscapeAnswer.size() > options_.maxText ||
        a.comment.size() > options_.maxText)
        refuse(inv, trial, request, 400,
               fmt::format("answer: texts are limited to {} characters", options_.maxText));
    if (!store_.protocol().questions.comment && !a.comment.empty())
        refuse(inv, trial, request, 422, "answer: this protocol asks no comment");
    if (const auto r = body.find("ratings"); r != body.end() && !r->is_null()) {
        if (!r->is_object() || r->size() > 64)
            refuse(inv, trial, request, 400,
                   "answer: 'ratings' must be an object scale -> integer");
        for (const auto& [k, v] : r->items()) {
            if (!v.is_number_integer() || v.get<std::int64_t>() < -1000000 ||
                v.get<std::int64_t>() > 1000000)
                refuse(inv, trial, request, 422,
                       fmt::format("answer: rating '{}' must be an integer on its scale", k));
            a.ratings[k] = v.get<int>();
        }
    }
    const auto clientMs = member<double>(body, "clientMs", request);
    if (clientMs && (*clientMs < 0 || *clientMs > 86400000.0))
        refuse(inv, trial, request, 400, "answer: 'clientMs' must be 0 to 86400000 ms");
    if (const auto problems = store_.checkAnswer(s->participant().groupId, a, t.stimulus, t.block);
        !problems.empty()) {
        std::string all;
        for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
        refuse(inv, trial, request, 422, "answer: " + all);
    }
    if (!s->playing()) {
        if (t.startedAt.empty())
            refuse(inv, trial, request, 409,
                   fmt::format("answer: trial index {} was not presented yet; play the clip first",
                               trial));
        // Presented before a server restart: the presentation is restored (journaled as a
        // restart of the trial by the store), then the answer is committed.
        s->play();
    }
    invitations_->recordAttempt(inv.id, trial, *attempt, clientMs);
    try {
        s->answer(a);
    } catch (const StoreError& e) {
        refuse(inv, trial, request, 422, fmt::format("answer: {}", e.what()));
    }
    json j = stateOf(inv);
    j["stored"] = true;
    j["duplicate"] = false;
    return j;
}

json WebStudy::finishBreak(const std::string& token, const json& body) {
    (void)body;
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    if (s && s->phase() == SessionPhase::Break) s->finishBreak();
    return stateOf(inv);
}

ClipFile WebStudy::clip(const std::string& token, int trialIndex) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    const int trial = currentTrialChecked(inv, s, json{{"trial", trialIndex}}, "clip");
    const Stimulus& stimulus = s->current().stimulus;
    std::error_code ec;
    const fs::path root = fs::canonical(options_.clipsDir, ec);
    if (ec) refuse(inv, trial, "clip", 500, "clip: the clips folder is not readable");
    const fs::path file = fs::weakly_canonical(fs::path(clipPath(stimulus, options_.clipsDir)), ec);
    // Only regular files inside the clips folder (after resolving '..' and symbolic links).
    const auto [rootEnd, fileIt] =
        std::mismatch(root.begin(), root.end(), file.begin(), file.end());
    if (ec || rootEnd != root.end() || fileIt == file.end())
        refuse(
            inv, trial, "clip", 403,
            fmt::format("clip: the clip of trial index {} lies outside the clips folder", trial));
    if (!fs::is_regular_file(file, ec))
        refuse(inv, trial, "clip", 404,
               fmt::format("clip: the clip of trial index {} is missing", trial));
    return {file.string(), contentTypeOf(file), fs::file_size(file, ec)};
}

} // namespace underfoot::web
