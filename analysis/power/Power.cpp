// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/power/Power.h"

#include "analysis/stats/MixedModels.h"
#include "analysis/stats/OrdinalMixed.h"
#include "analysis/stats/Tests.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace underfoot::analysis {

namespace {

std::uint64_t splitmix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

struct Outcome {
    bool classic = false;
    bool mixed = false;
    bool mixedFailed = false;
    bool mixedSingular = false;
    bool ordinal = false; ///< ratings: the clmm's LRT
    bool ordinalFailed = false;
};

Outcome analyse(const std::vector<SimulatedAnswer>& answers, int groups,
                const PowerOptions& options) {
    Outcome o;
    CountTable table(static_cast<std::size_t>(groups), std::vector<double>(2, 0.0));
    for (const auto& a : answers) {
        if (a.group < 0 || a.group >= groups)
            throw std::invalid_argument(
                fmt::format("simulated answer of participant {}: group {} (0..{} expected)",
                            a.participant, a.group, groups - 1));
        table.at(static_cast<std::size_t>(a.group))[a.correct ? 0 : 1] += 1;
    }
    const auto chi =
        chisqTest(table, options.yates ? Continuity::Corrected : Continuity::Uncorrected);
    o.classic = chi.ok() && chi.p < options.alpha;
    if (!options.mixedModel) return o;
    // one binomial cell per (participant, group, surface): the same likelihood as the answers
    // one by one, built without strings
    const bool surface =
        options.withSurface && std::any_of(answers.begin(), answers.end(),
                                           [](const SimulatedAnswer& a) { return a.surface >= 0; });
    std::vector<std::array<int, 4>> keys; // participant, group, surface, correct
    keys.reserve(answers.size());
    for (const auto& a : answers)
        keys.push_back(
            {a.participant, a.group, surface ? std::max(a.surface, 0) : -1, a.correct ? 1 : 0});
    std::sort(keys.begin(), keys.end());
    std::vector<BinomialCell> cells;
    for (const auto& k : keys) {
        if (cells.empty() || cells.back().participant != k[0] || cells.back().condition != k[1] ||
            cells.back().surface != k[2])
            cells.push_back({k[0], k[1], k[2], 0.0, 0.0});
        cells.back().trials += 1;
        cells.back().successes += k[3];
    }
    const auto fit = logisticLikelihoodRatio(cells, options.nAGQ);
    if (!fit.error.empty() || std::isnan(fit.p)) {
        o.mixedFailed = true;
        return o;
    }
    o.mixed = fit.p < options.alpha;
    o.mixedSingular = fit.randomVariance < 1e-8;
    return o;
}

PowerEstimate estimate(double significant, double studies, double confLevel) {
    PowerEstimate e;
    e.significant = significant;
    e.studies = studies;
    e.power = studies > 0 ? significant / studies : 0.0;
    e.wilson = wilsonInterval(significant, studies, confLevel);
    const auto exact = binomTest(significant, studies, 0.5, Alternative::TwoSided, confLevel);
    if (exact.confInt) e.clopperPearson = *exact.confInt;
    return e;
}

} // namespace

std::uint64_t powerTaskSeed(std::uint64_t seed, int participantsPerGroup, int simulation) {
    std::uint64_t s = splitmix(seed);
    s = splitmix(s ^ static_cast<std::uint64_t>(participantsPerGroup));
    return splitmix(s ^ (static_cast<std::uint64_t>(simulation) << 20));
}

namespace {

/// Runs `analyse(size, seed)` for every group size and simulation on the worker threads (seeded
/// per task, so results do not depend on the number of threads) and fills the curve's points.
void runSimulations(const std::function<Outcome(int, std::uint64_t)>& analyseOne,
                    const PowerOptions& options, PowerCurve& curve) {
    if (options.simulations < 1) throw std::invalid_argument("--simulations must be at least 1");
    const std::size_t sizes = options.participantsPerGroup.size();
    const auto sims = static_cast<std::size_t>(options.simulations);
    const std::size_t total = sizes * sims;
    std::vector<Outcome> outcomes(total);
    std::atomic<std::size_t> next{0};
    std::mutex progressLock;
    std::size_t done = 0;
    std::exception_ptr failure;
    auto worker = [&] {
        for (;;) {
            const std::size_t task = next.fetch_add(1);
            if (task >= total) return;
            const int size = options.participantsPerGroup[task / sims];
            const int sim = static_cast<int>(task % sims);
            try {
                outcomes[task] = analyseOne(size, powerTaskSeed(options.seed, size, sim));
            } catch (...) {
                std::lock_guard lock(progressLock);
                if (!failure) failure = std::current_exception();
                next.store(total);
                return;
            }
            std::lock_guard lock(progressLock);
            ++done;
            if (options.progress) options.progress(done, total);
        }
    };
    unsigned threads = options.threads ? options.threads : std::thread::hardware_concurrency();
    threads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(total)));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    for (std::size_t s = 0; s < sizes; ++s) {
        PowerPoint p;
        p.participantsPerGroup = options.participantsPerGroup[s];
        double classic = 0, mixed = 0, ordinal = 0;
        for (std::size_t k = 0; k < sims; ++k) {
            const Outcome& o = outcomes[s * sims + k];
            classic += o.classic ? 1 : 0;
            mixed += o.mixed ? 1 : 0;
            ordinal += o.ordinal ? 1 : 0;
            p.mixedFailures += o.mixedFailed ? 1 : 0;
            p.mixedSingular += o.mixedSingular ? 1 : 0;
            p.ordinalFailures += o.ordinalFailed ? 1 : 0;
        }
        p.classic = estimate(classic, static_cast<double>(sims), options.confLevel);
        if (options.mixedModel)
            p.mixed = estimate(mixed, static_cast<double>(sims), options.confLevel);
        if (curve.ordinal)
            p.ordinal = estimate(ordinal, static_cast<double>(sims), options.confLevel);
        curve.points.push_back(p);
    }
    std::vector<PowerPoint> sorted = curve.points;
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
        return a.participantsPerGroup < b.participantsPerGroup;
    });
    for (const auto& p : sorted) {
        if (curve.smallestClassic < 0 && p.classic.power >= options.target)
            curve.smallestClassic = p.participantsPerGroup;
        if (options.mixedModel && curve.smallestMixed < 0 && p.mixed.power >= options.target)
            curve.smallestMixed = p.participantsPerGroup;
        if (curve.ordinal && curve.smallestOrdinal < 0 && p.ordinal.power >= options.target)
            curve.smallestOrdinal = p.participantsPerGroup;
    }
}

Outcome analyseRatings(const std::vector<SimulatedRating>& ratings, const PowerOptions& options) {
    Outcome o;
    // each participant's mean rating per condition (participants missing one are left out)
    std::map<int, std::array<std::pair<double, int>, 2>> cells;
    for (const auto& r : ratings) {
        if (r.condition < 0 || r.condition > 1)
            throw std::invalid_argument(
                fmt::format("simulated rating of participant {}: condition {} (0 or 1 expected)",
                            r.participant, r.condition));
        auto& c = cells[r.participant][static_cast<std::size_t>(r.condition)];
        c.first += r.value;
        c.second += 1;
    }
    std::vector<double> x, y;
    for (const auto& [participant, c] : cells)
        if (c[0].second > 0 && c[1].second > 0) {
            x.push_back(c[0].first / c[0].second);
            y.push_back(c[1].first / c[1].second);
        }
    TTestOptions t;
    t.pairing = Pairing::Paired;
    const auto paired = tTest(x, y, t);
    o.classic = paired.ok() && paired.p < options.alpha;
    if (!options.mixedModel) return o;
    MixedModelData d;
    d.y.reserve(ratings.size());
    for (const auto& r : ratings) {
        d.y.push_back(r.value);
        d.condition.push_back(r.condition == 0 ? "c0" : "c1");
        d.participant.push_back(fmt::format("p{:06d}", r.participant));
    }
    const auto fit = fitLinearMixedModel(d);
    const FixedEffect* effect = fit.ok() ? fit.coefficient("conditionc1") : nullptr;
    if (!effect || std::isnan(effect->p)) {
        o.mixedFailed = true;
    } else {
        o.mixed = effect->p < options.alpha;
        o.mixedSingular = fit.randomVariance < 1e-8;
    }
    const bool whole = std::all_of(ratings.begin(), ratings.end(), [](const SimulatedRating& r) {
        return std::floor(r.value) == r.value && std::fabs(r.value) < 1e6;
    });
    if (options.ordinalModel && !whole) {
        o.ordinalFailed = true; // ratings between categories: no ordinal model
    } else if (options.ordinalModel) {
        OrdinalOptions ord;
        ord.standardErrors = false; // the LRT only
        const auto clmm = fitOrdinalMixedModel(d, ord);
        if (!clmm.ok() || std::isnan(clmm.lrt.p))
            o.ordinalFailed = true;
        else
            o.ordinal = clmm.lrt.p < options.alpha;
    }
    return o;
}

} // namespace

PowerCurve simulatePower(const StudySimulator& simulator, int groups, const PowerOptions& options) {
    if (groups < 2) throw std::invalid_argument("power needs at least two groups to compare");
    PowerCurve curve;
    curve.groups = groups;
    curve.classicMethod =
        groups == 2 && options.yates
            ? "chisq.test on the pooled counts (Yates' continuity correction), as the papers"
            : "chisq.test on the pooled counts (groups x correct/not correct)";
    curve.mixedMethod = fmt::format("glmer(correct ~ group{} + (1 | participant), binomial, "
                                    "nAGQ = {}): likelihood-ratio test of group",
                                    options.withSurface ? " (+ surface)" : "", options.nAGQ);
    runSimulations(
        [&](int size, std::uint64_t seed) {
            return analyse(simulator(size, seed), groups, options);
        },
        options, curve);
    return curve;
}

PowerCurve simulateRatingPower(const RatingStudySimulator& simulator, const PowerOptions& options) {
    PowerCurve curve;
    curve.groups = 2;
    curve.classicMethod = "t.test(x, y, paired = TRUE) on each participant's mean rating per "
                          "condition";
    curve.mixedMethod = "lmer(rating ~ condition + (1 | participant)), REML: Satterthwaite "
                        "t-test of condition (lmerTest)";
    curve.ordinal = options.mixedModel && options.ordinalModel;
    curve.ordinalMethod = "clmm(ordered(rating) ~ condition + (1 | participant), logit, "
                          "Laplace): likelihood-ratio test of condition (ordinal)";
    runSimulations(
        [&](int size, std::uint64_t seed) {
            return analyseRatings(simulator(size, seed), options);
        },
        options, curve);
    return curve;
}

} // namespace underfoot::analysis
