// SPDX-License-Identifier: GPL-3.0-or-later
// The headphone check scored by the server (experiment/HeadphoneCheck.h) over loopback HTTP
// and a real study file: a posted score is refused, the page must fetch each triplet's tones
// and may answer only after they could be heard; a listener with headphones passes, one with
// loudspeakers fails (the antiphase tone cancels between the ears); the stored seed replays the
// layout and every byte of the tones served; a restart resumes the check where it was.
#include "WebTestSupport.h"

#include "experiment/HeadphoneCheck.h"

#include <gtest/gtest.h>

namespace underfoot::web::test {
namespace {

using experiment::HeadphoneCheck;
using experiment::StudyStore;

json storedDetail(const StudyFixture& f, int link = 0) {
    StudyStore store = StudyStore::open(f.study);
    const std::string d =
        experiment::Invitations(store).byCode(f.links[link].participantCode).screeningDetail;
    return json::parse(d.empty() ? "null" : d);
}

TEST(WebScreening, AForgedScoreIsRefused) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    ASSERT_EQ(consent(c).status, 200);
    // The old page's score, before and after the check started: refused, nothing stored.
    EXPECT_EQ(c.post("/api/screening", {{"correct", 6}, {"total", 6}}).status, 400);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 0}, {"choice", 1}}).status, 409);
    ASSERT_EQ(c.post("/api/screening/start", json::object()).status, 200);
    EXPECT_EQ(c.post("/api/screening", {{"correct", 1}, {"total", 1}}).status, 400);
    // Choices without the tones: refused, whatever they are.
    for (int choice = 1; choice <= 3; ++choice)
        EXPECT_EQ(c.post("/api/screening", {{"triplet", 0}, {"choice", choice}}).status, 409);
    EXPECT_EQ(doScreening(c, Listener::Guess1).status, 409);
    // Tones of a later triplet than the one waiting, choices out of range or out of order.
    EXPECT_EQ(c.get("/api/screening/tones/1").status, 409);
    ASSERT_EQ(c.get("/api/screening/tones/0").status, 200);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 0}, {"choice", 4}}).status, 400);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 1}, {"choice", 1}}).status, 409);
    const json st = c.get("/api/state").body;
    EXPECT_EQ(st["phase"], "screening");
    EXPECT_EQ(st["check"]["next"], 0);
    EXPECT_TRUE(storedDetail(f).is_null());
    EXPECT_EQ(c.post("/api/present", {{"trial", 0}}).status, 409);
}

TEST(WebScreening, HeadphonesPassLoudspeakersFail) {
    StudyFixture f(2);
    InProcessServer s(f);
    ApiClient ears(s.port, f.links[0].token);
    ApiClient room(s.port, f.links[1].token);
    ASSERT_EQ(consent(ears).status, 200);
    ASSERT_EQ(consent(room).status, 200);
    const Reply pass = doScreening(ears, Listener::Headphones);
    ASSERT_EQ(pass.status, 200) << pass.raw;
    EXPECT_EQ(pass.body["screening"]["passed"], true);
    EXPECT_EQ(pass.body["phase"], "practice");
    const Reply fail = doScreening(room, Listener::Loudspeakers);
    ASSERT_EQ(fail.status, 200) << fail.raw;
    EXPECT_EQ(fail.body["screening"]["passed"], false);
    // Stored: the seed, the layout, each choice, the score and the pass mark.
    const json good = storedDetail(f, 0), bad = storedDetail(f, 1);
    EXPECT_EQ(good["correct"], 6);
    EXPECT_EQ(bad["correct"], 0); // over loudspeakers the antiphase tone sounds quietest
    EXPECT_EQ(good["total"], HeadphoneCheck::kTriplets);
    EXPECT_EQ(good["passMark"], HeadphoneCheck::kPassMark);
    EXPECT_EQ(good["choices"].size(), 6u);
    for (std::size_t k = 0; k < 6; ++k) {
        EXPECT_EQ(good["choices"][k], good["layout"][k]["quiet"]);
        EXPECT_EQ(bad["choices"][k], bad["layout"][k]["antiphase"]);
    }
    // Journaled: the start (with the seed) and the six answers of each participant.
    int started = 0, answers = 0;
    for (const auto& e : StudyStore::open(f.study).events()) {
        started += e.kind == "online_screening_started";
        answers += e.kind == "online_screening_answer";
    }
    EXPECT_EQ(started, 2);
    EXPECT_EQ(answers, 12);
    // The first verdict counts: a later check is not started, a later choice changes nothing.
    EXPECT_EQ(room.post("/api/screening/start", json::object()).body["screening"]["passed"], false);
    EXPECT_EQ(room.get("/api/screening/tones/0").status, 409);
}

TEST(WebScreening, FiveOfSixPassFourDoNot) {
    StudyFixture f(2);
    InProcessServer s(f);
    for (int link = 0; link < 2; ++link) {
        ApiClient c(s.port, f.links[static_cast<std::size_t>(link)].token);
        ASSERT_EQ(consent(c).status, 200);
        Reply r = c.post("/api/screening/start", json::object());
        const int wrong = link == 0 ? 1 : 2; // participant 0: 5 of 6; participant 1: 4 of 6
        for (int k = 0; k < 6; ++k) {
            const Reply tones = c.get("/api/screening/tones/" + std::to_string(k));
            const int heard = quietestHeard(tones.raw);
            r = c.post("/api/screening",
                       {{"triplet", k}, {"choice", k < wrong ? heard % 3 + 1 : heard}});
            ASSERT_EQ(r.status, 200) << r.raw;
        }
        EXPECT_EQ(r.body["screening"]["passed"], link == 0);
        EXPECT_EQ(storedDetail(f, link)["correct"], 6 - wrong);
    }
}

TEST(WebScreening, AnAnswerBeforeTheTonesCouldEndIsRefused) {
    EXPECT_DOUBLE_EQ(WebOptions{}.screeningMinResponseS, HeadphoneCheck::tripletSeconds());
    StudyFixture f(1);
    WebOptions wo = testOptions();
    wo.screeningMinResponseS = 0.4;
    InProcessServer s(f, {}, wo);
    ApiClient c(s.port, f.links[0].token);
    ASSERT_EQ(consent(c).status, 200);
    ASSERT_EQ(c.post("/api/screening/start", json::object()).status, 200);
    const Reply tones = c.get("/api/screening/tones/0");
    ASSERT_EQ(tones.status, 200);
    const int heard = quietestHeard(tones.raw);
    const Reply early = c.post("/api/screening", {{"triplet", 0}, {"choice", heard}});
    EXPECT_EQ(early.status, 409) << early.raw;
    EXPECT_NE(early.raw.find("at least 0.40 s"), std::string::npos) << early.raw;
    // Fetching the tones again does not restart the clock, nor skip it.
    std::this_thread::sleep_for(std::chrono::milliseconds(450));
    ASSERT_EQ(c.get("/api/screening/tones/0").status, 200);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 0}, {"choice", heard}}).status, 200);
    // The next triplet's clock starts with its own tones.
    ASSERT_EQ(c.get("/api/screening/tones/1").status, 200);
    EXPECT_EQ(c.post("/api/screening", {{"triplet", 1}, {"choice", 1}}).status, 409);
}

TEST(WebScreening, TheStoredSeedReplaysTheTonesServed) {
    StudyFixture f(1);
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    ASSERT_EQ(consent(c).status, 200);
    ASSERT_EQ(c.post("/api/screening/start", json::object()).status, 200);
    std::vector<std::string> served;
    for (int k = 0; k < 6; ++k) {
        const Reply tones = c.get("/api/screening/tones/" + std::to_string(k));
        ASSERT_EQ(tones.status, 200);
        EXPECT_EQ(tones.headers.at("Content-Type"), "audio/wav");
        EXPECT_EQ(tones.headers.count("Content-Disposition"), 0u);
        served.push_back(tones.raw);
        ASSERT_EQ(
            c.post("/api/screening", {{"triplet", k}, {"choice", quietestHeard(tones.raw)}}).status,
            200);
    }
    const json d = storedDetail(f);
    const auto seed = d.at("seed").get<std::uint64_t>();
    const auto layout = HeadphoneCheck::layout(seed);
    for (std::size_t k = 0; k < 6; ++k) {
        EXPECT_EQ(d["layout"][k]["quiet"], layout[k].quiet + 1);
        EXPECT_EQ(d["layout"][k]["antiphase"], layout[k].antiphase + 1);
        const std::string again = HeadphoneCheck::wav(layout[k]);
        EXPECT_EQ(experiment::sha256Hex(again), experiment::sha256Hex(served[k])) << k;
    }
}

TEST(WebScreening, ARestartResumesTheCheckWithItsSeed) {
    StudyFixture f(1);
    std::string first;
    {
        InProcessServer s(f);
        ApiClient c(s.port, f.links[0].token);
        ASSERT_EQ(consent(c).status, 200);
        ASSERT_EQ(c.post("/api/screening/start", json::object()).status, 200);
        for (int k = 0; k < 2; ++k) {
            const Reply tones = c.get("/api/screening/tones/" + std::to_string(k));
            if (k == 0) first = tones.raw;
            ASSERT_EQ(
                c.post("/api/screening", {{"triplet", k}, {"choice", quietestHeard(tones.raw)}})
                    .status,
                200);
        }
    }
    InProcessServer s(f);
    ApiClient c(s.port, f.links[0].token);
    const Reply r = c.post("/api/screening/start", json::object());
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body["check"]["next"], 2);
    const Reply done = doScreening(c);
    ASSERT_EQ(done.status, 200) << done.raw;
    EXPECT_EQ(done.body["screening"]["passed"], true);
    const json d = storedDetail(f);
    EXPECT_EQ(d["correct"], 6);
    EXPECT_EQ(HeadphoneCheck::wav(HeadphoneCheck::layout(d["seed"].get<std::uint64_t>())[0]),
              first);
}

} // namespace
} // namespace underfoot::web::test
