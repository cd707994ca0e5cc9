// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Monte-Carlo power of a between-group comparison of correct answers: whole studies are
/// simulated (by a caller-supplied simulator, e.g. the experiment layer's synthetic
/// participants), each is analysed with the classic test (chi-square on the pooled counts, as
/// the reference papers) and with the logistic mixed model (likelihood-ratio test of the group
/// effect, participant as random intercept), and the share of significant results is the power.
/// Seeded per task, so results do not depend on the number of threads. No Qt.
#include "analysis/stats/TestResult.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace underfoot::analysis {

/// One simulated answer.
struct SimulatedAnswer {
    int participant = 0; ///< unique within one simulated study
    int group = 0;       ///< 0-based group index
    int surface = -1;    ///< 0-based surface index, -1 = no surface factor
    bool correct = false;
};

/// Simulates one whole study with `participantsPerGroup` participants in every group. Must be
/// deterministic in (participantsPerGroup, seed) and safe to call from several threads.
using StudySimulator =
    std::function<std::vector<SimulatedAnswer>(int participantsPerGroup, std::uint64_t seed)>;

struct PowerOptions {
    std::vector<int> participantsPerGroup{10, 20, 30, 40, 50, 60};
    int simulations = 2000;
    std::uint64_t seed = 1;
    unsigned threads = 0; ///< 0 = all cores
    double alpha = 0.05;
    double target = 0.8;     ///< power the smallest group size must reach
    bool yates = true;       ///< chi-square with Yates' correction (2 groups), as the papers
    bool mixedModel = true;  ///< also fit the logistic mixed model
    bool withSurface = true; ///< surface as a fixed factor in the mixed model when present
    int nAGQ = 1;
    bool ordinalModel = true; ///< ratings: also fit the cumulative link mixed model (clmm)
    double confLevel = 0.95;  ///< of the Monte-Carlo intervals
    /// Progress (tasks done, total), called under a lock from the worker threads.
    std::function<void(std::size_t, std::size_t)> progress;
};

/// Power estimated from `simulations` studies, with Monte-Carlo intervals.
struct PowerEstimate {
    double significant = 0;
    double studies = 0;
    double power = 0;
    Interval wilson;         ///< Wilson score interval
    Interval clopperPearson; ///< exact (binom.test) interval
};

struct PowerPoint {
    int participantsPerGroup = 0;
    PowerEstimate classic;
    PowerEstimate mixed;
    int mixedFailures = 0; ///< fits that stopped (counted as not significant)
    int mixedSingular = 0; ///< singular fits (participant variance estimated as 0)
    PowerEstimate ordinal; ///< ratings: the clmm's likelihood-ratio test
    int ordinalFailures = 0;
};

struct PowerCurve {
    std::vector<PowerPoint> points;
    int groups = 0;
    /// Smallest simulated group size whose power estimate reaches the target; -1 = none.
    int smallestClassic = -1;
    int smallestMixed = -1;
    int smallestOrdinal = -1;
    std::string classicMethod;
    std::string mixedMethod;
    bool ordinal = false; ///< the curve has the clmm's power (ratings)
    std::string ordinalMethod;
};

/// 64-bit seed of one task (SplitMix64 of the study seed, the group size and the simulation).
std::uint64_t powerTaskSeed(std::uint64_t seed, int participantsPerGroup, int simulation);

/// Runs the simulations; `groups` is the number of groups the simulator produces.
PowerCurve simulatePower(const StudySimulator& simulator, int groups, const PowerOptions& options);

/// One simulated rating (within-subject comparison of two conditions).
struct SimulatedRating {
    int participant = 0; ///< unique within one simulated study
    int condition = 0;   ///< 0 or 1: the two conditions compared
    double value = 0;
};

/// Simulates one whole rating study with `participants` participants (each rates both
/// conditions). Must be deterministic in (participants, seed) and safe to call from several
/// threads.
using RatingStudySimulator =
    std::function<std::vector<SimulatedRating>(int participants, std::uint64_t seed)>;

/// Monte-Carlo power of a within-subject comparison of two conditions on a rating scale: the
/// classic test is the paired t-test on each participant's mean rating per condition (t.test(x,
/// y, paired = TRUE)); the mixed model lmerTest::lmer(rating ~ condition + (1 | participant)) by
/// REML, the Satterthwaite t-test of the condition; with `ordinalModel` also the cumulative link
/// mixed model ordinal::clmm(ordered(rating) ~ condition + (1 | participant)), the
/// likelihood-ratio test of the condition. `participantsPerGroup` holds the numbers of
/// participants; `yates`, `withSurface` and `nAGQ` are not used.
PowerCurve simulateRatingPower(const RatingStudySimulator& simulator, const PowerOptions& options);

} // namespace underfoot::analysis
