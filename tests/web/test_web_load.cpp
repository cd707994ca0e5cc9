// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot serve` as a separate process under load and faults, on loopback: simulated
// participants at once (threads with the httplib client) with lost replies, duplicate
// submissions and server SIGKILLs + restarts. Checked: every acknowledged answer is in the
// study, no answer is stored twice, every participant resumes and finishes; SIGTERM stops
// cleanly. The figures (answer round trip, clip delivery, memory per participant) are printed
// (docs/web.md quotes them with the command); they are never pass/fail.
#include "WebTestSupport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <map>
#include <mutex>
#include <random>
#include <sys/wait.h>

namespace underfoot::web::test {
namespace {

using Clock = std::chrono::steady_clock;

/// A child `underfoot serve` process.
class ServeProcess {
  public:
    ServeProcess(const StudyFixture& f, int port) {
        int fds[2];
        if (::pipe(fds) != 0) throw std::runtime_error("pipe");
        const std::string p = std::to_string(port); // nothing but exec after fork (threads)
        pid_ = ::fork();
        if (pid_ == 0) {
            ::dup2(fds[1], 1);
            ::close(fds[0]);
            ::close(fds[1]);
            ::execl(UNDERFOOT_CLI, UNDERFOOT_CLI, "serve", "--study", f.study.c_str(), "--clips",
                    f.clips.c_str(), "--port", p.c_str(), "--rate", "1000", nullptr);
            ::_exit(127);
        }
        ::close(fds[1]);
        out_ = ::fdopen(fds[0], "r");
        char line[1024];
        // "underfoot serve: study ... listening on http://127.0.0.1:PORT/ ..."
        while (std::fgets(line, sizeof line, out_)) {
            const std::string l = line;
            const auto at = l.find("listening on http://127.0.0.1:");
            if (at == std::string::npos) continue;
            port_ = std::stoi(l.substr(at + std::string("listening on http://127.0.0.1:").size()));
            break;
        }
        if (port_ <= 0) throw std::runtime_error("underfoot serve did not print where it listens");
    }
    ~ServeProcess() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        if (out_) std::fclose(out_);
    }
    int port() const { return port_; }
    pid_t pid() const { return pid_; }
    void kill9() {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
    }
    /// SIGTERM; returns the exit status and the rest of the output.
    std::pair<int, std::string> terminate() {
        ::kill(pid_, SIGTERM);
        std::string rest;
        char line[1024];
        while (std::fgets(line, sizeof line, out_)) rest += line;
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, rest};
    }
    /// Resident memory of the server (kB).
    long rssKb() const {
        std::FILE* f = std::fopen(("/proc/" + std::to_string(pid_) + "/status").c_str(), "r");
        if (!f) return -1;
        char line[256];
        long kb = -1;
        while (std::fgets(line, sizeof line, f))
            if (std::sscanf(line, "VmRSS: %ld kB", &kb) == 1) break;
        std::fclose(f);
        return kb;
    }

  private:
    pid_t pid_ = -1;
    std::FILE* out_ = nullptr;
    int port_ = -1;
};

struct Figures {
    std::mutex mutex;
    std::vector<double> answerMs, answerMsNoRetry, clipMs;
    int lostReplies = 0, duplicates = 0, retries = 0;
};

/// Runs one simulated participant to the completion code. Returns acknowledged answers
/// (trial -> realism rating sent).
std::map<int, int> participate(const std::atomic<int>& port, const std::string& token,
                               std::uint64_t seed, Figures& fig, std::atomic<int>& acked,
                               const std::atomic<bool>& holdAfterConsent) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::map<int, int> sent;
    // Retries a request until the server answers (down during a restart: status 0 or 5xx).
    int lastRetries = 0; // retries of the last call
    auto call = [&](auto&& request) {
        for (int i = 0; i < 600; ++i) {
            lastRetries = i;
            ApiClient c(port.load(), token);
            Reply r = request(c);
            if (r.status != 0 && r.status < 500 && r.status != 429) return r;
            {
                std::lock_guard lock(fig.mutex);
                ++fig.retries;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        throw std::runtime_error("the server did not come back within 30 s");
    };
    Reply r = call([&](ApiClient& c) {
        return c.post("/api/consent",
                      {{"consent", true}, {"fields", {{"listening_device", "headphones"}}}});
    });
    if (r.status != 200) throw std::runtime_error("consent: " + r.raw);
    while (holdAfterConsent.load()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    call([&](ApiClient& c) { return c.post("/api/client", {{"sampleRate", 44100}}); });
    json state = call([&](ApiClient& c) {
                     return c.post("/api/screening", {{"correct", 6}, {"total", 6}});
                 }).body;
    for (int guard = 0; guard < 200 && state["phase"] != "finished"; ++guard) {
        if (state["phase"] == "break") {
            state = call([&](ApiClient& c) { return c.post("/api/break", json::object()); }).body;
            continue;
        }
        if (!state.contains("trial")) throw std::runtime_error("unexpected state " + state.dump());
        const int trial = state["trial"]["index"];
        const auto t0 = Clock::now();
        const Reply clip =
            call([&](ApiClient& c) { return c.get("/api/clip/" + std::to_string(trial)); });
        const double clipMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        const std::string playId = "p" + std::to_string(rng());
        const Reply p = call([&](ApiClient& c) {
            return c.post("/api/present", {{"trial", trial}, {"attempt", playId}});
        });
        if (p.status == 409 || clip.status == 409) { // a restart moved on; ask again
            state = call([&](ApiClient& c) { return c.get("/api/state"); }).body;
            continue;
        }
        json a = validAnswer(state, "a" + std::to_string(rng()));
        const int rating = 1 + static_cast<int>(rng() % 7);
        a["ratings"]["realism"] = rating;
        std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(u(rng) * 20)));
        if (u(rng) < 0.1) { // a lost reply: sent, the connection drops before the answer
            std::lock_guard lock(fig.mutex);
            ++fig.lostReplies;
            ApiClient c(port.load(), token);
            c.post("/api/answer", a); // reply ignored, as if the network lost it
        }
        const auto a0 = Clock::now();
        Reply ack = call([&](ApiClient& c) { return c.post("/api/answer", a); });
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - a0).count();
        const bool retried = lastRetries > 0;
        if (ack.status == 409) { // moved on meanwhile (should not happen with one page)
            throw std::runtime_error("answer refused: " + ack.raw);
        }
        if (ack.status != 200) throw std::runtime_error("answer: " + ack.raw);
        if (u(rng) < 0.1) { // a duplicate submission (double click, retry after a timeout)
            const Reply dup = call([&](ApiClient& c) { return c.post("/api/answer", a); });
            if (dup.status != 200 || dup.body["duplicate"] != true)
                throw std::runtime_error("duplicate: " + dup.raw);
            std::lock_guard lock(fig.mutex);
            ++fig.duplicates;
        }
        sent[trial] = rating;
        ++acked;
        {
            std::lock_guard lock(fig.mutex);
            fig.answerMs.push_back(ms);
            if (!retried) fig.answerMsNoRetry.push_back(ms);
            if (clip.status == 200) fig.clipMs.push_back(clipMs);
        }
        state = ack.body;
    }
    if (state["phase"] != "finished") throw std::runtime_error("not finished: " + state.dump());
    return sent;
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const auto i = static_cast<std::size_t>(
        std::min<double>(static_cast<double>(v.size() - 1), p * static_cast<double>(v.size())));
    return v[i];
}

void runLoad(int participants, int repetitions, int kills) {
    std::string protocol = webProtocol();
    protocol.replace(protocol.find("repetitions = 2"), 15,
                     "repetitions = " + std::to_string(repetitions));
    StudyFixture f(participants, protocol);
    auto server = std::make_unique<ServeProcess>(f, 0);
    std::atomic<int> port{server->port()};
    const long rssIdle = server->rssKb();
    Figures fig;
    std::atomic<int> acked{0};
    std::atomic<bool> hold{true};
    std::vector<std::map<int, int>> sent(static_cast<std::size_t>(participants));
    std::vector<std::string> errors(static_cast<std::size_t>(participants));
    std::vector<std::thread> threads;
    for (int i = 0; i < participants; ++i)
        threads.emplace_back([&, i] {
            try {
                sent[i] = participate(port, f.links[i].token, 1000 + i, fig, acked, hold);
            } catch (const std::exception& e) {
                errors[i] = e.what();
            }
        });
    // Memory with every participant's session open (all consented, held before the trials).
    {
        experiment::StudyStore store = experiment::StudyStore::open(f.study);
        const auto deadline = Clock::now() + std::chrono::seconds(60);
        while (Clock::now() < deadline &&
               static_cast<int>(store.participants().size()) < participants)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const long rssOpen = server->rssKb();
    hold = false;
    const int total = participants * (1 + 3 * repetitions);
    for (int k = 1; k <= kills; ++k) {
        while (acked.load() < total * k / (kills + 1))
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        server->kill9();
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        server = std::make_unique<ServeProcess>(f, port.load()); // the same port, as in a restart
    }
    for (auto& t : threads) t.join();
    for (int i = 0; i < participants; ++i) EXPECT_EQ(errors[i], "") << "participant " << i;
    const auto [exitCode, output] = server->terminate();
    EXPECT_EQ(exitCode, 0);
    EXPECT_NE(output.find("stopped (SIGTERM)"), std::string::npos) << output;

    // 0 lost, 0 duplicated, every participant finished.
    experiment::StudyStore store = experiment::StudyStore::open(f.study);
    std::map<std::pair<std::string, int>, int> answeredEvents;
    int changed = 0;
    for (const auto& e : store.events()) {
        if (e.kind == "answered" && e.trialIndex) ++answeredEvents[{e.participant, *e.trialIndex}];
        changed += e.kind == "answer_changed";
    }
    EXPECT_EQ(changed, 0);
    int lost = 0, duplicated = 0, stored = 0;
    for (int i = 0; i < participants; ++i) {
        const std::string code = f.links[i].participantCode;
        EXPECT_EQ(store.participant(code).status, experiment::ParticipantStatus::Completed) << code;
        for (const auto& t : store.trials(code)) {
            stored += t.answered;
            const auto it = sent[i].find(t.index);
            if (it != sent[i].end() &&
                (!t.answered || t.answer.ratings.at("realism") != it->second))
                ++lost;
            const auto n = answeredEvents[{code, t.index}];
            if (n > 1) ++duplicated;
        }
    }
    EXPECT_EQ(lost, 0);
    EXPECT_EQ(duplicated, 0);
    EXPECT_EQ(stored, total);
    std::printf("[figures] participants %d, answers %d (acknowledged %d), server SIGKILLs %d, "
                "lost replies %d, duplicate submissions %d, client retries %d\n",
                participants, stored, acked.load(), kills, fig.lostReplies, fig.duplicates,
                fig.retries);
    std::printf("[figures] lost %d, duplicated %d\n", lost, duplicated);
    std::printf("[figures] answer round trip (POST /api/answer -> durable -> acknowledged, "
                "incl. retries over restarts): median %.2f ms, p99 %.2f ms, max %.2f ms\n",
                percentile(fig.answerMs, 0.5), percentile(fig.answerMs, 0.99),
                percentile(fig.answerMs, 1.0));
    std::printf("[figures] answer round trip, answers sent while the server was up (%zu): "
                "median %.2f ms, p99 %.2f ms\n",
                fig.answerMsNoRetry.size(), percentile(fig.answerMsNoRetry, 0.5),
                percentile(fig.answerMsNoRetry, 0.99));
    std::printf("[figures] clip delivery (%zu clips of %ju bytes): median %.2f ms, p99 %.2f ms\n",
                fig.clipMs.size(), static_cast<std::uintmax_t>(fs::file_size(f.clips + "/WD.wav")),
                percentile(fig.clipMs, 0.5), percentile(fig.clipMs, 0.99));
    std::printf("[figures] server memory: idle %ld kB, %d sessions open %ld kB: %.1f kB per "
                "participant\n",
                rssIdle, participants, rssOpen,
                static_cast<double>(rssOpen - rssIdle) / participants);
}

#ifndef UNDERFOOT_WEB_SOAK
TEST(WebLoad, FiftyParticipantsDisconnectsDuplicatesAndOneSigkill) {
    runLoad(50, 2, 1);
}
#else
TEST(WebLoadSoak, FiftyParticipantsLongerTestsThreeSigkills) {
    runLoad(50, 6, 3);
}
#endif

} // namespace
} // namespace underfoot::web::test
