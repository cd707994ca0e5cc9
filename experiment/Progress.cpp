// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Progress.h"

#include <algorithm>

namespace underfoot::experiment {

StudyProgress studyProgress(const StudyStore& store) {
    StudyProgress progress;
    progress.info = store.info();
    progress.groups = store.groupCounts();
    const auto counts = store.progressCounts();
    for (const auto& p : store.participants()) {
        ParticipantProgress pp{p.code, p.groupId, p.status, 0, 0};
        if (const auto it = counts.find(p.code); it != counts.end()) {
            pp.answered = it->second.first;
            pp.planned = it->second.second;
        }
        progress.participants.push_back(std::move(pp));
    }
    int perGroup = 1;
    for (const auto& g : progress.groups)
        perGroup = std::max({perGroup, g.active + g.completed + g.dropped, g.target});
    progress.plan = summarizePlans(store.protocol(), progress.info.seed, perGroup);
    return progress;
}

} // namespace underfoot::experiment
