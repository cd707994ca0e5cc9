// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A participant's trial order, generated from the protocol, the study seed and the
/// participant's index: the same inputs always give the same plan.
#include "experiment/Protocol.h"

#include <cstdint>
#include <string>
#include <vector>

namespace underfoot::experiment {

/// One planned trial.
struct PlannedTrial {
    /// 0-based position in the session (practice trials first).
    int index = 0;
    /// 0 for practice; 1..repetitions for blocked designs; 1 otherwise.
    int block = 1;
    bool practice = false;
    /// The stimulus as presented (group overrides applied).
    Stimulus stimulus;
    /// 1-based repetition number of this stimulus (practice trials: 1).
    int repetition = 1;
    /// Seed proposed to the renderer for this trial.
    std::uint64_t plannedSeed = 0;
    /// Whether a break follows this trial.
    bool breakAfter = false;
};

/// Generates the plan of participant `participantIndex` (0-based) in group `groupId`.
/// Throws std::invalid_argument for an unknown group or an impossible constraint.
std::vector<PlannedTrial> generatePlan(const Protocol& protocol, const std::string& groupId,
                                       std::uint64_t studySeed, int participantIndex);

/// The session seed of a participant (stored with the session).
std::uint64_t participantSeed(std::uint64_t studySeed, int participantIndex);

/// How many times each stimulus appears at each position across a set of plans.
struct BalanceTable {
    std::string groupId;
    std::vector<std::string> stimulusIds;
    /// counts[stimulus][position] over the main (non-practice) trials.
    std::vector<std::vector<int>> counts;
    int participants = 0;
};

/// A protocol's plan summary for `participants` simulated registrations.
struct PlanSummary {
    struct GroupSummary {
        std::string groupId;
        int practiceTrials = 0;
        int mainTrials = 0;
        int breaks = 0;
        double estimatedDurationS = 0.0;
    };
    std::vector<GroupSummary> groups;
    std::vector<BalanceTable> balance;
};

/// Computes the summary from plans of `participantsPerGroup` participants per group.
PlanSummary summarizePlans(const Protocol& protocol, std::uint64_t studySeed,
                           int participantsPerGroup);

/// The group's stimuli with the group's overrides applied.
std::vector<Stimulus> groupStimuli(const Protocol& protocol, const Group& group);

} // namespace underfoot::experiment
