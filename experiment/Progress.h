// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A study's state at a glance: groups against their targets, each participant's progress, and
/// the protocol's plan summary (trials, breaks, duration, balance).
#include "experiment/Plan.h"
#include "experiment/Store.h"

namespace underfoot::experiment {

struct ParticipantProgress {
    std::string code;
    std::string groupId;
    ParticipantStatus status = ParticipantStatus::Registered;
    int answered = 0;
    int planned = 0;
};

struct StudyProgress {
    StudyInfo info;
    std::vector<GroupCount> groups;
    std::vector<ParticipantProgress> participants;
    /// Plan summary over as many participants per group as the largest group has (or its
    /// target, if larger).
    PlanSummary plan;
};

/// Computes the progress of an open study.
StudyProgress studyProgress(const StudyStore& store);

} // namespace underfoot::experiment
