// SPDX-License-Identifier: GPL-3.0-or-later
// Crash test for real: a child process answers trials (printing "ack CODE TRIAL" after each
// commit) and is killed with SIGKILL at random points, many times. Every acknowledged answer
// must be in the database, answered trials must form a prefix of each plan, and the next run
// must resume at the first unanswered trial.
#include "TestSupport.h"
#include "experiment/Random.h"
#include "experiment/Store.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <map>
#include <optional>
#include <poll.h>
#include <set>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {

struct ChildRun {
    std::vector<std::pair<std::string, int>> acks;
    bool finished = false; // exited by itself with status 0
};

/// Runs the child, kills it after `killAfterMs` (negative: let it finish) and returns the
/// complete ack lines it printed.
/// With `fromFirstAck`, the delay counts from the first ack (kills land among commits even on a
/// slow machine); otherwise from the start (kills also land in start-up and registration).
ChildRun runChild(const std::string& study, const std::string& matrix, int participants,
                  int killAfterMs, bool fromFirstAck = false) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
    const std::string count = std::to_string(participants);
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
        ::dup2(fds[1], STDOUT_FILENO);
        ::close(fds[0]);
        ::close(fds[1]);
        const char* argv[] = {UNDERFOOT_SESSION_CHILD, study.c_str(), matrix.c_str(), count.c_str(),
                              nullptr};
        ::execv(UNDERFOOT_SESSION_CHILD, const_cast<char* const*>(argv));
        ::_exit(127);
    }
    ::close(fds[1]);
    std::string output;
    using Clock = std::chrono::steady_clock;
    const auto spawned = Clock::now();
    std::optional<Clock::time_point> start;
    if (!fromFirstAck) start = spawned;
    bool killed = false;
    char buffer[4096];
    while (true) {
        int timeoutMs = 1000;
        if (killAfterMs >= 0 && !killed) {
            if (!start && output.find('\n') != std::string::npos) start = Clock::now();
            const auto since = Clock::now() - (start ? *start : spawned);
            const auto elapsed = std::chrono::duration_cast<std::chrono::milliseconds>(since);
            // Safety net: a child that never acknowledges anything is killed after 60 s.
            const long limit = start ? killAfterMs : 60000;
            timeoutMs = static_cast<int>(std::max<long>(0, limit - elapsed.count()));
            if (timeoutMs == 0) {
                ::kill(pid, SIGKILL);
                killed = true;
                timeoutMs = 1000;
            }
            if (!start) timeoutMs = std::min(timeoutMs, 5);
        }
        pollfd p{fds[0], POLLIN, 0};
        const int ready = ::poll(&p, 1, timeoutMs);
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) continue; // deadline reached: kill on the next turn
        const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
        if (n <= 0) break; // EOF: the child is gone
        output.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(fds[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ChildRun run;
    run.finished = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    std::istringstream lines(output);
    std::string line;
    while (std::getline(lines, line)) {
        if (lines.eof()) break; // a last line without '\n' was cut by the kill
        std::istringstream words(line);
        std::string word, code;
        int index = -1;
        if (words >> word >> code >> index && word == "ack") run.acks.emplace_back(code, index);
    }
    return run;
}

} // namespace

TEST(ExperimentCrash, SigkillAtRandomPointsLosesNoAcknowledgedAnswer) {
    TempDir dir;
    const std::string study = dir.file("crash.db");
    {
        StudyStore::create(study, loadProtocol(shipped("tvcg2011_exp1.toml")),
                           {"CR", "ci", 4, "t"});
    }
    const std::string matrix = dataFile("tvcg2011_exp1_confusion.csv");
    const int participants = 1000; // never reached while killing
    // At least 40 kills, and more (up to 200) while fewer than 51 answers were acknowledged: on
    // a loaded machine (a sanitizer build beside other work) the timed kills land earlier in
    // each run, so the count of kills adapts instead of the timing.
    const int minKills = 40, maxKills = 200, enoughAcks = 50;
    Rng rng(20261121);
    std::set<std::pair<std::string, int>> acknowledged;
    std::map<std::string, int> expectedResume; // participant -> first unanswered after a kill
    int totalAcks = 0;
    int kills = 0;
    for (int k = 0; k < minKills || (totalAcks <= enoughAcks && k < maxKills); ++k, ++kills) {
        // Alternate: kills timed from the start (start-up, registration, first commits) and
        // kills timed from the first commit (in the middle of sessions).
        const bool fromFirstAck = k % 2 == 1;
        const int killAfterMs = static_cast<int>(rng.below(fromFirstAck ? 120 : 250));
        const ChildRun run = runChild(study, matrix, participants, killAfterMs, fromFirstAck);
        ASSERT_FALSE(run.finished);
        // The run resumes each unfinished participant at its first unanswered trial.
        std::set<std::string> seen;
        for (const auto& [code, index] : run.acks) {
            if (seen.insert(code).second && expectedResume.count(code)) {
                EXPECT_EQ(index, expectedResume[code]) << "kill " << k << " " << code;
            }
            acknowledged.insert({code, index});
        }
        totalAcks += static_cast<int>(run.acks.size());
        StudyStore store = StudyStore::open(study);
        for (const auto& [code, index] : acknowledged)
            ASSERT_TRUE(store.trial(code, index).answered)
                << "acknowledged answer lost: " << code << " trial " << index << " (kill " << k
                << ")";
        expectedResume.clear();
        for (const auto& p : store.participants()) {
            const auto trials = store.trials(p.code);
            const auto first = store.firstUnanswered(p.code);
            const int prefix = first ? *first : static_cast<int>(trials.size());
            for (const auto& t : trials)
                ASSERT_EQ(t.answered, t.index < prefix) << p.code << " trial " << t.index;
            if (first) expectedResume[p.code] = *first;
        }
    }
    EXPECT_GT(totalAcks, enoughAcks)
        << "the kills came too early to test anything (" << kills << " kills)";
    RecordProperty("acknowledged_answers", totalAcks);
    std::printf("crash test: %d kills, %d acknowledged answers, all present\n", kills, totalAcks);
    // Finally let it run: the interrupted participant finishes, then one more is completed.
    StudyStore before = StudyStore::open(study);
    const int registered = static_cast<int>(before.participants().size());
    const ChildRun last = runChild(study, matrix, registered + 1, -1);
    EXPECT_TRUE(last.finished);
    StudyStore after = StudyStore::open(study);
    for (const auto& p : after.participants()) {
        EXPECT_FALSE(after.firstUnanswered(p.code)) << p.code;
        EXPECT_EQ(p.status, ParticipantStatus::Completed) << p.code;
    }
    for (const auto& [code, index] : acknowledged) EXPECT_TRUE(after.trial(code, index).answered);
}

// The SIGKILL soak (label soak; run by ctest -L soak, not in the default run):
// hundreds of kills at random moments (start-up, registration, inside commits, mid-session),
// then every acknowledged answer must be present once and as typed: answered exactly once in
// the journal (no "answer_changed"), the stored answer equal to the journaled one.
// UNDERFOOT_SIGKILL_SOAK_KILLS sets the number of kills (default 300).
TEST(ExperimentCrashSoak, DISABLED_HundredsOfSigkillsLoseAndDuplicateNothing) {
    TempDir dir;
    const std::string study = dir.file("soak.db");
    {
        StudyStore::create(study, loadProtocol(shipped("tvcg2011_exp1.toml")),
                           {"SK", "ci", 16, "t"});
    }
    const std::string matrix = dataFile("tvcg2011_exp1_confusion.csv");
    const char* env = std::getenv("UNDERFOOT_SIGKILL_SOAK_KILLS");
    const int kills = env ? std::max(1, std::atoi(env)) : 300;
    Rng rng(20261125);
    std::set<std::pair<std::string, int>> acknowledged;
    int totalAcks = 0, duplicated = 0, lost = 0, changed = 0;
    for (int k = 0; k < kills; ++k) {
        const bool fromFirstAck = k % 3 != 0;
        const int killAfterMs = static_cast<int>(rng.below(fromFirstAck ? 150 : 300));
        const ChildRun run = runChild(study, matrix, 100000, killAfterMs, fromFirstAck);
        for (const auto& a : run.acks) acknowledged.insert(a);
        totalAcks += static_cast<int>(run.acks.size());
    }
    StudyStore store = StudyStore::open(study);
    std::map<std::pair<std::string, int>, std::vector<std::string>> journaled;
    for (const auto& e : store.events()) {
        if (e.kind == "answer_changed") ++changed;
        if (e.kind == "answered" && e.trialIndex)
            journaled[{e.participant, *e.trialIndex}].push_back(e.detail);
    }
    for (const auto& key : acknowledged) {
        const TrialRecord t = store.trial(key.first, key.second);
        if (!t.answered) {
            ++lost;
            ADD_FAILURE() << "acknowledged answer lost: " << key.first << " trial " << key.second;
            continue;
        }
        const auto& j = journaled[key];
        if (j.size() != 1) {
            ++duplicated;
            ADD_FAILURE() << key.first << " trial " << key.second << " answered " << j.size()
                          << " times in the journal";
            continue;
        }
        EXPECT_NE(j[0].find("\"answer\":\"" + t.answer.answer + "\""), std::string::npos)
            << key.first << " trial " << key.second << ": stored answer '" << t.answer.answer
            << "' differs from the journaled " << j[0];
    }
    EXPECT_EQ(changed, 0);
    RecordProperty("kills", kills);
    RecordProperty("acknowledged_answers", totalAcks);
    std::printf("SIGKILL soak: %d kills, %d acknowledged answers (%zu distinct), %d lost, %d "
                "duplicated, %d changed\n",
                kills, totalAcks, acknowledged.size(), lost, duplicated, changed);
}
