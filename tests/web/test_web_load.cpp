// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot serve` as a separate process under load and faults, on loopback: simulated
// participants (threads, each from its own loopback address, a fresh connection per request
// as a page with retries would make) with lost replies, duplicate submissions, reloads and
// server SIGKILLs + restarts on the same port. Checked: every acknowledged answer is in the
// study with the ratings that participant sent, no answer is stored twice, every participant
// finishes; SIGTERM stops cleanly. The figures (answer round trip, clip delivery, memory per
// participant) are printed for docs/reference/web-server.md; they are never pass/fail.
#include "ServeProcess.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>

namespace underfoot::web::test {
namespace {

using Clock = std::chrono::steady_clock;

struct Figures {
    std::mutex mutex;
    std::vector<double> answerMs, answerMsNoRetry, clipMs;
    int lostReplies = 0, duplicates = 0, reloads = 0, retries = 0;
    /// The end page (phase "finished") shown with trials still unanswered.
    int falseCompletions = 0;
};

/// Ratings for every scale of the trial in `state`, drawn at random within each scale.
json randomRatings(const json& state, std::mt19937_64& rng) {
    json ratings = json::object();
    for (const auto& s : state.at("trial").at("scales")) {
        const int lo = s.at("min"), hi = s.at("max");
        ratings[s.at("id").get<std::string>()] = lo + static_cast<int>(rng() % (hi - lo + 1));
    }
    return ratings;
}

/// What one participant runs through: the page's requests, with the faults of a real network.
class Participant {
  public:
    Participant(const std::atomic<int>& port, std::string token, std::string source,
                std::uint64_t seed, Figures& fig, std::atomic<int>& acked)
        : port_(port), token_(std::move(token)), source_(std::move(source)), rng_(seed), fig_(fig),
          acked_(acked) {}

    /// Consents (answering the protocol's fields with their first option).
    void consent() {
        const json st = call([&](ApiClient& c) { return c.get("/api/state"); }).body;
        json fields = json::object();
        for (const auto& f : st.value("fields", json::array()))
            if (!f.at("options").empty()) fields[f.at("id").get<std::string>()] = f["options"][0];
        const Reply r = call([&](ApiClient& c) {
            return c.post("/api/consent", {{"consent", true}, {"fields", fields}});
        });
        if (r.status != 200) throw std::runtime_error("consent: " + r.raw);
    }

    /// The rest of the test; returns acknowledged answers (trial -> ratings sent).
    std::map<int, json> finish() {
        call([&](ApiClient& c) { return c.post("/api/client", {{"sampleRate", 44100}}); });
        json state = call([&](ApiClient& c) { return doScreening(c); }).body;
        for (int guard = 0; guard < 400 && state["phase"] != "finished"; ++guard) {
            if (state["phase"] == "break") {
                state =
                    call([&](ApiClient& c) { return c.post("/api/break", json::object()); }).body;
                continue;
            }
            if (!state.contains("trial"))
                throw std::runtime_error("unexpected state " + state.dump());
            state = trial(state);
        }
        if (state["phase"] != "finished") throw std::runtime_error("not finished: " + state.dump());
        if (state["progress"]["answered"] != state["progress"]["total"]) {
            std::lock_guard lock(fig_.mutex);
            ++fig_.falseCompletions;
        }
        return sent_;
    }

  private:
    /// Retries a request until the server answers (down during a restart: status 0 or 5xx).
    template <typename Request>
    Reply call(Request&& request) {
        for (int i = 0; i < 1200; ++i) {
            lastRetries_ = i;
            ApiClient c(port_.load(), token_, source_);
            Reply r = request(c);
            if (r.status != 0 && r.status < 500 && r.status != 429) return r;
            {
                std::lock_guard lock(fig_.mutex);
                ++fig_.retries;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        throw std::runtime_error("the server did not come back within 60 s");
    }

    /// A reload of the page: the page and its files, then the state.
    json reload() {
        {
            std::lock_guard lock(fig_.mutex);
            ++fig_.reloads;
        }
        for (const char* path : {"/p", "/assets/app.js", "/assets/style.css"}) // no token
            if (call([&](ApiClient&) {
                    return exchange(port_.load(), "GET", path, {}, "", source_);
                }).status != 200)
                throw std::runtime_error(std::string("reload: ") + path);
        return call([&](ApiClient& c) { return c.get("/api/state"); }).body;
    }

    /// Presents and answers the current trial; returns the next state.
    json trial(const json& state) {
        std::uniform_real_distribution<double> u(0, 1);
        const int index = state["trial"]["index"];
        const auto t0 = Clock::now();
        const Reply clip =
            call([&](ApiClient& c) { return c.get("/api/clip/" + std::to_string(index)); });
        const double clipMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        const std::string playId = "p" + std::to_string(rng_());
        const Reply p = call([&](ApiClient& c) {
            return c.post("/api/present", {{"trial", index}, {"attempt", playId}});
        });
        if (p.status == 409 || clip.status == 409) // a restart moved on; ask again
            return call([&](ApiClient& c) { return c.get("/api/state"); }).body;
        json a = validAnswer(state, "a" + std::to_string(rng_()));
        a["ratings"] = randomRatings(state, rng_);
        std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(u(rng_) * 20)));
        Reply ack;
        double ms = 0;
        bool retried = false;
        if (u(rng_) < 0.1) { // a lost reply: sent, the connection drops before the answer
            {
                std::lock_guard lock(fig_.mutex);
                ++fig_.lostReplies;
            }
            ApiClient(port_.load(), token_, source_).post("/api/answer", a); // reply ignored
            if (u(rng_) < 0.5) { // the participant reloads; the page resends the kept answer
                const json now = reload();
                if (now.contains("trial") && now["trial"]["index"] == index) {
                    const auto a0 = Clock::now();
                    ack = call([&](ApiClient& c) { return c.post("/api/answer", a); });
                    ms = std::chrono::duration<double, std::milli>(Clock::now() - a0).count();
                    retried = true;
                } else { // stored by the lost request: the page goes on
                    sent_[index] = a["ratings"];
                    ++acked_;
                    return now;
                }
            }
        }
        if (ack.status == 0) {
            const auto a0 = Clock::now();
            ack = call([&](ApiClient& c) { return c.post("/api/answer", a); });
            ms = std::chrono::duration<double, std::milli>(Clock::now() - a0).count();
            retried = retried || lastRetries_ > 0;
        }
        if (ack.status != 200) throw std::runtime_error("answer: " + ack.raw);
        if (u(rng_) < 0.1) { // a duplicate submission (double click, retry after a timeout)
            const Reply dup = call([&](ApiClient& c) { return c.post("/api/answer", a); });
            if (dup.status != 200 || dup.body["duplicate"] != true)
                throw std::runtime_error("duplicate: " + dup.raw);
            std::lock_guard lock(fig_.mutex);
            ++fig_.duplicates;
        }
        sent_[index] = a["ratings"];
        ++acked_;
        std::lock_guard lock(fig_.mutex);
        fig_.answerMs.push_back(ms);
        if (!retried) fig_.answerMsNoRetry.push_back(ms);
        if (clip.status == 200) fig_.clipMs.push_back(clipMs);
        return ack.body;
    }

    const std::atomic<int>& port_;
    std::string token_, source_;
    std::mt19937_64 rng_;
    Figures& fig_;
    std::atomic<int>& acked_;
    std::map<int, json> sent_;
    int lastRetries_ = 0;
};

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const auto i = static_cast<std::size_t>(
        std::min<double>(static_cast<double>(v.size() - 1), p * static_cast<double>(v.size())));
    return v[i];
}

struct LoadPlan {
    std::string protocol;
    int participants = 50;
    /// Participants taking the test at the same time (the next starts when one finishes).
    int concurrency = 50;
    /// Trials each participant answers (practice included).
    int trialsEach = 7;
    int kills = 1;
};

void runLoad(const LoadPlan& plan) {
    StudyFixture f(plan.participants, plan.protocol);
    auto server = std::make_unique<ServeProcess>(f, 0, std::vector<std::string>{"--rate", "1000"});
    std::atomic<int> port{server->port()};
    const long rssIdle = server->rssKb();
    Figures fig;
    std::atomic<int> acked{0}, next{0}, consented{0};
    std::atomic<bool> hold{true};
    const auto n = static_cast<std::size_t>(plan.participants);
    std::vector<std::map<int, json>> sent(n);
    std::vector<std::string> errors(n);
    std::vector<std::thread> threads;
    for (int w = 0; w < plan.concurrency; ++w)
        threads.emplace_back([&] {
            for (int i = next++; i < plan.participants; i = next++) {
                try {
                    Participant p(port, f.links[i].token, clientAddress(i), 1000 + i, fig, acked);
                    p.consent();
                    ++consented;
                    // The first wave holds after consent: memory with every session open.
                    while (hold.load()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
                    sent[i] = p.finish();
                } catch (const std::exception& e) {
                    errors[i] = e.what();
                }
            }
        });
    const auto deadline = Clock::now() + std::chrono::seconds(120);
    while (Clock::now() < deadline && consented.load() < plan.concurrency)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const long rssOpen = server->rssKb();
    hold = false;
    const int total = plan.participants * plan.trialsEach;
    for (int k = 1; k <= plan.kills; ++k) {
        while (acked.load() < total * k / (plan.kills + 1))
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        server->kill9();
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        server = std::make_unique<ServeProcess>( // the same port, as in a restart
            f, port.load(), std::vector<std::string>{"--rate", "1000"});
    }
    for (auto& t : threads) t.join();
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(errors[i], "") << "participant " << i;
    const auto [exitCode, output] = server->terminate();
    EXPECT_EQ(exitCode, 0);
    EXPECT_NE(output.find("stopped (SIGTERM)"), std::string::npos) << output;

    // 0 lost, 0 duplicated, 0 misattributed, every participant finished.
    experiment::StudyStore store = experiment::StudyStore::open(f.study);
    std::map<std::pair<std::string, int>, int> answeredEvents;
    int changed = 0;
    for (const auto& e : store.events()) {
        if (e.kind == "answered" && e.trialIndex) ++answeredEvents[{e.participant, *e.trialIndex}];
        changed += e.kind == "answer_changed";
    }
    EXPECT_EQ(changed, 0);
    int lost = 0, duplicated = 0, misattributed = 0, stored = 0, acknowledged = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::string code = f.links[i].participantCode;
        EXPECT_EQ(store.participant(code).status, experiment::ParticipantStatus::Completed) << code;
        acknowledged += static_cast<int>(sent[i].size());
        for (const auto& t : store.trials(code)) {
            stored += t.answered;
            if (answeredEvents[{code, t.index}] > 1) ++duplicated;
            const auto it = sent[i].find(t.index);
            if (it == sent[i].end()) continue;
            if (!t.answered) {
                ++lost;
                continue;
            }
            for (const auto& [scale, value] : it->second.items())
                if (t.answer.ratings.at(scale) != value.get<int>()) {
                    ++misattributed;
                    break;
                }
        }
    }
    EXPECT_EQ(lost, 0);
    EXPECT_EQ(duplicated, 0);
    EXPECT_EQ(misattributed, 0);
    EXPECT_EQ(stored, total);
    EXPECT_EQ(acknowledged, total);
    std::printf("[figures] participants %d (%d at a time), answers stored %d (acknowledged %d), "
                "server SIGKILLs %d, lost replies %d, duplicate submissions %d, reloads %d, "
                "client retries %d\n",
                plan.participants, plan.concurrency, stored, acknowledged, plan.kills,
                fig.lostReplies, fig.duplicates, fig.reloads, fig.retries);
    std::printf("[figures] lost %d, duplicated %d, misattributed %d, false completions %d\n", lost,
                duplicated, misattributed, fig.falseCompletions);
    EXPECT_EQ(fig.falseCompletions, 0);
    std::printf("[figures] answer round trip (POST /api/answer -> durable -> acknowledged, "
                "incl. retries over restarts): median %.2f ms, p95 %.2f ms, p99 %.2f ms, max "
                "%.2f ms\n",
                percentile(fig.answerMs, 0.5), percentile(fig.answerMs, 0.95),
                percentile(fig.answerMs, 0.99), percentile(fig.answerMs, 1.0));
    std::printf("[figures] answer round trip, answers sent while the server was up (%zu): "
                "median %.2f ms, p95 %.2f ms, p99 %.2f ms\n",
                fig.answerMsNoRetry.size(), percentile(fig.answerMsNoRetry, 0.5),
                percentile(fig.answerMsNoRetry, 0.95), percentile(fig.answerMsNoRetry, 0.99));
    std::printf("[figures] clip delivery (%zu clips of %ju bytes): median %.2f ms, p99 %.2f ms\n",
                fig.clipMs.size(),
                static_cast<std::uintmax_t>(fs::file_size(fs::directory_iterator(f.clips)->path())),
                percentile(fig.clipMs, 0.5), percentile(fig.clipMs, 0.99));
    std::printf("[figures] server memory: idle %ld kB, %d sessions open %ld kB: %.1f kB per "
                "participant\n",
                rssIdle, plan.concurrency, rssOpen,
                static_cast<double>(rssOpen - rssIdle) / plan.concurrency);
}

std::string webProtocolWithRepetitions(int repetitions) {
    std::string protocol = webProtocol();
    protocol.replace(protocol.find("repetitions = 2"), 15,
                     "repetitions = " + std::to_string(repetitions));
    return protocol;
}

#ifndef UNDERFOOT_WEB_SOAK
TEST(WebLoad, FiftyParticipantsDisconnectsDuplicatesReloadsAndOneSigkill) {
    runLoad({webProtocolWithRepetitions(2), 50, 50, 7, 1});
}
#else
TEST(WebLoadSoak, FiftyParticipantsLongerTestsThreeSigkills) {
    runLoad({webProtocolWithRepetitions(6), 50, 50, 19, 3});
}

// The shipped wading listening test (6 clips x 4 scale blocks = 24 trials), 200 participants
// of whom 64 take it at the same time, two SIGKILLs.
TEST(WebLoadSoak, TwoHundredWadingListeningParticipantsSixtyFourAtATimeTwoSigkills) {
    std::ifstream in(experiment::shippedProtocolDir() + "/wading_listening.toml");
    std::stringstream text;
    text << in.rdbuf();
    ASSERT_FALSE(text.str().empty());
    runLoad({text.str(), 200, 64, 24, 2});
}
#endif

} // namespace
} // namespace underfoot::web::test
