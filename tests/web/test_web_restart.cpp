// SPDX-License-Identifier: GPL-3.0-or-later
// A restart of `underfoot serve` mid-test never tells a participant they have finished: the
// killed server's lease is left as a crash would leave it, or rewritten as a re-created
// container, a reboot or a reused PID would show it, and the participant at trial 4 of 7 must
// resume there and finish with all answers stored once. A lease of a live process on this host
// gets a retryable 503 (Retry-After) until that process ends, never the end page.
#include "ServeProcess.h"

#include "experiment/LeaseHolder.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

#include <csignal>
#include <thread>

namespace underfoot::web::test {
namespace {

using experiment::LeaseHolder;

/// Answers the current trial (presenting it first) or finishes a break; returns the new state.
json step(const ApiClient& c, const json& state, int n) {
    if (state.at("phase") == "break") return c.post("/api/break", json::object()).body;
    const int index = state.at("trial").at("index").get<int>();
    Reply r = c.post("/api/present", {{"trial", index}, {"attempt", "p" + std::to_string(n)}});
    EXPECT_EQ(r.status, 200) << r.raw;
    r = c.post("/api/answer", validAnswer(state, "a" + std::to_string(n)));
    EXPECT_EQ(r.status, 200) << r.raw;
    return r.body;
}

/// Rewrites the participant's lease as another holder would have left it.
void setLease(const StudyFixture& f, const std::string& code, const LeaseHolder& h) {
    SQLite::Database db(f.study, SQLite::OPEN_READWRITE);
    SQLite::Statement q(db, "UPDATE session_leases SET pid = ?, host = ?, start_ticks = ?, "
                            "boot_id = ? WHERE participant_id = (SELECT id FROM participants "
                            "WHERE code = ?)");
    q.bind(1, h.pid);
    q.bind(2, h.host);
    if (h.startTicks)
        q.bind(3, static_cast<std::int64_t>(*h.startTicks));
    else
        q.bind(3);
    q.bind(4, h.bootId);
    q.bind(5, code);
    ASSERT_EQ(q.exec(), 1) << "the killed server left no lease";
}

std::string participantStatus(const StudyFixture& f, const std::string& code) {
    SQLite::Database db(f.study, SQLite::OPEN_READONLY);
    SQLite::Statement q(db, "SELECT status FROM participants WHERE code = ?");
    q.bind(1, code);
    return q.executeStep() ? q.getColumn(0).getString() : "";
}

/// The holder states journaled when leases were recovered or taken over.
std::vector<std::string> leaseEvents(const StudyFixture& f) {
    SQLite::Database db(f.study, SQLite::OPEN_READONLY);
    SQLite::Statement q(db, "SELECT kind || ':' || json_extract(detail, '$.holder') FROM events "
                            "WHERE kind IN ('lease_recovered', 'lease_taken_over') ORDER BY id");
    std::vector<std::string> out;
    while (q.executeStep()) out.push_back(q.getColumn(0).getString());
    return out;
}

/// One participant of a study served by an `underfoot serve` process (`first`), past consent
/// and screening; `state` is their first trial's.
struct Started {
    StudyFixture f{1};
    std::string code = f.links[0].participantCode;
    std::unique_ptr<ServeProcess> first = std::make_unique<ServeProcess>(f, 0);
    ApiClient c{first->port(), f.links[0].token};
    json state = startParticipant(c);
};

enum class Holder { Reaped, Zombie, OtherHost, OtherBoot, ReusedPid };

/// Three trials (and the practice) answered, the server killed, the lease left as `holder`,
/// a new server: the participant resumes at the next trial and finishes, nothing lost.
void restartResumes(Holder holder, const std::string& expectedEvent) {
    Started p;
    auto& [f, code, first, c, state] = p;
    int n = 0;
    int answered = 0;
    while (answered < 4) {
        const bool trial = state.at("phase") != "break";
        state = step(c, state, n++);
        answered += trial ? 1 : 0;
    }
    ASSERT_EQ(state.at("progress").at("answered"), 4);
    if (holder == Holder::Zombie) {
        ::kill(first->pid(), SIGKILL); // not reaped until `first` is destroyed
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    } else {
        first->kill9();
    }
    LeaseHolder me = experiment::thisProcess(); // a live process on this host and boot
    switch (holder) {
    case Holder::Reaped:
    case Holder::Zombie:
        break;
    case Holder::OtherHost:
        me.host = "re-created-container";
        setLease(f, code, me);
        break;
    case Holder::OtherBoot:
        me.bootId = "00000000-0000-0000-0000-000000000000";
        setLease(f, code, me);
        break;
    case Holder::ReusedPid:
        *me.startTicks -= 1;
        setLease(f, code, me);
        break;
    }
    ServeProcess second(f, 0);
    c.setPort(second.port());
    Reply r = c.get("/api/state");
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_NE(r.body.at("phase"), "finished") << r.raw;
    EXPECT_FALSE(r.body.contains("completionCode")) << r.raw;
    EXPECT_EQ(r.body.at("progress").at("answered"), 4) << r.raw;
    EXPECT_EQ(participantStatus(f, code), "active");
    state = r.body;
    while (state.at("phase") != "finished" && n < 40) state = step(c, state, n++);
    EXPECT_EQ(state.at("phase"), "finished");
    EXPECT_EQ(state.at("progress").at("answered"), state.at("progress").at("total"));
    EXPECT_FALSE(state.at("completionCode").get<std::string>().empty());
    EXPECT_EQ(participantStatus(f, code), "completed");
    const auto events = leaseEvents(f);
    ASSERT_FALSE(events.empty());
    EXPECT_EQ(events.back(), expectedEvent);
}

TEST(WebRestart, KilledServerLeaseIsRecovered) {
    restartResumes(Holder::Reaped, "lease_recovered:dead");
}

TEST(WebRestart, UnreapedKilledServerIsNotALiveHolder) {
    restartResumes(Holder::Zombie, "lease_recovered:dead");
}

TEST(WebRestart, ForeignHostLeaseIsTakenOver) {
    restartResumes(Holder::OtherHost, "lease_taken_over:other host");
}

TEST(WebRestart, LeaseOfAnEarlierBootIsRecovered) {
    restartResumes(Holder::OtherBoot, "lease_recovered:before a reboot");
}

TEST(WebRestart, ReusedPidIsNotALiveHolder) {
    restartResumes(Holder::ReusedPid, "lease_recovered:PID reused");
}

TEST(WebRestart, LiveHolderGetsRetryableUnavailableNeverTheEndPage) {
    Started p;
    auto& [f, code, first, c, state] = p;
    state = step(c, state, 0); // the practice trial
    state = step(c, state, 1);
    first->kill9();
    // Another live process on this host holds the lease (a second server on the same file).
    const pid_t holderPid = ::fork();
    if (holderPid == 0) {
        ::pause();
        ::_exit(0);
    }
    ASSERT_GT(holderPid, 0);
    LeaseHolder live = experiment::thisProcess();
    live.pid = holderPid;
    live.startTicks = experiment::processStartTicks(holderPid);
    ASSERT_TRUE(live.startTicks.has_value());
    setLease(f, code, live);
    ServeProcess second(f, 0);
    c.setPort(second.port());
    for (const std::string path : {"/api/state", "/api/answer"}) {
        const Reply r = path == "/api/state"
                            ? c.get(path)
                            : c.post(path, {{"trial", 2}, {"attempt", "x"}, {"answer", "wood"}});
        EXPECT_EQ(r.status, 503) << path << ": " << r.raw;
        EXPECT_EQ(r.headers.count("Retry-After") ? r.headers.at("Retry-After") : "", "5") << path;
        EXPECT_EQ(r.raw.find("completionCode"), std::string::npos) << r.raw;
        EXPECT_EQ(r.raw.find("finished"), std::string::npos) << r.raw;
    }
    EXPECT_EQ(participantStatus(f, code), "active");
    ::kill(holderPid, SIGKILL);
    ::waitpid(holderPid, nullptr, 0);
    const Reply r = c.get("/api/state");
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body.at("phase"), "trial") << r.raw;
    EXPECT_EQ(r.body.at("progress").at("answered"), 2);
    EXPECT_EQ(leaseEvents(f).back(), "lease_recovered:dead");
}

TEST(WebRestart, ReplaysBeforeAKillAreKept) {
    Started p;
    auto& [f, code, first, c, state] = p;
    const int index = state.at("trial").at("index").get<int>();
    for (const char* play : {"p1", "p2", "p3"}) // one presentation, two replays
        ASSERT_EQ(c.post("/api/present", {{"trial", index}, {"attempt", play}}).status, 200);
    first->kill9();
    ServeProcess second(f, 0);
    c.setPort(second.port());
    Reply r = c.get("/api/state");
    ASSERT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body.at("trial").at("replays"), 2) << r.raw;
    r = c.post("/api/answer", validAnswer(r.body, "a1"));
    ASSERT_EQ(r.status, 200) << r.raw;
    SQLite::Database db(f.study, SQLite::OPEN_READONLY);
    SQLite::Statement q(db, "SELECT replays FROM trials WHERE trial_index = ? AND participant_id = "
                            "(SELECT id FROM participants WHERE code = ?)");
    q.bind(1, index);
    q.bind(2, code);
    ASSERT_TRUE(q.executeStep());
    EXPECT_EQ(q.getColumn(0).getInt(), 2);
}

} // namespace
} // namespace underfoot::web::test
