// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/WebStudy.h"
#include "base/Version.h"

#include "experiment/TrialFlow.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

namespace underfoot::web {

using namespace underfoot::experiment;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

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
    try {
        player_ = std::make_unique<ClipPlayer>(store_.protocol(), options_.clipsDir);
    } catch (const StoreError& e) {
        throw std::runtime_error(
            fmt::format("{}: the clips cannot be served:\n{}", options_.clipsDir, e.what()));
    }
    invitations_ = std::make_unique<Invitations>(store_);
}

WebStudy::~WebStudy() {
    stop();
}

void WebStudy::stop() {
    std::lock_guard lock(mutex_);
    flows_.clear();
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

bool WebStudy::isInvitation(const std::string& token) const {
    std::lock_guard lock(mutex_);
    return invitations_->find(token).has_value();
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
            store_.journal(JournalEvent::OnlineRefused, inv.participantCode, trial, detail);
        } catch (const StoreError&) {
            store_.journal(JournalEvent::OnlineRefused, "", trial, detail); // not registered yet
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
        close(code);
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
    // The server is the study's only online writer: a lease of another host name (a re-created
    // container) is taken over, journaled; dead holders and reused PIDs always are.
    settings.takeOverForeign = true;
    std::unique_ptr<Session> s;
    try {
        s = std::make_unique<Session>(store_, code, *player_, settings);
    } catch (const StoreError& e) {
        // Finished means every trial answered, and nothing else: any other failure (a live
        // lease holder, a busy or failing store) is retryable and never shows the end page.
        if (!store_.firstUnanswered(code)) return nullptr; // marked completed by the session
        try {
            store_.journal(JournalEvent::OnlineUnavailable, code, std::nullopt,
                           jsonObject({{"participant", code}, {"reason", e.what()}}));
        } catch (const std::exception&) {
        }
        throw ApiError(503,
                       dynamic_cast<const LeaseHeld*>(&e)
                           ? "your session is still held by the previous server process; please "
                             "wait a moment, it resumes where you left off"
                           : "your session cannot be opened just now; please wait a moment",
                       5);
    }
    // Consent is the briefing: a participant who consented goes straight to the trials.
    if (s->phase() == SessionPhase::Briefing) s->finishBriefing();
    Session* raw = s.get();
    flows_[code] = std::make_unique<TrialFlow>(store_, *raw);
    sessions_[code] = std::move(s);
    return raw;
}

TrialFlow* WebStudy::flow(const std::string& code) {
    const auto it = flows_.find(code);
    return it == flows_.end() ? nullptr : it->second.get();
}

void WebStudy::close(const std::string& code) {
    flows_.erase(code);
    sessions_.erase(code);
}

json WebStudy::trialJson(const TrialFlow& flow) const {
    const ParticipantScreen screen = flow.participantScreen();
    const Session& s = flow.session();
    const TrialRecord& t = s.current();
    json j;
    j["index"] = t.index;
    j["practice"] = t.practice;
    j["heading"] = screen.heading;
    j["text"] = screen.text;
    j["presented"] = s.playing();
    j["replays"] = t.replays;
    j["replayAllowed"] = flow.protocol().clips.replay;
    json scales = json::array();
    for (const AnswerSection& section : screen.sections) {
        switch (section.kind) {
        case SectionKind::Surface:
            j["surface"] = {
                {"prompt", section.prompt.empty() ? "Which surface is it?" : section.prompt},
                {"options", optionsJson(section.options)}};
            break;
        case SectionKind::Soundscape:
            if (section.options.empty()) break;
            j["soundscape"] = {
                {"prompt", section.prompt.empty() ? "Which environment is it?" : section.prompt},
                {"options", optionsJson(section.options)}};
            break;
        case SectionKind::Scale: {
            const Scale& sc = *section.scale;
            json anchors = json::array();
            for (const auto& [v, label] : sc.anchors)
                anchors.push_back({{"value", v}, {"label", label}});
            scales.push_back({{"id", sc.id},
                              {"prompt", section.prompt},
                              {"min", sc.min},
                              {"max", sc.max},
                              {"minLabel", sc.minLabel},
                              {"maxLabel", sc.maxLabel},
                              {"anchors", anchors}});
            break;
        }
        }
    }
    j["scales"] = scales;
    j["comment"] = flow.protocol().questions.comment;
    return j;
}

json WebStudy::stateOf(const Invitation& inv) {
    const Protocol& protocol = store_.protocol();
    json j;
    j["participant"] = inv.participantCode;
    // What participants may read about the study: never its title or notes, which may name the
    // design (groups, conditions), only the participant-facing title and briefing.
    j["study"] = {{"title", participantTitle(protocol)}, {"briefing", consentBriefing(protocol)}};
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
        // session() returns null for a registered, not dropped participant only when every
        // trial is answered; checked again here so that nothing else can show the end page.
        const auto trials = store_.trials(p->code);
        const auto answered =
            std::count_if(trials.begin(), trials.end(), [](const auto& t) { return t.answered; });
        if (answered != static_cast<std::ptrdiff_t>(trials.size()))
            throw ApiError(503, "your session cannot be opened just now; please wait a moment", 5);
        j["progress"] = {{"answered", answered}, {"total", trials.size()}};
        j["phase"] = "finished";
        j["completionCode"] = inv.completionCode;
        return j;
    }
    j["progress"] = {{"answered", s->answeredCount()}, {"total", s->trialCount()}};
    if (!inv.screeningPassed) {
        j["phase"] = "screening";
        // Progress only: which interval is the quiet one is never sent.
        const auto it = checks_.find(inv.participantCode);
        const HeadphoneCheck* c = it == checks_.end() ? nullptr : it->second.check.get();
        j["check"] = {{"triplets", HeadphoneCheck::kTriplets},
                      {"started", c != nullptr},
                      {"next", c ? c->next() : 0}};
        return j;
    }
    switch (s->phase()) {
    case SessionPhase::Break:
        j["phase"] = "break";
        break;
    case SessionPhase::Practice:
    case SessionPhase::Trial:
        j["phase"] = s->phase() == SessionPhase::Practice ? "practice" : "trial";
        j["trial"] = trialJson(*flow(inv.participantCode));
        break;
    case SessionPhase::Finished:
        j["phase"] = "finished";
        j["completionCode"] = inv.completionCode;
        break;
    default:
        throw ApiError(503, "your session cannot be opened just now; please wait a moment", 5);
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

HeadphoneCheck* WebStudy::check(const Invitation& inv) {
    auto& entry = checks_[inv.participantCode];
    if (entry.check) return entry.check.get();
    // After a restart: the last check started in the journal, with the answers given since.
    std::optional<std::uint64_t> seed;
    std::vector<std::pair<int, int>> answers;
    for (const Event& e : store_.events()) {
        if (e.participant != inv.participantCode) continue;
        if (e.event == JournalEvent::OnlineScreeningStarted) {
            const json d = json::parse(e.detail, nullptr, false);
            if (!d.is_object() || !d.contains("seed") || !d["seed"].is_number_unsigned()) continue;
            seed = d["seed"].get<std::uint64_t>();
            answers.clear();
        } else if (e.event == JournalEvent::OnlineScreeningAnswer && seed) {
            const json d = json::parse(e.detail, nullptr, false);
            if (d.is_object() && d.value("triplet", -1) >= 0)
                answers.emplace_back(d.value("triplet", -1), d.value("choice", 0));
        }
    }
    if (!seed) {
        checks_.erase(inv.participantCode);
        return nullptr;
    }
    entry.check = std::make_unique<HeadphoneCheck>(*seed, options_.screeningMinResponseS);
    // Replayed as stored (their timing was checked when they were given).
    for (const auto& [triplet, choice] : answers)
        (void)entry.check->answer(triplet, choice, std::numeric_limits<double>::infinity());
    return entry.check.get();
}

json WebStudy::screeningStart(const std::string& token, const json&) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    if (!s)
        refuse(inv, std::nullopt, "screening/start", 409, "screening/start: no running session");
    if (inv.screeningPassed) return stateOf(inv); // screened already: the first verdict counts
    if (!check(inv)) {
        // 53 bits: exact in every JSON reader of the journal.
        std::random_device rd;
        const std::uint64_t seed =
            ((std::uint64_t{rd()} << 32) ^ std::uint64_t{rd()}) & ((std::uint64_t{1} << 53) - 1);
        auto& entry = checks_[inv.participantCode];
        entry.check = std::make_unique<HeadphoneCheck>(seed, options_.screeningMinResponseS);
        entry.served.reset();
        store_.journal(JournalEvent::OnlineScreeningStarted, inv.participantCode, std::nullopt,
                       json({{"test", "woods2017_antiphase"},
                             {"seed", seed},
                             {"triplets", HeadphoneCheck::kTriplets},
                             {"passMark", HeadphoneCheck::kPassMark},
                             {"minResponseS", options_.screeningMinResponseS}})
                           .dump());
    }
    return stateOf(inv);
}

std::string WebStudy::screeningTones(const std::string& token, int index) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    const std::string request = fmt::format("screening/tones/{}", index);
    if (inv.screeningPassed)
        refuse(inv, std::nullopt, request, 409, request + ": the headphone check is over");
    HeadphoneCheck* c = check(inv);
    if (!c)
        refuse(inv, std::nullopt, request, 409,
               request + ": the headphone check has not started (POST /api/screening/start)");
    if (index != c->next())
        refuse(inv, std::nullopt, request, 409,
               fmt::format("{}: refused; the triplet waiting for an answer is {}", request,
                           c->next()));
    auto& served = checks_[inv.participantCode].served;
    if (!served) served = std::chrono::steady_clock::now(); // a refetch does not restart it
    return HeadphoneCheck::wav(c->triplets()[static_cast<std::size_t>(index)]);
}

json WebStudy::screening(const std::string& token, const json& body) {
    std::lock_guard lock(mutex_);
    const Invitation inv = invitation(token);
    Session* s = session(inv);
    if (!s) refuse(inv, std::nullopt, "screening", 409, "screening: no running session");
    if (inv.screeningPassed)
        return stateOf(inv); // already screened (a retry or a reload): the first result counts
    const auto triplet = member<int>(body, "triplet", "screening");
    const auto choice = member<int>(body, "choice", "screening");
    if (!triplet || !choice)
        refuse(inv, std::nullopt, "screening", 400,
               "screening: expected integers 'triplet' (the check's triplet) and 'choice' (1, 2 "
               "or 3: the quietest sound); the server scores the check");
    HeadphoneCheck* c = check(inv);
    if (!c)
        refuse(inv, std::nullopt, "screening", 409,
               "screening: the headphone check has not started (POST /api/screening/start)");
    auto& entry = checks_[inv.participantCode];
    std::optional<double> since;
    if (entry.served)
        since =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - *entry.served).count();
    if (const auto problem = c->answer(*triplet, *choice, since))
        refuse(inv, std::nullopt, "screening", *choice < 1 || *choice > 3 ? 400 : 409,
               "screening: " + *problem);
    entry.served.reset();
    const auto k = static_cast<std::size_t>(*triplet);
    store_.journal(JournalEvent::OnlineScreeningAnswer, inv.participantCode, std::nullopt,
                   json({{"triplet", *triplet},
                         {"choice", *choice},
                         {"correct", *choice - 1 == c->triplets()[k].quiet},
                         {"secondsSinceTones", *since}})
                       .dump());
    if (!c->done()) return stateOf(inv);
    const bool passed = c->passed();
    json layout = json::array();
    for (const auto& t : c->triplets())
        layout.push_back({{"quiet", t.quiet + 1}, {"antiphase", t.antiphase + 1}});
    const std::string detail = json({{"test", "woods2017_antiphase"},
                                     {"seed", c->seed()},
                                     {"layout", layout},
                                     {"choices", c->choices()},
                                     {"correct", c->correct()},
                                     {"total", HeadphoneCheck::kTriplets},
                                     {"passMark", HeadphoneCheck::kPassMark}})
                                   .dump();
    invitations_->recordScreening(inv.id, passed, detail);
    store_.journal(passed ? JournalEvent::OnlineScreeningPassed
                          : JournalEvent::OnlineScreeningFailed,
                   inv.participantCode, std::nullopt, detail);
    checks_.erase(inv.participantCode);
    if (!passed && options_.screeningFailure == ScreeningFailure::End) {
        s->interrupt();
        close(inv.participantCode);
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
        // The flow plays the clip the first time and counts (and stores) each replay after.
        if (const FlowResult r = flow(inv.participantCode)->start(); !r)
            refuse(inv, trial, "present", r.refusal == Refusal::Failed ? 503 : 409,
                   fmt::format("present: {}", r.message));
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
    const std::string answer = member<std::string>(body, "answer", request).value_or("");
    const std::string soundscape = member<std::string>(body, "soundscape", request).value_or("");
    const std::string comment = member<std::string>(body, "comment", request).value_or("");
    if (answer.size() > options_.maxText || soundscape.size() > options_.maxText ||
        comment.size() > options_.maxText)
        refuse(inv, trial, request, 400,
               fmt::format("answer: texts are limited to {} characters", options_.maxText));
    if (!store_.protocol().questions.comment && !comment.empty())
        refuse(inv, trial, request, 422, "answer: this protocol asks no comment");
    const auto clientMs = member<double>(body, "clientMs", request);
    if (clientMs && (*clientMs < 0 || *clientMs > 86400000.0))
        refuse(inv, trial, request, 400, "answer: 'clientMs' must be 0 to 86400000 ms");
    if (!s->playing() && t.startedAt.empty())
        refuse(inv, trial, request, 409,
               fmt::format("answer: trial index {} was not presented yet; play the clip first",
                           trial));
    // The page's answer goes into the participant's trial flow, which validates it (options of
    // the questions asked, ratings of the scales asked, on their range) and commits it.
    TrialFlow& f = *flow(inv.participantCode);
    f.reset();
    // Presented before a server restart: the presentation is restored (journaled as a restart
    // of the trial by the store), then the answer is committed.
    if (!s->playing())
        if (const FlowResult r = f.start(); !r)
            refuse(inv, trial, request, 409, "answer: " + r.message);
    const auto chooseId = [&](SectionKind kind, const std::string& id, const char* what) {
        if (id.empty()) return;
        for (const AnswerSection& section : f.sections()) {
            if (section.kind != kind) continue;
            for (const AnswerOption& o : section.options)
                if (o.id == id) {
                    if (const FlowResult r = f.choose(kind, o.letter); !r)
                        refuse(inv, trial, request, 422, "answer: " + r.message);
                    return;
                }
        }
        refuse(inv, trial, request, 422,
               fmt::format("answer: {} '{}' is not one of the options of this trial", what, id));
    };
    chooseId(SectionKind::Surface, answer, "answer");
    chooseId(SectionKind::Soundscape, soundscape, "soundscape");
    if (const auto r = body.find("ratings"); r != body.end() && !r->is_null()) {
        if (!r->is_object() || r->size() > 64)
            refuse(inv, trial, request, 400,
                   "answer: 'ratings' must be an object scale -> integer");
        for (const auto& [k, v] : r->items()) {
            if (!v.is_number_integer())
                refuse(inv, trial, request, 422,
                       fmt::format("answer: rating '{}' must be an integer on its scale", k));
            if (const FlowResult res = f.setRating(k, v.get<int>()); !res)
                refuse(inv, trial, request, 422,
                       fmt::format("answer: rating '{}': {}", k, res.message));
        }
    }
    f.setComment(comment);
    if (const auto problems = f.problems(); !problems.empty()) {
        std::string all;
        for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
        refuse(inv, trial, request, 422, "answer: " + all);
    }
    invitations_->recordAttempt(inv.id, trial, *attempt, clientMs);
    if (const FlowResult r = f.commit(); !r)
        refuse(inv, trial, request, 422, "answer: " + r.message);
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
    if (s && s->phase() == SessionPhase::Break) {
        s->finishBreak();
        flow(inv.participantCode)->reset(); // the next trial's questions
    }
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
    // Only the file the manifest describes (and the trial stores): a replaced file, or a hard
    // link to another file put in its place, is refused.
    const ClipRecord* record = player_->record(stimulus.id);
    std::string hash;
    try {
        hash = fileSha256(file.string());
    } catch (const std::exception&) {
    }
    if (!stimulus.clip && (!record || hash != record->sha256))
        refuse(inv, trial, "clip", 409,
               fmt::format("clip: the clip of trial index {} does not match the clip manifest; "
                           "the experimenter must render the clips again",
                           trial));
    if (stimulus.clip && record && hash != record->sha256)
        refuse(inv, trial, "clip", 409,
               fmt::format("clip: the clip of trial index {} changed since it was recorded in "
                           "the clip manifest",
                           trial));
    return {file.string(), contentTypeOf(file), fs::file_size(file, ec)};
}

} // namespace underfoot::web
