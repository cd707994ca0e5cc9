// SPDX-License-Identifier: GPL-3.0-or-later
// Experiment runner speed, against these goals:
//   - a durable answer commit (WAL, synchronous=FULL, own transaction): median < 10 ms;
//   - opening a study with 200 participants and computing its plan summary: < 200 ms.
// Run: build/tests/bench/bench_experiment   (study files go to $TMPDIR; same disk matters)
#include "experiment/Progress.h"
#include "experiment/Protocol.h"
#include "experiment/Session.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <unistd.h>

using namespace underfoot::experiment;

namespace {

std::string tempStudy(const std::string& name) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("underfoot-bench-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto path = dir / name;
    std::filesystem::remove(path);
    std::filesystem::remove(path.string() + "-wal");
    std::filesystem::remove(path.string() + "-shm");
    return path.string();
}

std::string shipped(const std::string& name) {
    return shippedProtocolDir() + "/" + name;
}

void BM_DurableAnswerCommit(benchmark::State& state) {
    const std::string path = tempStudy("commit.db");
    StudyStore store = StudyStore::create(path, loadProtocol(shipped("tvcg2011_exp2.toml")),
                                          {"BENCH", "bench", 1, "bench"});
    std::vector<double> samplesMs;
    int participant = 0;
    std::string code;
    std::vector<TrialRecord> trials;
    std::size_t next = 0;
    int session = 0;
    for (auto _ : state) {
        if (next >= trials.size()) {
            code = fmt::format("B{:04}", participant++);
            store.registerParticipant({code, {}, "", "", "", {}, ""});
            trials = store.trials(code);
            session = store.startSession(code, {"bench", "none", "none", "bench"});
            next = 0;
        }
        const TrialRecord& t = trials[next++];
        store.markTrialStarted(code, t.index, session, t.plannedSeed, std::nullopt);
        TrialAnswer a;
        a.answer = t.stimulus.surface;
        a.ratings = {{"realism", 5}, {"quality", 4}};
        if (store.protocol().questions.asksSoundscape(store.participant(code).groupId))
            a.soundscapeAnswer = "forest";
        const auto start = std::chrono::steady_clock::now();
        store.commitAnswer(code, t.index, a, 3.0);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(seconds);
        samplesMs.push_back(seconds * 1e3);
    }
    std::sort(samplesMs.begin(), samplesMs.end());
    if (!samplesMs.empty()) {
        state.counters["median_ms"] = samplesMs[samplesMs.size() / 2];
        state.counters["p95_ms"] = samplesMs[samplesMs.size() * 95 / 100];
    }
    std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}
BENCHMARK(BM_DurableAnswerCommit)->UseManualTime()->Iterations(300)->Unit(benchmark::kMillisecond);

void BM_OpenStudyWith200ParticipantsAndSummarize(benchmark::State& state) {
    const std::string path = tempStudy("open200.db");
    {
        StudyStore store = StudyStore::create(path, loadProtocol(shipped("tvcg2011_exp1.toml")),
                                              {"BENCH", "bench", 1, "bench"});
        MatrixByGroup m;
        m[""] = loadConfusionMatrix(std::string(UNDERFOOT_SOURCE_DIR) +
                                    "/tests/experiment/data/tvcg2011_exp1_confusion.csv");
        // 200 participants: 150 completed sessions (26 answered trials each), 50 registered.
        simulateStudy(store, m, 150, {});
        for (int i = 0; i < 50; ++i)
            store.registerParticipant({fmt::format("R{:03}", i), {}, "", "", "", {}, ""});
    }
    std::vector<double> samplesMs;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        StudyStore store = StudyStore::open(path);
        const StudyProgress progress = studyProgress(store);
        benchmark::DoNotOptimize(progress.plan.groups.size());
        if (progress.participants.size() != 200) state.SkipWithError("expected 200 participants");
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(seconds);
        samplesMs.push_back(seconds * 1e3);
    }
    std::sort(samplesMs.begin(), samplesMs.end());
    if (!samplesMs.empty()) state.counters["median_ms"] = samplesMs[samplesMs.size() / 2];
    std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}
BENCHMARK(BM_OpenStudyWith200ParticipantsAndSummarize)
    ->UseManualTime()
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
