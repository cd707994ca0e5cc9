// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Whole identification studies simulated for `underfoot protocol power` (and its benchmark,
/// tests/bench/bench_analysis.cpp): each participant's plan from the protocol (experiment/Plan),
/// answers by the experiment layer's synthetic participant from the group's confusion matrix,
/// its share of correct answers shifted by a per-participant ability on the logit scale.
/// Header-only so the benchmark measures the very code the command runs; no Qt.
#include "analysis/model/Catalog.h"
#include "analysis/power/Power.h"
#include "experiment/Catalogue.h"
#include "experiment/Plan.h"
#include "experiment/Protocol.h"
#include "experiment/Random.h"
#include "experiment/Simulation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

namespace underfoot::cli::power {

using namespace underfoot::experiment;

/// A participant's own matrix: the row's share of correct answers shifted by `ability` on the
/// logit scale (a row with every answer correct or none counts as half an answer off, so that it
/// can move), the wrong answers keeping their proportions: participants differ as real ones do.
inline ConfusionMatrix withAbility(const ConfusionMatrix& m, double ability) {
    if (ability == 0.0) return m;
    ConfusionMatrix out = m;
    for (auto& row : out.rows) {
        double correct = 0, total = 0;
        std::size_t rightColumn = row.counts.size(), wrongColumn = row.counts.size();
        for (std::size_t c = 0; c < row.counts.size(); ++c) {
            total += row.counts[c];
            const bool right = answerIsCorrect(m.answers[c], row.surface);
            if (right) correct += row.counts[c];
            if (right && rightColumn == row.counts.size()) rightColumn = c;
            if (!right && m.answers[c] == kDontKnow) wrongColumn = c;
        }
        if (total <= 0 || rightColumn == row.counts.size()) continue;
        const double p = std::clamp(correct / total, 0.5 / total, 1.0 - 0.5 / total);
        const double shifted = 1.0 / (1.0 + std::exp(-(std::log(p / (1 - p)) + ability)));
        const double wrong = total - correct;
        for (std::size_t c = 0; c < row.counts.size(); ++c) {
            const bool right = answerIsCorrect(m.answers[c], row.surface);
            if (right)
                row.counts[c] = correct > 0 ? row.counts[c] * shifted * total / correct : 0.0;
            else
                row.counts[c] = wrong > 0 ? row.counts[c] * (1 - shifted) * total / wrong : 0.0;
        }
        if (correct <= 0) row.counts[rightColumn] = shifted * total;
        if (wrong <= 0 && wrongColumn < row.counts.size())
            row.counts[wrongColumn] = (1 - shifted) * total;
    }
    return out;
}

/// Answers of participant `index` of a simulated study (plan from the study seed `seed`, the
/// participant's own draws from `ps`) by the experiment layer's synthetic answerer.
template <typename Emit>
inline void answerPlan(const Protocol& p, const Group& group, const ConfusionMatrix& matrix,
                       double abilitySd, std::uint64_t seed, std::uint64_t ps, int index,
                       const std::shared_ptr<const RatingModel>& ratingModel, Emit&& emit) {
    Rng abilityRng(deriveSeed(ps, {0xAB1E}));
    const ConfusionMatrix own =
        abilitySd > 0 ? withAbility(matrix, abilitySd * abilityRng.gaussian()) : matrix;
    SimulationSettings settings;
    settings.ratingModel = ratingModel;
    SimulatedParticipant answerer(own, p, group.id, deriveSeed(ps, {0xA5}), settings);
    if (ratingModel) { // participant fields uniformly among their options, as simulateStudy
        std::map<std::string, std::string> fields;
        Rng fieldRng(deriveSeed(ps, {0xF1E1D}));
        for (const auto& f : p.participantFields)
            fields[f.id] =
                f.options.empty()
                    ? std::string("simulated")
                    : f.options[static_cast<std::size_t>(fieldRng.below(f.options.size()))];
        answerer.setParticipant(deriveSeed(ps, {0xB1A5}), std::move(fields));
    }
    for (const auto& planned : generatePlan(p, group.id, seed, index)) {
        if (planned.practice) continue;
        TrialRecord trial;
        trial.index = planned.index;
        trial.block = planned.block;
        trial.stimulus = planned.stimulus;
        trial.repetition = planned.repetition;
        emit(planned, answerer.answer(trial));
    }
}

/// Between-subject groups: `perGroup` participants in each of `groups`, answering from
/// `byGroup` (same order); the answers carry the group index and a surface index (the mixed
/// model's surface factor). The protocol and matrices must outlive the simulator.
inline analysis::StudySimulator betweenGroupsSimulator(const Protocol& p,
                                                       std::vector<const Group*> groups,
                                                       std::vector<const ConfusionMatrix*> byGroup,
                                                       double abilitySd) {
    std::map<std::string, int> surfaceIndex;
    for (const Group* g : groups)
        for (const auto& st : groupStimuli(p, *g))
            surfaceIndex.try_emplace(st.surface, static_cast<int>(surfaceIndex.size()));
    return [&p, groups = std::move(groups), byGroup = std::move(byGroup), abilitySd,
            surfaceIndex = std::move(surfaceIndex)](int perGroup, std::uint64_t seed) {
        std::vector<analysis::SimulatedAnswer> answers;
        int participant = 0;
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
            for (int i = 0; i < perGroup; ++i, ++participant) {
                answerPlan(p, *groups[gi], *byGroup[gi], abilitySd, seed,
                           deriveSeed(seed, {gi, static_cast<std::uint64_t>(i)}), i, nullptr,
                           [&](const PlannedTrial& planned, const TrialAnswer& answer) {
                               analysis::SimulatedAnswer out;
                               out.participant = participant;
                               out.group = static_cast<int>(gi);
                               out.surface = surfaceIndex.at(planned.stimulus.surface);
                               out.correct =
                                   answerIsCorrect(answer.answer, planned.stimulus.surface);
                               answers.push_back(out);
                           });
            }
        }
        return answers;
    };
}

} // namespace underfoot::cli::power
