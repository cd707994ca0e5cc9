// SPDX-License-Identifier: GPL-3.0-or-later
// The online API over loopback (an in-process server, the tests' Beast client): the whole flow,
// idempotent retries and every rule of docs/reference/web-server.md about what a request may
// do (bad token, another participant's trial, traversal, oversized body, invalid answers,
// out-of-range numbers, rate limits, HEAD), each refusal journaled.
#include "WebTestSupport.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <map>
#include <set>

namespace underfoot::web::test {
namespace {

using experiment::StudyStore;

/// Presents and answers the current trial; returns the reply.
Reply answerCurrent(const ApiClient& c, const json& state, const std::string& attempt) {
    const int trial = state["trial"]["index"];
    const Reply p = c.post("/api/present", {{"trial", trial}});
    EXPECT_EQ(p.status, 200) << p.raw;
    return c.post("/api/answer", validAnswer(state, attempt));
}

/// One participant of a study served in process, past consent and screening: `state` is their
/// first trial's, `t` its index.
struct AtFirstTrial {
    explicit AtFirstTrial(const std::string& protocol = webProtocol())
        : f(1, protocol), s(f), c(s.port, f.links[0].token), state(startParticipant(c)),
          t(state["trial"]["index"].get<int>()) {}
    int replaysStored() const {
        return StudyStore::open(f.study).trial(f.links[0].participantCode, t).replays;
    }
    StudyFixture f;
    InProcessServer s;
    ApiClient c;
    json state;
    int t;
};

int refusals(const std::string& study) {
    int n = 0;
    for (const auto& e : StudyStore::open(study).events()) n += e.kind == "online_refused";
    return n;
}

TEST(WebApi, ParticipantRunsFromConsentToCompletionCode) {
    StudyFixture f(2);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    Reply r = c.get("/api/state");
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body["phase"], "consent");
    EXPECT_EQ(r.body["fields"][0]["id"], "listening_device");
    // Participants read the participant-facing title and briefing, never the study's title or
    // the experimenter's notes (sent as data; the page shows them with textContent).
    EXPECT_EQ(r.body["study"]["title"], "Listening study");
    EXPECT_EQ(r.body["study"]["briefing"],
              "You will hear short sound clips and answer a few questions about each one.");
    EXPECT_EQ(r.raw.find("identification"), std::string::npos);
    json state = startParticipant(c);
    ASSERT_EQ(state["phase"], "practice") << state.dump();
    EXPECT_TRUE(state["trial"]["practice"]);
    EXPECT_EQ(state["trial"]["surface"]["options"].size(), 4u); // + I don't know
    EXPECT_EQ(state["trial"]["surface"]["options"][3]["id"], "dont_know");
    int answered = 0, breaks = 0;
    while (state["phase"] != "finished") {
        if (state["phase"] == "break") {
            ++breaks;
            state = c.post("/api/break", json::object()).body;
            continue;
        }
        ASSERT_TRUE(state["phase"] == "trial" || state["phase"] == "practice") << state.dump();
        const Reply clip = c.get("/api/clip/" + std::to_string(state["trial"]["index"].get<int>()));
        ASSERT_EQ(clip.status, 200);
        EXPECT_EQ(clip.raw.substr(0, 4), "RIFF");
        r = answerCurrent(c, state, "a" + std::to_string(answered));
        ASSERT_EQ(r.status, 200) << r.raw;
        EXPECT_EQ(r.body["stored"], true);
        EXPECT_EQ(r.body["duplicate"], false);
        state = r.body;
        ++answered;
    }
    EXPECT_EQ(answered, 7); // 1 practice + 3 stimuli x 2
    EXPECT_EQ(breaks, 1);
    const std::string code = state["completionCode"];
    EXPECT_EQ(code.size(), 10u);

    StudyStore store = StudyStore::open(f.study);
    const auto p = store.participant(f.links[0].participantCode);
    EXPECT_EQ(p.status, experiment::ParticipantStatus::Completed);
    EXPECT_EQ(p.fields.at("listening_device"), "headphones");
    for (const auto& t : store.trials(p.code)) {
        EXPECT_TRUE(t.answered) << t.index;
        EXPECT_EQ(t.answer.ratings.at("realism"), 7);
        EXPECT_TRUE(t.responseTimeS);
    }
    experiment::Invitations inv(store);
    const auto i = inv.byCode(p.code);
    EXPECT_EQ(i.completionCode, code);
    EXPECT_EQ(i.screeningPassed, true);
    const auto clients = inv.clients(i.id);
    ASSERT_EQ(clients.size(), 1u);
    EXPECT_EQ(clients[0].userAgent, "underfoot-web-test/1");
    EXPECT_EQ(clients[0].audioSampleRateHz, 48000.0);
    const auto a = inv.attempt(i.id, 0);
    ASSERT_TRUE(a);
    EXPECT_EQ(a->clientResponseTimeMs, 1234.5);
    // A finished participant's link shows the completion code again.
    EXPECT_EQ(c.get("/api/state").body["completionCode"], code);
}

TEST(WebApi, RetriedAnswerIsStoredOnceAndAcknowledgedAgain) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    json state = startParticipant(c);
    const json a = validAnswer(state, "attempt-1");
    ASSERT_EQ(c.post("/api/present", {{"trial", a["trial"]}}).status, 200);
    const Reply first = c.post("/api/answer", a);
    ASSERT_EQ(first.status, 200) << first.raw;
    const Reply again = c.post("/api/answer", a);
    ASSERT_EQ(again.status, 200) << again.raw;
    EXPECT_EQ(again.body["duplicate"], true);
    EXPECT_EQ(again.body["trial"]["index"], first.body["trial"]["index"]);
    // Another attempt at the answered trial is refused, not stored.
    json other = a;
    other["attempt"] = "attempt-2";
    other["ratings"]["realism"] = 1;
    EXPECT_EQ(c.post("/api/answer", other).status, 409);
    StudyStore store = StudyStore::open(f.study);
    int answered = 0, changed = 0;
    for (const auto& e : store.events()) {
        answered += e.kind == "answered";
        changed += e.kind == "answer_changed";
    }
    EXPECT_EQ(answered, 1);
    EXPECT_EQ(changed, 0);
    EXPECT_EQ(store.trial(f.links[0].participantCode, a["trial"]).answer.ratings.at("realism"), 7);
}

TEST(WebApi, BadTokensAreRefused) {
    StudyFixture f(1);
    InProcessServer s(f);
    for (const std::string& token :
         {std::string(), std::string("nonsense"), std::string(43, 'A'),
          f.links[0].token.substr(0, 42) + (f.links[0].token.back() == 'A' ? "B" : "A"),
          f.links[0].token + "x", std::string("../../etc/passwd")}) {
        ApiClient c(s.port, token);
        EXPECT_EQ(c.get("/api/state").status, 403) << token;
        EXPECT_EQ(c.post("/api/consent", {{"consent", true}}).status, 403) << token;
        EXPECT_EQ(c.get("/api/clip/0").status, 403) << token;
    }
    // Nothing was registered by a bad token.
    EXPECT_TRUE(StudyStore::open(f.study).participants().empty());
}

TEST(WebApi, AnotherParticipantsTrialAndUnpresentedTrialsAreRefusedAndJournaled) {
    StudyFixture f(2);
    InProcessServer s(f);
    ApiClient a(s.port, f.links[0].token), b(s.port, f.links[1].token);
    json sa = startParticipant(a);
    json sb = startParticipant(b);
    const int trialA = sa["trial"]["index"];
    // Answer to a trial not presented yet.
    Reply r = a.post("/api/answer", validAnswer(sa, "x1"));
    EXPECT_EQ(r.status, 409) << r.raw;
    EXPECT_NE(r.body["error"].get<std::string>().find("not presented"), std::string::npos);
    // B claims A's trial: refused (403) whatever the trial number.
    json claim = validAnswer(sb, "x2");
    claim["participant"] = f.links[0].participantCode;
    EXPECT_EQ(b.post("/api/answer", claim).status, 403);
    // A trial that is not the current one (a later trial, a trial that does not exist).
    ASSERT_EQ(a.post("/api/present", {{"trial", trialA}}).status, 200);
    json later = validAnswer(sa, "x3");
    later["trial"] = trialA + 2;
    EXPECT_EQ(a.post("/api/answer", later).status, 409);
    later["trial"] = 9999;
    EXPECT_EQ(a.post("/api/answer", later).status, 409);
    EXPECT_EQ(a.post("/api/present", {{"trial", trialA + 1}}).status, 409);
    EXPECT_EQ(a.get("/api/clip/" + std::to_string(trialA + 1)).status, 409);
    EXPECT_EQ(refusals(f.study), 6);
    // Still answerable.
    EXPECT_EQ(a.post("/api/answer", validAnswer(sa, "x4")).status, 200);
}

TEST(WebApi, InvalidAnswersAreRefusedAndJournaled) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    json state = startParticipant(c);
    ASSERT_EQ(c.post("/api/present", {{"trial", state["trial"]["index"]}}).status, 200);
    const json good = validAnswer(state, "g1");
    auto with = [&](const std::function<void(json&)>& change) {
        json a = good;
        change(a);
        return c.post("/api/answer", a);
    };
    EXPECT_EQ(with([](json& a) { a["answer"] = "snow"; }).status, 422);        // outside the list
    EXPECT_EQ(with([](json& a) { a["answer"] = ""; }).status, 422);            // missing
    EXPECT_EQ(with([](json& a) { a["ratings"]["realism"] = 8; }).status, 422); // outside 1-7
    EXPECT_EQ(with([](json& a) { a["ratings"]["realism"] = 0; }).status, 422);
    EXPECT_EQ(with([](json& a) { a["ratings"] = json::object(); }).status, 422);
    EXPECT_EQ(with([](json& a) { a["ratings"]["loudness"] = 3; }).status, 422); // not asked
    EXPECT_EQ(with([](json& a) { a["ratings"]["realism"] = 3.5; }).status, 422);
    EXPECT_EQ(with([](json& a) { a["ratings"]["realism"] = "7"; }).status, 422);
    EXPECT_EQ(with([](json& a) { a["comment"] = std::string(2001, 'x'); }).status, 400);
    EXPECT_EQ(with([](json& a) { a["clientMs"] = -1; }).status, 400);
    EXPECT_EQ(with([](json& a) { a["trial"] = "0"; }).status, 400);
    EXPECT_EQ(with([](json& a) { a["attempt"] = "bad id!"; }).status, 400);
    EXPECT_EQ(c.postRaw("/api/answer", "{not json").status, 400);
    EXPECT_EQ(c.postRaw("/api/answer", "[1,2]").status, 400);
    EXPECT_GE(refusals(f.study), 9);
    // Nothing of it was stored; the valid answer still is.
    StudyStore store = StudyStore::open(f.study);
    EXPECT_FALSE(store.trial(f.links[0].participantCode, good["trial"]).answered);
    EXPECT_EQ(c.post("/api/answer", good).status, 200);
    // Screening and consent are validated too.
    ApiClient fresh(s.port, f.links[0].token);
    EXPECT_EQ(fresh.post("/api/client", {{"sampleRate", -5}}).status, 400);
}

TEST(WebApi, OutOfRangeNumbersAreRefusedNotTruncated) {
    AtFirstTrial p;
    auto& [f, s, c, state, t] = p;
    ASSERT_EQ(c.post("/api/present", {{"trial", t}}).status, 200);
    const json good = validAnswer(state, "g1");
    constexpr std::int64_t two32 = std::int64_t{1} << 32;
    // 2^32 + t once became trial t, and 2^31 became -2147483648.
    for (const json& bad : {json(two32 + t), json(std::int64_t{1} << 31),
                            json(-(std::int64_t{1} << 31) - 1), json(~std::uint64_t{0})}) {
        json a = good;
        a["trial"] = bad;
        const Reply r = c.post("/api/answer", a);
        EXPECT_EQ(r.status, 400) << bad.dump() << " " << r.raw;
        EXPECT_NE(r.raw.find("out of range"), std::string::npos) << r.raw;
        EXPECT_EQ(c.post("/api/present", {{"trial", bad}}).status, 400) << bad.dump();
    }
    json rating = good;
    rating["ratings"]["realism"] = two32 + 7;
    EXPECT_EQ(c.post("/api/answer", rating).status, 400);
    // Numbers JSON cannot hold as doubles, and nesting deeper than 8 levels.
    EXPECT_EQ(c.postRaw("/api/answer", R"({"trial": 1e400})").status, 400);
    EXPECT_EQ(c.postRaw("/api/answer", R"({"x": [[[[[[[[[1]]]]]]]]]})").status, 400);
    EXPECT_EQ(c.get("/api/clip/4294967296").status, 404); // paths take at most 6 digits
    StudyStore store = StudyStore::open(f.study);
    EXPECT_FALSE(store.trial(f.links[0].participantCode, t).answered);
    EXPECT_EQ(c.post("/api/answer", good).status, 200);
}

TEST(WebApi, ConsentNeedsTheProtocolsRequiredFields) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    EXPECT_EQ(c.post("/api/consent", {{"consent", false}}).status, 400);
    EXPECT_EQ(c.post("/api/consent", {{"consent", true}}).status, 422);
    EXPECT_EQ(
        c.post("/api/consent", {{"consent", true}, {"fields", {{"listening_device", "tin_can"}}}})
            .status,
        422);
    EXPECT_EQ(c.post("/api/consent",
                     {{"consent", true}, {"fields", {{"listening_device", "headphones"}}}})
                  .status,
              200);
    // Trials before the screening are refused.
    const json st = c.get("/api/state").body;
    EXPECT_EQ(st["phase"], "screening");
    EXPECT_EQ(c.post("/api/present", {{"trial", 0}}).status, 409);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 0}, {"choice", 1}}).status, 409);
}

TEST(WebApi, FailedScreeningEndsTheSessionWhenAskedTo) {
    StudyFixture f(2);
    WebOptions wo = testOptions();
    wo.screeningFailure = ScreeningFailure::End;
    InProcessServer s(f, {}, wo);
    ApiClient c(s.port, f.links[0].token);
    ASSERT_EQ(consent(c).status, 200);
    const Reply r = doScreening(c, Listener::Loudspeakers);
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body["phase"], "ended");
    EXPECT_EQ(r.body["reason"], "screening");
    StudyStore store = StudyStore::open(f.study);
    EXPECT_EQ(store.participant(f.links[0].participantCode).status,
              experiment::ParticipantStatus::Dropped);
    experiment::Invitations inv(store);
    EXPECT_EQ(inv.byCode(f.links[0].participantCode).screeningPassed, false);
}

TEST(WebApi, FailedScreeningIsFlaggedByDefault) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    ASSERT_EQ(consent(c).status, 200);
    const Reply r = doScreening(c, Listener::Loudspeakers);
    EXPECT_EQ(r.body["phase"], "practice");
    EXPECT_EQ(r.body["screening"]["passed"], false);
}

TEST(WebApi, ReplaysAreCountedOrRefusedAsTheProtocolSays) {
    {
        const AtFirstTrial p;
        for (int replays = 0; replays < 3; ++replays)
            EXPECT_EQ(p.c.post("/api/present", {{"trial", p.t}}).body["replays"], replays);
        EXPECT_EQ(p.replaysStored(), 2);
    }
    {
        const AtFirstTrial p(webProtocol("replay = false\n"));
        EXPECT_EQ(p.state["trial"]["replayAllowed"], false);
        EXPECT_EQ(p.c.post("/api/present", {{"trial", p.t}}).status, 200);
        EXPECT_EQ(p.c.post("/api/present", {{"trial", p.t}}).status, 409);
        EXPECT_EQ(p.replaysStored(), 0);
    }
}

TEST(WebApi, NoPathOutsideTheClipsFolderAndNoListing) {
    StudyFixture f(1);
    // A secret next to the clips folder, and a clip that is a symbolic link leaving the folder.
    { std::ofstream(f.dir.file("secret.txt")) << "SECRET"; }
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    const json st = startParticipant(c);
    for (const std::string path :
         {"/assets/../../etc/passwd", "/assets/..%2F..%2Fetc%2Fpasswd", "/assets/%2e%2e/secret.txt",
          "/assets//etc/passwd", "/assets/", "/assets", "/api/clip/../../secret.txt",
          "/api/clip/..%2F..%2Fsecret.txt", "/api/clip/%2Fetc%2Fpasswd", "/api/clip//etc/passwd",
          "/api/clip/", "/clips/", "/clips/WD.wav", "/../secret.txt", "/%2e%2e/secret.txt",
          "/api/clip/0%00", "/api/clip/-1", "/assets/index.html"}) {
        const Reply r = c.get(path);
        EXPECT_TRUE(r.status == 404 || r.status == 400) << path << " -> " << r.status;
        EXPECT_EQ(r.raw.find("SECRET"), std::string::npos) << path;
        EXPECT_EQ(r.raw.find("root:"), std::string::npos) << path;
    }
    EXPECT_EQ(c.get("/assets/app.js").status, 200);
    EXPECT_EQ(c.get("/p").status, 200);
    // A clip file replaced by a symbolic link to a file outside the folder is refused.
    const int t = st["trial"]["index"];
    StudyStore store = StudyStore::open(f.study);
    const auto stimulus = store.trial(f.links[0].participantCode, t).stimulus;
    const std::string clip = experiment::clipPath(stimulus, f.clips);
    fs::remove(clip);
    fs::create_symlink(f.dir.file("secret.txt"), clip);
    const Reply r = c.get("/api/clip/" + std::to_string(t));
    EXPECT_EQ(r.status, 403) << r.raw;
    EXPECT_EQ(r.raw.find("SECRET"), std::string::npos);
}

TEST(WebApi, OversizedBodiesAndFloodsAreRefused) {
    StudyFixture f(1);
    ServerOptions so;
    so.maxBodyBytes = 4096;
    so.ratePerSecond = 5;
    so.burst = 10;
    InProcessServer s(f, so);
    ApiClient c(s.port, f.links[0].token);
    const Reply big = c.postRaw("/api/consent", std::string(100000, ' '));
    EXPECT_EQ(big.status, 413);
    int limited = 0;
    for (int i = 0; i < 40; ++i) limited += c.get("/api/state").status == 429;
    EXPECT_GE(limited, 20);
    // Bad tokens are limited per address as well.
    ApiClient bad(s.port, "nonsense");
    limited = 0;
    for (int i = 0; i < 40; ++i) limited += bad.get("/api/state").status == 429;
    EXPECT_GE(limited, 20);
}

TEST(WebApi, HeadAnswersLikeGetWithoutABody) {
    StudyFixture f(1);
    InProcessServer s(f);
    const json st = startParticipant(ApiClient(s.port, f.links[0].token));
    for (const auto& [path, token] :
         {std::pair<std::string, std::string>{"/p", ""},
          {"/assets/app.js", ""},
          {"/api/clip/" + std::to_string(st["trial"]["index"].get<int>()), f.links[0].token}}) {
        Headers h;
        if (!token.empty()) h.emplace_back("Authorization", "Bearer " + token);
        const Reply get = exchange(s.port, "GET", path, h, "");
        const Reply head = exchange(s.port, "HEAD", path, h, "");
        EXPECT_EQ(head.status, 200) << path;
        EXPECT_TRUE(head.raw.empty()) << path;
        EXPECT_EQ(head.headers.at("Content-Length"), std::to_string(get.raw.size())) << path;
        EXPECT_EQ(head.headers.at("Content-Type"), get.headers.at("Content-Type")) << path;
    }
}

TEST(WebApi, ATrustedProxyMustBeAnAddress) {
    StudyFixture f(1);
    WebOptions wo = testOptions();
    wo.clipsDir = f.clips;
    WebStudy study(f.study, wo);
    ServerOptions so;
    so.trustedProxies = {"127.0.0.1", "proxy.example.org"};
    try {
        WebServer server(study, so);
        FAIL() << "a host name was taken as a trusted proxy";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'proxy.example.org': not an IP address"),
                  std::string::npos)
            << e.what();
    }
}

TEST(WebApi, ProtocolsThatCannotRunOnlineAreRefusedClearly) {
    const auto laps = experiment::parseProtocol(
        "[protocol]\nid = \"walk\"\nversion = 1\ntitle = \"Walk\"\n[design]\ntype = \"within\"\n"
        "[[stimuli]]\nid = \"WD\"\nsurface = \"wood\"\n[laps]\nbaseline = 1\nfeedback = 2\n"
        "[questions]\n[[questions.scales]]\nid = \"effort\"\nprompt = \"Effort\"\nmin = 1\nmax = "
        "7\n",
        "walk.toml");
    try {
        checkOnlineProtocol(laps);
        FAIL() << "a laps protocol was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("laps"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot run online"), std::string::npos) << e.what();
    }
    const auto booth =
        experiment::loadProtocol(experiment::shippedProtocolDir() + "/tvcg2011_exp1.toml");
    EXPECT_THROW(checkOnlineProtocol(booth), std::runtime_error);
    EXPECT_NO_THROW(checkOnlineProtocol(experiment::parseProtocol(webProtocol(), "web.toml")));
}

TEST(WebApi, MissingClipsStopTheServerBeforeItStarts) {
    StudyFixture f(1);
    fs::remove(f.clips + "/GL.wav");
    WebOptions wo = testOptions();
    wo.clipsDir = f.clips;
    try {
        WebStudy study(f.study, wo);
        FAIL() << "started without a clip";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("GL.wav"), std::string::npos) << e.what();
    }
}

TEST(WebApi, TokensAreLongRandomAndStoredOnlyAsHashes) {
    StudyFixture f(20);
    std::set<std::string> seen;
    for (const auto& l : f.links) {
        EXPECT_EQ(l.token.size(), 43u); // 256 bits in base64url
        EXPECT_TRUE(seen.insert(l.token).second);
    }
    SQLite::Database db(f.study, SQLite::OPEN_READONLY);
    SQLite::Statement q(db, "SELECT token_sha256 FROM online_invitations");
    int rows = 0;
    while (q.executeStep()) {
        ++rows;
        const std::string h = q.getColumn(0).getString();
        EXPECT_EQ(h.size(), 64u);
        EXPECT_FALSE(seen.count(h));
    }
    EXPECT_EQ(rows, 20);
    // No byte of the study (file and write-ahead log) holds a token.
    std::string bytes;
    for (const std::string& file : {f.study, f.study + "-wal"}) {
        std::ifstream in(file, std::ios::binary);
        bytes += std::string(std::istreambuf_iterator<char>(in), {});
    }
    for (const auto& l : f.links) EXPECT_EQ(bytes.find(l.token), std::string::npos);
}

} // namespace
} // namespace underfoot::web::test
