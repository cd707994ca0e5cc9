// SPDX-License-Identifier: GPL-3.0-or-later
// What a participant receives online never names the design: every shipped protocol that runs
// online is taken from consent to the completion code (every group), and every API reply is
// searched for the experimenter's notes, group names, clip file names, seeds, and (outside the
// question texts and answer lists the protocol shows in every trial alike) the current
// stimulus's id, surface and soundscape, i.e. the correct answer. The headphone check is done
// as a listener does it (tones, then a choice): no reply names its seed or which interval is
// quiet or in antiphase, and its tones' headers are the same for every triplet. The scanner is
// first shown to find a planted leak, so the test can fail.
#include "WebTestSupport.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <set>

namespace underfoot::web::test {
namespace {

using experiment::Protocol;

/// Whether `word` occurs in `text` as a whole token (not inside a longer identifier).
bool hasToken(const std::string& text, const std::string& word) {
    if (word.empty()) return false;
    const auto ident = [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    };
    for (auto at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
        const bool before = at > 0 && ident(text[at - 1]);
        const bool after = at + word.size() < text.size() && ident(text[at + word.size()]);
        if (!before && !after) return true;
    }
    return false;
}

/// A reply without what the protocol itself shows every participant in every trial alike (the
/// titles, briefing, field labels, question prompts, answer lists and scale anchors).
json withoutQuestionTexts(json j) {
    if (!j.is_object()) return j;
    if (j.contains("study")) j.erase("study");
    if (j.contains("fields")) j.erase("fields");
    if (j.contains("trial") && j["trial"].is_object())
        for (const char* k : {"surface", "soundscape", "scales"}) j["trial"].erase(k);
    return j;
}

/// Keys that would tell the headphone check's answer (its layout or its scoring).
const std::set<std::string> kCheckKeys{"quiet",   "antiphase", "layout",  "correct",
                                       "choices", "seed",      "passMark"};

/// The first key of `j` (at any depth) that is one of kCheckKeys, or "".
std::string checkKey(const json& j) {
    if (j.is_object())
        for (const auto& [k, v] : j.items()) {
            if (kCheckKeys.count(k)) return k;
            if (std::string inner = checkKey(v); !inner.empty()) return inner;
        }
    if (j.is_array())
        for (const auto& v : j)
            if (std::string inner = checkKey(v); !inner.empty()) return inner;
    return "";
}

struct Leak {
    std::string what;
    std::string reply;
};

/// Everything a reply must not contain, given the protocol and the participant's stored trials.
class Scanner {
  public:
    Scanner(const Protocol& p, const std::string& clipsDir) : protocol_(p) {
        if (!p.notes.empty()) everywhere_.emplace_back("notes", p.notes);
        for (const auto& s : p.stimuli) {
            everywhere_.emplace_back("clip file name",
                                     fs::path(experiment::clipPath(s, clipsDir)).filename());
            everywhere_.emplace_back("clip seed", std::to_string(experiment::clipSeed(p, s)));
        }
        if (p.groups.size() > 1)
            for (const auto& g : p.groups) tokens_.emplace_back("group name", g.id);
    }
    void setTrials(std::vector<experiment::TrialRecord> trials) {
        trials_ = std::move(trials);
        for (const auto& t : trials_) {
            everywhere_.emplace_back("planned seed", std::to_string(t.plannedSeed));
            if (t.renderSeed)
                everywhere_.emplace_back("render seed", std::to_string(*t.renderSeed));
        }
    }
    /// The headphone check's seed (known once the verdict is stored).
    void setCheckSeed(std::uint64_t seed) {
        everywhere_.emplace_back("headphone check seed", std::to_string(seed));
    }
    /// Leaks in one reply.
    std::vector<Leak> scan(const std::string& raw) const {
        std::vector<Leak> out;
        for (const auto& [what, text] : everywhere_)
            if (raw.find(text) != std::string::npos) out.push_back({what + " '" + text + "'", raw});
        // The body, then the headers one a line (searched above only: a header such as the
        // content security policy's 'none' is the server's, not the study's).
        const std::string body = raw.substr(0, raw.find('\n'));
        const json j = json::parse(body, nullptr, false);
        const std::string rest = j.is_discarded() ? body : withoutQuestionTexts(j).dump();
        if (!j.is_discarded())
            if (const std::string k = checkKey(j); !k.empty())
                out.push_back({"headphone check key '" + k + "'", raw});
        for (const auto& [what, token] : tokens_)
            if (hasToken(rest, token)) out.push_back({what + " '" + token + "'", raw});
        if (!j.is_discarded() && j.contains("trial") && j["trial"].contains("index")) {
            const int index = j["trial"]["index"].get<int>();
            for (const auto& t : trials_) {
                if (t.index != index) continue;
                const auto& s = t.stimulus;
                if (hasToken(rest, s.id)) out.push_back({"stimulus id '" + s.id + "'", raw});
                if (hasToken(rest, s.surface))
                    out.push_back({"surface (correct answer) '" + s.surface + "'", raw});
                if (s.soundscape && hasToken(rest, *s.soundscape))
                    out.push_back({"soundscape '" + *s.soundscape + "'", raw});
                if (s.clip && rest.find(*s.clip) != std::string::npos)
                    out.push_back({"clip '" + *s.clip + "'", raw});
            }
            // The answer lists are the protocol's, the same for every trial.
            const json& trial = j["trial"];
            if (trial.contains("surface")) {
                EXPECT_EQ(trial["surface"]["options"].size(),
                          protocol_.questions.surfaceOptions.size());
            }
        }
        return out;
    }

  private:
    const Protocol& protocol_;
    std::vector<std::pair<std::string, std::string>> everywhere_;
    std::vector<std::pair<std::string, std::string>> tokens_;
    std::vector<experiment::TrialRecord> trials_;
};

/// Every reply a participant gets from consent to the end (first 400 requests at most).
std::vector<std::string> runParticipant(const ApiClient& c, const Protocol& p) {
    std::vector<std::string> replies;
    const auto keep = [&](const Reply& r) {
        EXPECT_EQ(r.status, 200) << r.raw;
        replies.push_back(r.raw);
        for (const auto& [name, value] : r.headers) replies.back() += "\n" + name + ": " + value;
        return r.body;
    };
    keep(c.get("/api/state"));
    json fields = json::object();
    for (const auto& f : p.participantFields)
        fields[f.id] = f.options.empty() ? std::string("x") : f.options.front();
    keep(c.post("/api/consent", {{"consent", true}, {"fields", fields}}));
    keep(c.post("/api/client", {{"sampleRate", 48000}}));
    // The headphone check as a listener with headphones does it. The tones' headers (but the
    // date) must be the same for every triplet: nothing in them depends on the layout.
    json state = keep(c.post("/api/screening/start", json::object()));
    std::set<std::string> toneHeaders;
    for (int n = 0; n < 12 && state.value("phase", "") == "screening"; ++n) {
        const int k = state.at("check").at("next");
        const Reply tones = c.get("/api/screening/tones/" + std::to_string(k));
        EXPECT_EQ(tones.status, 200) << tones.raw.substr(0, 200);
        std::string headers;
        for (const auto& [name, value] : tones.headers)
            if (name != "Date") headers += name + ": " + value + "\n";
        toneHeaders.insert(headers);
        replies.push_back(headers);
        state =
            keep(c.post("/api/screening", {{"triplet", k}, {"choice", quietestHeard(tones.raw)}}));
    }
    EXPECT_EQ(toneHeaders.size(), 1u);
    EXPECT_EQ(state.at("screening").at("passed"), true);
    for (int n = 0; n < 400 && state.value("phase", "") != "finished"; ++n) {
        if (state.value("phase", "") == "break") {
            state = keep(c.post("/api/break", json::object()));
            continue;
        }
        if (!state.contains("trial")) {
            ADD_FAILURE() << "unexpected state " << state.dump();
            break;
        }
        const json& t = state["trial"];
        const int index = t["index"].get<int>();
        keep(c.post("/api/present", {{"trial", index}, {"attempt", "p" + std::to_string(n)}}));
        const Reply clip = c.get("/api/clip/" + std::to_string(index));
        EXPECT_EQ(clip.status, 200);
        std::string clipHeaders;
        for (const auto& [name, value] : clip.headers) clipHeaders += name + ": " + value + "\n";
        replies.push_back(clipHeaders);
        json a{{"trial", index}, {"attempt", "a" + std::to_string(n)}};
        if (t.contains("surface")) a["answer"] = t["surface"]["options"][0]["id"];
        if (t.contains("soundscape")) a["soundscape"] = t["soundscape"]["options"][0]["id"];
        json ratings = json::object();
        for (const auto& s : t["scales"]) ratings[s["id"].get<std::string>()] = s["min"];
        a["ratings"] = ratings;
        state = keep(c.post("/api/answer", a));
    }
    EXPECT_EQ(state.value("phase", ""), "finished");
    return replies;
}

TEST(WebLeaks, ScannerFindsAPlantedLeak) {
    const Protocol p = experiment::parseProtocol(webProtocol(), "web.toml");
    Scanner scan(p, "/clips");
    experiment::TrialRecord t;
    t.index = 2;
    t.stimulus = p.stimuli[1]; // GL, gravel
    t.plannedSeed = 1234567890123ULL;
    scan.setTrials({t});
    EXPECT_TRUE(scan.scan(R"({"trial":{"index":2,"text":"Please answer."}})").empty());
    EXPECT_FALSE(scan.scan(R"({"trial":{"index":2,"text":"gravel"}})").empty());
    EXPECT_FALSE(scan.scan(R"({"trial":{"index":2,"id":"GL"}})").empty());
    EXPECT_FALSE(scan.scan(R"({"seed":1234567890123})").empty());
    EXPECT_FALSE(scan.scan(R"({"x":"Listen & identify <script>alert(1)</script>."})").empty());
    EXPECT_TRUE(scan.scan(R"({"phase":"screening","check":{"triplets":6,"next":2}})").empty());
    EXPECT_FALSE(scan.scan(R"({"phase":"screening","check":{"next":2,"quiet":3}})").empty());
    scan.setCheckSeed(987654321987ULL);
    EXPECT_FALSE(scan.scan(R"({"phase":"screening","n":987654321987})").empty());
}

TEST(WebLeaks, NoShippedProtocolShowsTheDesignToAParticipant) {
    int protocols = 0, participants = 0, searched = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(UNDERFOOT_SOURCE_DIR) / "protocols")) {
        if (entry.path().extension() != ".toml") continue;
        Protocol p;
        try {
            p = experiment::loadProtocol(entry.path().string());
            checkOnlineProtocol(p);
        } catch (const std::exception&) {
            continue; // not an online protocol (laps, no [clips]): WebApi tests its refusal
        }
        SCOPED_TRACE(entry.path().filename().string());
        ++protocols;
        const int people = static_cast<int>(std::max<std::size_t>(p.groups.size(), 1));
        StudyFixture f(people, p);
        ServerOptions fast;
        fast.ratePerSecond = 1000; // one participant as fast as the loopback goes
        fast.burst = 1000;
        InProcessServer server(f, fast);
        for (const auto& link : f.links) {
            const ApiClient c(server.port, link.token);
            const auto replies = runParticipant(c, p);
            ++participants;
            searched += static_cast<int>(replies.size());
            Scanner scan(p, f.clips);
            {
                experiment::StudyStore store = experiment::StudyStore::open(f.study);
                scan.setTrials(store.trials(link.participantCode));
                const json detail = json::parse(
                    experiment::Invitations(store).byCode(link.participantCode).screeningDetail);
                scan.setCheckSeed(detail.at("seed").get<std::uint64_t>());
            }
            int leaks = 0;
            for (const auto& r : replies)
                for (const auto& leak : scan.scan(r))
                    if (++leaks <= 5) ADD_FAILURE() << leak.what << " in " << leak.reply;
            EXPECT_EQ(leaks, 0) << link.participantCode << ": " << replies.size() << " replies";
        }
    }
    std::printf("[ leaks    ] %d shipped protocols online, %d participants, %d replies searched\n",
                protocols, participants, searched);
    EXPECT_GE(protocols, 2) << "shipped protocols that run online";
}

} // namespace
} // namespace underfoot::web::test
