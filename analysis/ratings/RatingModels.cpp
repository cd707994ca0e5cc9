// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/ratings/RatingModels.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

namespace underfoot::analysis {

std::vector<double> ratingCategories(const std::vector<double>& values, double min, double max,
                                     std::string& why) {
    why.clear();
    if (!(std::floor(min) == min && std::floor(max) == max && max > min && max - min <= 100)) {
        why = fmt::format("the scale {}..{} has no whole-point categories (the clmm needs ordered "
                          "categories; a continuous scale is analysed by the LMM)",
                          min, max);
        return {};
    }
    for (double v : values)
        if (std::floor(v) != v || v < min || v > max) {
            why = fmt::format("rating {} is not a whole point of the scale {}..{} (the clmm needs "
                              "ordered categories; a continuous scale is analysed by the LMM)",
                              v, min, max);
            return {};
        }
    std::vector<double> out;
    for (double c = min; c <= max; c += 1) out.push_back(c);
    return out;
}

ScaleModels fitScaleModels(const RatingData& data, const RatingScaleInfo& scale,
                           const OmnibusTest& omnibus) {
    ScaleModels m;
    MixedModelData d;
    std::set<std::string> people, stimuli;
    for (const auto& o : data.ratings) {
        if (o.scale != scale.id) continue;
        d.y.push_back(o.value);
        d.condition.push_back(o.stimulus);
        d.participant.push_back(o.participant);
        people.insert(o.participant);
        stimuli.insert(o.stimulus);
    }
    m.ratings = d.y.size();
    if (people.size() < 2 || stimuli.size() < 2) return m;
    for (const auto& s : data.stimulusOrder)
        if (stimuli.count(s)) d.conditionLevels.push_back(s);
    m.fitted = true;
    m.lmm = fitLinearMixedModel(d);
    OrdinalOptions o;
    o.categories = ratingCategories(d.y, scale.min, scale.max, m.clmmSkipped);
    if (m.clmmSkipped.empty()) m.clmm = fitOrdinalMixedModel(d, o);
    const double friedman = omnibus.result.ok() ? omnibus.result.p : std::nan("");
    const std::string omnibusName =
        omnibus.conditions.size() >= 3 ? "Friedman test" : "Wilcoxon signed-rank test";
    if (!m.clmmSkipped.empty() || !m.clmm.ok()) {
        m.advice = fmt::format(
            "Which test to cite: the {} on each participant's cell means and the linear mixed "
            "model on every rating (no clmm: {}).",
            omnibusName, m.clmmSkipped.empty() ? m.clmm.error : m.clmmSkipped);
        return m;
    }
    std::string agreement;
    if (!std::isnan(friedman) && !std::isnan(m.clmm.lrt.p) && !std::isnan(m.lmm.lrt.p)) {
        const bool a = friedman < 0.05, b = m.clmm.lrt.p < 0.05, c = m.lmm.lrt.p < 0.05;
        agreement = a == b && b == c
                        ? " Here the three agree about p < 0.05."
                        : fmt::format(" Here they disagree about p < 0.05 ({} p = {:.3g}, clmm "
                                      "p = {:.3g}, LMM p = {:.3g}): report the clmm.",
                                      omnibusName, friedman, m.clmm.lrt.p, m.lmm.lrt.p);
    }
    m.advice = fmt::format(
        "Which test to cite: the cumulative link mixed model (clmm). A {}..{} scale is ordered "
        "categories, not equally spaced numbers; the clmm models them as such and uses every "
        "rating with the participant as a random intercept, while the LMM assumes equal steps "
        "and normal errors and the {} uses only each participant's cell means.{}",
        scale.min, scale.max, omnibusName, agreement);
    return m;
}

} // namespace underfoot::analysis
