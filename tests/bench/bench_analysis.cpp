// SPDX-License-Identifier: GPL-3.0-or-later
// Speed of the analysis: a full study (200 participants x 26 trials = 5,200 trials, two groups)
// from CSV text to every table, test and export, and the exact tests at their largest exact n;
// the logistic mixed model (60 participants x 16 trials, nAGQ = 10) and power curves: an
// analysis-only one and the tvcg2011_exp2 curve of `underfoot protocol power` (its simulator).
//   build-analysis/tests/bench/bench_analysis
#include "analysis/io/TrialCsv.h"
#include "analysis/power/Power.h"
#include "analysis/report/Export.h"
#include "analysis/stats/MixedModels.h"
#include "analysis/stats/Tests.h"
#include "analysis/tables/Tables.h"
#include "app/cli/PowerSimulators.h"
#include "engine/dsp/Random.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

using namespace underfoot;
using namespace underfoot::analysis;

namespace {

/// 200 participants in two groups, 13 stimuli (TVCG exp. 1) x 2 repetitions each; answers are
/// right with a stimulus-dependent probability, otherwise a random surface or "I don't know";
/// ratings 1..7. Seeded, so every run analyses the same data.
std::vector<TrialRecord> syntheticStudy() {
    const std::vector<std::string> stimuli{"beach_sand",  "gravel",      "dirt_pebbles",
                                           "deep_snow",   "high_grass",  "forest_underbrush",
                                           "dry_leaves",  "wood",        "creaking_wood",
                                           "metal",       "wood_reverb", "creaking_wood_reverb",
                                           "metal_reverb"};
    const auto answers = defaultAnswerList();
    engine::Random rng(20110901);
    std::vector<TrialRecord> trials;
    for (int p = 0; p < 200; ++p) {
        const std::string group = p % 2 == 0 ? "audio" : "audiohaptic";
        int index = 0;
        for (int rep = 1; rep <= 2; ++rep)
            for (std::size_t s = 0; s < stimuli.size(); ++s) {
                TrialRecord t;
                t.participant = "P" + std::to_string(p);
                t.group = group;
                t.trialIndex = index++;
                t.stimulusId = stimuli[s];
                t.surfaceId = stimuli[s];
                t.repetition = rep;
                const double pCorrect =
                    0.3 + 0.05 * static_cast<double>(s % 10) + (group == "audiohaptic" ? 0.1 : 0.0);
                const double u = rng.uniform();
                if (u < pCorrect)
                    t.answerId = baseSurfaceId(stimuli[s]);
                else if (u < pCorrect + 0.08)
                    t.answerId = "dont_know";
                else
                    t.answerId = answers.options[static_cast<std::size_t>(rng.uniform() * 15.0)].id;
                t.realism = std::floor(1 + 7 * rng.uniform());
                t.quality = std::floor(1 + 7 * rng.uniform());
                t.responseTimeSeconds = 2 + 10 * rng.uniform();
                trials.push_back(std::move(t));
            }
    }
    return trials;
}

void fullAnalysis(benchmark::State& state) {
    const std::string csvText = formatTrialCsv(syntheticStudy());
    AnalysisOptions options;
    options.byGroup = true;
    for (auto _ : state) {
        const auto trials = parseTrialCsv(csvText, "synthetic.csv");
        const auto report = analyzeTrials(trials, options);
        std::size_t bytes = 0;
        for (auto format :
             {ReportFormat::Csv, ReportFormat::Latex, ReportFormat::Markdown, ReportFormat::Html})
            bytes += renderReport(report, format).size();
        benchmark::DoNotOptimize(bytes);
        state.counters["comparisons"] = static_cast<double>(report.comparisons.size());
    }
    state.counters["trials"] = 5200;
}
BENCHMARK(fullAnalysis)->Unit(benchmark::kMillisecond);

void tablesAndTestsOnly(benchmark::State& state) {
    const auto trials = syntheticStudy();
    AnalysisOptions options;
    options.byGroup = true;
    for (auto _ : state) benchmark::DoNotOptimize(analyzeTrials(trials, options));
}
BENCHMARK(tablesAndTestsOnly)->Unit(benchmark::kMillisecond);

std::vector<double> values(int n, std::uint64_t seed) {
    engine::Random rng(seed);
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(rng.gaussian());
    return v;
}

void signedRankExactN49(benchmark::State& state) {
    const auto x = values(49, 1);
    for (auto _ : state) benchmark::DoNotOptimize(wilcoxonTest(x).p);
}
BENCHMARK(signedRankExactN49)->Unit(benchmark::kMicrosecond);

void rankSumExact49x49(benchmark::State& state) {
    const auto x = values(49, 2), y = values(49, 3);
    for (auto _ : state) benchmark::DoNotOptimize(wilcoxonTest(x, y).p);
}
BENCHMARK(rankSumExact49x49)->Unit(benchmark::kMicrosecond);

void spearmanExactEnumerationN9(benchmark::State& state) {
    const auto x = values(9, 4), y = values(9, 5);
    for (auto _ : state) benchmark::DoNotOptimize(spearmanTest(x, y).p);
}
BENCHMARK(spearmanExactEnumerationN9)->Unit(benchmark::kMicrosecond);

void spearmanEdgeworthN1290(benchmark::State& state) {
    const auto x = values(1290, 6), y = values(1290, 7);
    for (auto _ : state) benchmark::DoNotOptimize(spearmanTest(x, y).p);
}
BENCHMARK(spearmanEdgeworthN1290)->Unit(benchmark::kMicrosecond);

void fisher2x2WithIntervalN1000(benchmark::State& state) {
    const CountTable table{{310, 190}, {240, 260}};
    for (auto _ : state) benchmark::DoNotOptimize(fisherTest(table).confInt);
}
BENCHMARK(fisher2x2WithIntervalN1000)->Unit(benchmark::kMicrosecond);

void shapiroN5000(benchmark::State& state) {
    const auto x = values(5000, 8);
    for (auto _ : state) benchmark::DoNotOptimize(shapiroTest(x).p);
}
BENCHMARK(shapiroN5000)->Unit(benchmark::kMicrosecond);

/// 60 participants x 16 trials (4 surfaces x 2 conditions x 2 repetitions, condition within or
/// between participants), random intercepts SD 1, seeded.
MixedModelData glmmData(bool within) {
    engine::Random rng(20261125);
    MixedModelData d;
    const char* surfaces[] = {"s1", "s2", "s3", "s4"};
    for (int p = 0; p < 60; ++p) {
        const double b = rng.gaussian();
        for (int t = 0; t < 16; ++t) {
            const int condition = within ? t % 2 : p % 2;
            const int surface = (t / 2) % 4;
            const double eta = 0.4 + 0.7 * condition - 0.3 * surface + b;
            d.y.push_back(rng.uniform() < 1 / (1 + std::exp(-eta)) ? 1 : 0);
            d.condition.push_back(condition ? "b" : "a");
            d.participant.push_back("p" + std::to_string(p));
            d.surface.push_back(surfaces[surface]);
        }
    }
    return d;
}

void glmm60x16Agq10Between(benchmark::State& state) {
    const auto d = glmmData(false);
    for (auto _ : state) benchmark::DoNotOptimize(fitLogisticMixedModel(d, 10).logLik);
}
BENCHMARK(glmm60x16Agq10Between)->Unit(benchmark::kMillisecond);

void glmm60x16Agq10Within(benchmark::State& state) {
    const auto d = glmmData(true);
    for (auto _ : state) benchmark::DoNotOptimize(fitLogisticMixedModel(d, 10).logLik);
}
BENCHMARK(glmm60x16Agq10Within)->Unit(benchmark::kMillisecond);

void lmm60x16(benchmark::State& state) {
    auto d = glmmData(true);
    engine::Random rng(7);
    for (auto& y : d.y) y = 4 + y + rng.gaussian();
    for (auto _ : state) benchmark::DoNotOptimize(fitLinearMixedModel(d).logLik);
}
BENCHMARK(lmm60x16)->Unit(benchmark::kMillisecond);

/// Power curve: 6 group sizes (10..60) x 2,000 simulated studies of two groups, 10 answers per
/// participant over 5 surfaces, participant SD 0.8; chi-square and glmer (Laplace) LRT each, on
/// all cores. (`underfoot protocol power` adds the protocol's plans and synthetic participants.)
void powerCurve6x2000(benchmark::State& state) {
    const StudySimulator sim = [](int perGroup, std::uint64_t seed) {
        engine::Random rng(seed);
        std::vector<SimulatedAnswer> out;
        for (int g = 0; g < 2; ++g)
            for (int i = 0; i < perGroup; ++i) {
                const double b = 0.8 * rng.gaussian();
                for (int k = 0; k < 10; ++k) {
                    const double eta = 0.8 + 0.4 * g - 0.2 * (k % 5) + b;
                    out.push_back(
                        {g * perGroup + i, g, k % 5, rng.uniform() < 1 / (1 + std::exp(-eta))});
                }
            }
        return out;
    };
    PowerOptions o;
    o.simulations = 2000;
    for (auto _ : state) {
        const auto curve = simulatePower(sim, 2, o);
        state.counters["smallest_mixed"] = curve.smallestMixed;
        state.counters["smallest_classic"] = curve.smallestClassic;
    }
}
BENCHMARK(powerCurve6x2000)->Unit(benchmark::kSecond)->Iterations(1);

/// The curve `underfoot protocol power protocols/tvcg2011_exp2.toml --threads 2` computes:
/// 6 group sizes (10..60) x 2,000 studies of the three groups, each participant's plan and
/// answers by the experiment layer's synthetic participant from the protocol's [simulation]
/// matrices (participant SD 0.8), chi-square and glmer (Laplace) LRT; two worker threads.
void powerCurveTvcg2011Exp2x2000(benchmark::State& state) {
    using experiment::Group;
    const experiment::Protocol p = experiment::loadProtocol(std::string(UNDERFOOT_SOURCE_DIR) +
                                                            "/protocols/tvcg2011_exp2.toml");
    const experiment::MatrixByGroup matrices = experiment::defaultMatrices(p);
    std::vector<const Group*> groups;
    std::vector<const experiment::ConfusionMatrix*> byGroup;
    for (const auto& g : p.groups) {
        groups.push_back(&g);
        byGroup.push_back(&matrices.at(g.id));
    }
    const auto sim = cli::power::betweenGroupsSimulator(p, groups, byGroup, 0.8);
    PowerOptions o;
    o.simulations = 2000;
    o.threads = 2;
    for (auto _ : state) {
        const auto curve = simulatePower(sim, 3, o);
        state.counters["smallest_mixed"] = curve.smallestMixed;
        state.counters["power_mixed_10"] = curve.points[0].mixed.power;
    }
}
BENCHMARK(powerCurveTvcg2011Exp2x2000)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
