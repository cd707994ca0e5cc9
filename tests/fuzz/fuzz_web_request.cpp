// SPDX-License-Identifier: GPL-3.0-or-later
// HTTP requests and answer payloads of `underfoot serve` (app/web/Api.h: WebApi::handle, which
// applies the framing rules, limits and token check, routes and validates every request and
// drives WebStudy), in process and without a socket. An input is a sequence of up to 16
// requests separated by lines "%%":
//
//     POST /api/answer HTTP/1.1
//     Authorization: Bearer @TOKEN0@
//
//     {"trial": 0, "attempt": "a1", "answer": "wood", "ratings": {"realism": 7}}
//
// (request line, header lines, an empty line, the body). @TOKEN0@ and @TOKEN1@ stand for the
// link tokens of the two invited participants (random per run). The request target goes
// through decodeTargetPath (app/web/Limits.h) as in the server; the peer is 127.0.0.1, a
// trusted proxy, so X-Forwarded-For headers are read. The HTTP syntax itself is Boost.Beast's
// and not fuzzed here; everything our code does with any method, target, header and body is.
// Each input starts from the same fresh study (a copy of a template), so a finding replays
// alone. Every answer must be one of the documented statuses with a JSON object body (an
// "error" message on refusals); 500 (an unexpected exception) is a finding; a clip is always a
// file inside the clips folder.
#include "FuzzSupport.h"
#include "app/web/Api.h"
#include "app/web/Limits.h"
#include "app/web/WebStudy.h"
#include "experiment/Clips.h"
#include "experiment/Invitations.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"

#include <nlohmann/json.hpp>

#include <set>

namespace {

using namespace underfoot;
namespace fs = std::filesystem;

struct Template {
    std::string study, clips, work;
    std::vector<std::string> tokens;
};

const char* kProtocol = R"([protocol]
id = "web_ident"
version = 1
title = "Web identification"
[design]
type = "within"
[input]
type = "walker"
[clips]
seconds = 1
seed = 7
replay = true
[[stimuli]]
id = "WD"
surface = "wood"
[[stimuli]]
id = "GL"
surface = "gravel"
[ordering]
repetitions = 2
practice = ["WD"]
break_every = 2
[questions]
comment = true
[questions.surface]
prompt = "Which surface?"
options = ["wood", "gravel"]
[[questions.scales]]
id = "realism"
prompt = "How realistic?"
min = 1
max = 7
[[participant_fields]]
id = "listening_device"
label = "Listening device"
options = ["laptop_speakers", "headphones"]
)";

Template& templ() {
    static Template t = [] {
        Template t;
        const fs::path dir = fuzz::scratchDir();
        t.study = (dir / "template.db").string();
        t.clips = (dir / "clips").string();
        t.work = (dir / "work.db").string();
        const experiment::Protocol p = experiment::parseProtocol(kProtocol, "web.toml");
        {
            experiment::StudyStore store =
                experiment::StudyStore::create(t.study, p, {"WEB", "web", 4, "fuzz"});
            experiment::Invitations inv(store);
            const auto links = inv.create(store, 2, std::nullopt);
            for (const auto& link : links) t.tokens.push_back(link.token);
            // The first participant has passed the headphone check (its layout is the server's
            // secret, so an input could not pass it): the trials are reachable after consent.
            // The second one takes the check (corpus failed_screening).
            inv.recordScreening(inv.byCode(links[0].participantCode).id, true,
                                R"({"test": "passed in the fuzz template"})");
        }
        fs::create_directories(t.clips);
        // WebStudy checks that each clip exists and is the manifest's (its SHA-256); the
        // samples are not read here, so a stand-in file with its manifest row will do.
        std::vector<experiment::ClipRecord> records;
        for (const auto& job : experiment::clipJobs(p, t.clips)) {
            {
                std::ofstream out(job.path, std::ios::binary);
                out << "RIFF";
            }
            experiment::ClipRecord r;
            r.stimulusId = job.stimulus.id;
            r.file = fs::path(job.path).filename().string();
            r.source = job.source;
            r.seed = job.seed;
            r.seconds = job.seconds;
            r.sampleRateHz = 48000.0;
            r.frames = static_cast<std::size_t>(job.seconds * 48000.0);
            r.sha256 = experiment::fileSha256(job.path);
            records.push_back(r);
        }
        experiment::writeClipManifest(t.clips, records);
        return t;
    }();
    return t;
}

std::vector<std::string> splitRequests(const std::string& input) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (out.size() < 16) {
        const std::size_t sep = input.find("\n%%\n", start);
        out.push_back(
            input.substr(start, sep == std::string::npos ? std::string::npos : sep - start));
        if (sep == std::string::npos) break;
        start = sep + 4;
    }
    return out;
}

void replaceAll(std::string& s, const std::string& from, const std::string& to) {
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
        s.replace(at, from.size(), to);
}

/// The request in `text`, or nullopt when its target is not a path (the server answers 400).
std::optional<web::HttpRequest> parseRequest(std::string text, const Template& t) {
    for (std::size_t i = 0; i < t.tokens.size(); ++i)
        replaceAll(text, "@TOKEN" + std::to_string(i) + "@", t.tokens[i]);
    web::HttpRequest r;
    r.remoteAddr = "127.0.0.1";
    std::size_t pos = 0;
    auto line = [&]() -> std::optional<std::string> {
        if (pos >= text.size()) return std::nullopt;
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string l = text.substr(pos, end - pos);
        pos = end + 1;
        if (!l.empty() && l.back() == '\r') l.pop_back();
        return l;
    };
    const std::string first = line().value_or("");
    const std::size_t sp = first.find(' ');
    r.method = first.substr(0, sp);
    if (sp == std::string::npos) return std::nullopt;
    std::string target = first.substr(sp + 1);
    const auto path = web::decodeTargetPath(target.substr(0, target.find(' ')));
    if (!path) return std::nullopt;
    r.path = *path;
    while (const auto l = line()) {
        if (l->empty()) break;
        const std::size_t colon = l->find(':');
        if (colon == std::string::npos) continue;
        std::string value = l->substr(colon + 1);
        value.erase(0, value.find_first_not_of(' ') == std::string::npos
                           ? value.size()
                           : value.find_first_not_of(' '));
        r.headers.emplace(l->substr(0, colon), value);
    }
    if (pos < text.size()) r.body = text.substr(pos);
    return r;
}

void check(const web::HttpRequest& req, const web::HttpAnswer& a, const Template& t) {
    static const std::set<int> documented{200, 400, 403, 404, 409, 413, 422, 429, 431, 503};
    const std::string what = req.method + " " + req.path;
    if (a.status == 500) fuzz::fail(what + ": 500 (an unexpected exception): " + a.body);
    if (!documented.count(a.status))
        fuzz::fail(what + ": undocumented status " + std::to_string(a.status));
    if (a.clip) {
        const fs::path clip = fs::weakly_canonical(a.clip->path);
        const fs::path folder = fs::weakly_canonical(t.clips);
        if (clip.parent_path() != folder)
            fuzz::fail(what + ": a clip outside the clips folder: " + a.clip->path);
        return;
    }
    if (a.contentType.rfind("application/json", 0) != 0) return; // the page and its assets
    const auto body = nlohmann::json::parse(a.body, nullptr, false);
    if (body.is_discarded() || !body.is_object()) fuzz::fail(what + ": the answer is not JSON");
    if (a.status != 200 && !(body.contains("error") && body["error"].is_string()))
        fuzz::fail(what + ": a refusal without an error message: " + a.body);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const Template& t = templ();
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(t.work + suffix, ec);
    fuzz::copyFile(t.study, t.work);
    web::WebOptions wo;
    wo.clipsDir = t.clips;
    wo.screeningMinResponseS = 0.0; // the check's choices are reachable without waiting
    web::ServerOptions so;
    so.maxBodyBytes = 16 * 1024;
    so.ratePerSecond = 1e9; // the rate limit is tested by tests/web, not fuzzed
    so.burst = 1e9;
    so.trustedProxies = {"127.0.0.1"};
    web::WebStudy study(t.work, wo);
    web::WebApi api(study, so);
    const bool verbose = std::getenv("UNDERFOOT_FUZZ_VERBOSE") != nullptr;
    for (const std::string& text : splitRequests(fuzz::text(data, size))) {
        const auto parsed = parseRequest(text, t);
        if (!parsed) continue;
        const web::HttpRequest& req = *parsed;
        web::HttpAnswer a;
        try {
            a = api.handle(req);
        } catch (const std::exception& e) {
            fuzz::fail(std::string("WebApi::handle threw: ") + e.what());
        }
        if (verbose)
            std::fprintf(stderr, "%s %s -> %d %s\n", req.method.c_str(), req.path.c_str(), a.status,
                         a.clip ? a.clip->path.c_str() : a.body.substr(0, 300).c_str());
        check(req, a, t);
    }
    study.stop();
    return 0;
}
