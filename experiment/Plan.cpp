// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Plan.h"

#include "experiment/Random.h"

#include <fmt/format.h>

#include <numeric>
#include <stdexcept>

namespace underfoot::experiment {

namespace {
constexpr std::uint64_t kOrderStream = 1;
constexpr std::uint64_t kRenderStream = 2;

/// Whether `counts` (total `remaining`) can still be laid out with no two equal neighbours
/// when the previous element was `last` (-1: none). Each x needs count <= ceil(R/2), and the
/// previous element, which cannot come first, count <= floor(R/2).
bool feasible(const std::vector<int>& counts, int remaining, int last) {
    for (std::size_t x = 0; x < counts.size(); ++x) {
        const int limit = static_cast<int>(x) == last ? remaining / 2 : (remaining + 1) / 2;
        if (counts[x] > limit) return false;
    }
    return true;
}
/// A random sequence of `items`, each `reps` times; with `noRepeat` no two equal neighbours (nor
/// `last`, the element before the sequence, first). Sequential draw weighted by remaining counts,
/// restricted to choices that keep the rest feasible.
std::vector<int> drawSequence(const std::vector<int>& items, int reps, bool noRepeat, int last,
                              Rng& rng) {
    std::vector<int> out;
    if (!noRepeat) {
        for (int r = 0; r < reps; ++r) out.insert(out.end(), items.begin(), items.end());
        rng.shuffle(out);
        return out;
    }
    const int k = static_cast<int>(items.size());
    std::vector<int> counts(items.size(), reps);
    int remaining = k * reps;
    int lastLocal = -1;
    for (int x = 0; x < k; ++x)
        if (items[static_cast<std::size_t>(x)] == last) lastLocal = x;
    if (!feasible(counts, remaining, lastLocal))
        throw std::invalid_argument("impossible ordering constraint: no_immediate_repeat");
    while (remaining > 0) {
        std::vector<int> weights(items.size(), 0);
        int total = 0;
        for (int x = 0; x < k; ++x) {
            auto& c = counts[static_cast<std::size_t>(x)];
            if (c == 0 || x == lastLocal) continue;
            --c;
            if (feasible(counts, remaining - 1, x)) {
                weights[static_cast<std::size_t>(x)] = c + 1;
                total += c + 1;
            }
            ++c;
        }
        if (total == 0)
            throw std::invalid_argument("impossible ordering constraint: no_immediate_repeat");
        auto pick = static_cast<int>(rng.below(static_cast<std::uint64_t>(total)));
        int chosen = 0;
        for (; chosen < k; ++chosen) {
            pick -= weights[static_cast<std::size_t>(chosen)];
            if (pick < 0) break;
        }
        --counts[static_cast<std::size_t>(chosen)];
        --remaining;
        lastLocal = chosen;
        out.push_back(items[static_cast<std::size_t>(chosen)]);
    }
    return out;
}
} // namespace

std::uint64_t participantSeed(std::uint64_t studySeed, int participantIndex) {
    return deriveSeed(studySeed, {static_cast<std::uint64_t>(participantIndex)});
}

std::vector<Stimulus> groupStimuli(const Protocol& protocol, const Group& group) {
    std::vector<Stimulus> out;
    for (const auto& sid : group.stimuli) {
        const Stimulus* s = protocol.stimulus(sid);
        if (!s)
            throw std::invalid_argument(
                fmt::format("group '{}' names unknown stimulus '{}'", group.id, sid));
        Stimulus copy = *s;
        if (group.modalities) copy.modalities = *group.modalities;
        out.push_back(std::move(copy));
    }
    return out;
}

std::vector<PlannedTrial> generatePlan(const Protocol& protocol, const std::string& groupId,
                                       std::uint64_t studySeed, int participantIndex) {
    const Group* group = protocol.group(groupId);
    if (!group)
        throw std::invalid_argument(
            fmt::format("protocol '{}' has no group '{}'", protocol.id, groupId));
    if (participantIndex < 0) throw std::invalid_argument("participant index must be >= 0");
    const std::vector<Stimulus> stimuli = groupStimuli(protocol, *group);
    const auto& o = protocol.ordering;
    const int k = static_cast<int>(stimuli.size());
    const int reps = o.repetitions;
    if (k == 0) throw std::invalid_argument(fmt::format("group '{}' is empty", groupId));
    Rng rng(deriveSeed(studySeed, {static_cast<std::uint64_t>(participantIndex), kOrderStream}));

    // Main sequence: (stimulus index, block).
    std::vector<std::pair<int, int>> sequence;
    sequence.reserve(static_cast<std::size_t>(k * reps));
    if (o.blocks == BlockKind::Scale) {
        // One block per scale: the stimuli that scale rates, `reps` times each, in a new order.
        const auto& scales = protocol.questions.scales;
        for (std::size_t b = 0; b < scales.size(); ++b) {
            std::vector<int> items;
            for (int i = 0; i < k; ++i)
                if (scales[b].asksFor(stimuli[static_cast<std::size_t>(i)].id)) items.push_back(i);
            if (items.empty()) continue;
            std::vector<int> order;
            if (o.order == OrderKind::Fixed) {
                for (int r = 0; r < reps; ++r)
                    order.insert(order.end(), items.begin(), items.end());
            } else {
                if (o.noImmediateRepeat && items.size() < 2 && reps > 1)
                    throw std::invalid_argument("impossible ordering constraint: "
                                                "no_immediate_repeat with a single stimulus");
                order = drawSequence(items, reps, o.noImmediateRepeat,
                                     sequence.empty() ? -1 : sequence.back().first, rng);
            }
            for (int i : order) sequence.emplace_back(i, static_cast<int>(b) + 1);
        }
    } else if (o.order == OrderKind::Fixed) {
        for (int r = 1; r <= reps; ++r)
            for (int i = 0; i < k; ++i)
                sequence.emplace_back(i, o.blocks == BlockKind::Repetition ? r : 1);
    } else if (o.blocks == BlockKind::Repetition) {
        std::vector<int> perm(static_cast<std::size_t>(k));
        for (int r = 1; r <= reps; ++r) {
            for (int i = 0; i < k; ++i) perm[static_cast<std::size_t>(i)] = i;
            rng.shuffle(perm);
            if (o.noImmediateRepeat && !sequence.empty()) {
                if (k < 2)
                    throw std::invalid_argument("impossible ordering constraint: "
                                                "no_immediate_repeat with a single stimulus");
                // Rejection keeps every valid block equally likely (succeeds with p >= 1/2).
                while (perm.front() == sequence.back().first) rng.shuffle(perm);
            }
            for (int i : perm) sequence.emplace_back(i, r);
        }
    } else {
        // Every stimulus `reps` times in one random sequence (drawSequence: with
        // no_immediate_repeat, never relaxed, failing loudly if it cannot hold).
        std::vector<int> items(static_cast<std::size_t>(k));
        std::iota(items.begin(), items.end(), 0);
        for (int i : drawSequence(items, reps, o.noImmediateRepeat, -1, rng))
            sequence.emplace_back(i, 1);
    }

    std::vector<PlannedTrial> plan;
    int index = 0;
    auto seedFor = [&](int trialIndex) {
        return deriveSeed(studySeed, {static_cast<std::uint64_t>(participantIndex), kRenderStream,
                                      static_cast<std::uint64_t>(trialIndex)});
    };
    for (const auto& sid : o.practice) {
        const Stimulus* s = protocol.stimulus(sid);
        if (!s) throw std::invalid_argument(fmt::format("unknown practice stimulus '{}'", sid));
        PlannedTrial t;
        t.index = index;
        t.block = 0;
        t.practice = true;
        t.stimulus = *s;
        if (group->modalities) t.stimulus.modalities = *group->modalities;
        t.repetition = 1;
        t.plannedSeed = seedFor(index);
        plan.push_back(std::move(t));
        ++index;
    }
    std::vector<int> seen(static_cast<std::size_t>(k), 0);
    const int mainTotal = static_cast<int>(sequence.size());
    int previousBlock = 0;
    for (int m = 0; m < mainTotal; ++m) {
        const auto [si, block] = sequence[static_cast<std::size_t>(m)];
        // Per-scale blocks count repetitions within each block (every block hears each clip).
        if (o.blocks == BlockKind::Scale && block != previousBlock)
            std::fill(seen.begin(), seen.end(), 0);
        previousBlock = block;
        PlannedTrial t;
        t.index = index;
        t.block = block;
        t.stimulus = stimuli[static_cast<std::size_t>(si)];
        t.repetition = ++seen[static_cast<std::size_t>(si)];
        t.plannedSeed = seedFor(index);
        t.breakAfter = o.breakEvery > 0 && (m + 1) % o.breakEvery == 0 && m + 1 < mainTotal;
        plan.push_back(std::move(t));
        ++index;
    }
    return plan;
}

PlanSummary summarizePlans(const Protocol& protocol, std::uint64_t studySeed,
                           int participantsPerGroup) {
    PlanSummary summary;
    int participantIndex = 0;
    for (const auto& g : protocol.groups) {
        PlanSummary::GroupSummary gs;
        gs.groupId = g.id;
        BalanceTable table;
        table.groupId = g.id;
        table.stimulusIds = g.stimuli;
        const std::size_t k = g.stimuli.size();
        std::size_t positions = k * static_cast<std::size_t>(protocol.ordering.repetitions);
        if (protocol.ordering.blocks == BlockKind::Scale) {
            positions = 0;
            for (const auto& t : generatePlan(protocol, g.id, studySeed, 0))
                positions += t.practice ? 0 : 1;
        }
        table.counts.assign(k, std::vector<int>(positions, 0));
        for (int p = 0; p < participantsPerGroup; ++p, ++participantIndex) {
            const auto plan = generatePlan(protocol, g.id, studySeed, participantIndex);
            std::size_t position = 0;
            int practice = 0;
            int breaks = 0;
            for (const auto& t : plan) {
                if (t.practice) {
                    ++practice;
                    continue;
                }
                if (t.breakAfter) ++breaks;
                for (std::size_t s = 0; s < k; ++s)
                    if (g.stimuli[s] == t.stimulus.id) ++table.counts[s][position];
                ++position;
            }
            gs.practiceTrials = practice;
            gs.mainTrials = static_cast<int>(position);
            gs.breaks = breaks;
        }
        if (participantsPerGroup == 0) {
            gs.practiceTrials = static_cast<int>(protocol.ordering.practice.size());
            gs.mainTrials = static_cast<int>(positions);
            gs.breaks = protocol.ordering.breakEvery > 0
                            ? (gs.mainTrials - 1) / protocol.ordering.breakEvery
                            : 0;
        }
        table.participants = participantsPerGroup;
        gs.estimatedDurationS = protocol.timing.briefingS +
                                (gs.practiceTrials + gs.mainTrials) * protocol.timing.trialS +
                                gs.breaks * protocol.timing.breakS;
        summary.groups.push_back(gs);
        summary.balance.push_back(std::move(table));
    }
    return summary;
}

} // namespace underfoot::experiment
