// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/StudyAnalysis.h"

#include "analysis/io/TrialCsv.h"
#include "analysis/report/MixedModelReport.h"
#include "experiment/Export.h"

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

namespace underfoot::wiring {

namespace an = underfoot::analysis;
namespace exp = underfoot::experiment;

namespace {
exp::SimulatedRows rowsOf(const StudyAnalysisOverrides& o) {
    return o.includeSimulated ? exp::SimulatedRows::Include : exp::SimulatedRows::Exclude;
}
} // namespace

an::AnalysisOptions studyAnalysisOptions(const exp::Protocol& protocol,
                                         const StudyAnalysisOverrides& overrides) {
    an::AnalysisOptions options;
    options.byGroup = overrides.byGroup.value_or(protocol.design == exp::DesignKind::Between);
    if (!overrides.groupOrder.empty())
        options.groupOrder = overrides.groupOrder;
    else
        for (const auto& g : protocol.groups) options.groupOrder.push_back(g.id);
    options.split =
        overrides.poolSoundscapes ? an::SoundscapeSplit::Pooled : an::SoundscapeSplit::BySoundscape;
    options.confLevel = overrides.confLevel;
    if (overrides.answers) {
        options.answers = *overrides.answers;
    } else if (!protocol.questions.surfaceOptions.empty()) {
        options.answers.options.clear();
        for (const auto& a : protocol.questions.surfaceOptions)
            if (a.id != an::kDontKnowId) options.answers.options.push_back({a.id, a.label});
        options.answers.options.push_back(
            {std::string(an::kDontKnowId), an::labelFor(an::kDontKnowId)});
    }
    return options;
}

int simulatedParticipants(const exp::StudyStore& store) {
    int n = 0;
    for (const auto& p : store.participants()) n += p.simulated ? 1 : 0;
    return n;
}

bool isRatingStudy(const exp::Protocol& protocol) {
    return !protocol.questions.asksSurface() && !protocol.questions.scales.empty();
}

an::AnalysisReport analyzeStudy(const exp::StudyStore& store,
                                const StudyAnalysisOverrides& overrides) {
    std::ostringstream csv;
    exp::writeTrialsCsv(store, csv, exp::ExportScope::Answered, rowsOf(overrides));
    const auto trials = an::parseTrialCsv(csv.str(), store.path());
    const auto options = studyAnalysisOptions(store.protocol(), overrides);
    auto report = an::analyzeTrials(trials, options);
    an::addMixedModelComparisons(report, trials, options);
    report.title = overrides.title.empty() ? store.protocol().title : overrides.title;
    report.source = store.path();
    return report;
}

StudyRatings studyRatings(const exp::StudyStore& store, const StudyAnalysisOverrides& overrides) {
    const auto rows = rowsOf(overrides);
    std::ostringstream ratings, participants, scales;
    exp::writeRatingsCsv(store, ratings, exp::ExportScope::Answered, rows);
    exp::writeParticipantsCsv(store, participants, rows);
    exp::writeScalesCsv(store, scales);
    const std::string& path = store.path();
    StudyRatings out;
    out.data = an::parseRatingData(ratings.str(), path + " (ratings)", participants.str(),
                                   path + " (participants)", scales.str(), path + " (scales)");
    out.data.title = overrides.title.empty() ? store.protocol().title : overrides.title;
    if (overrides.includeSimulated) out.labels.simulatedParticipants = simulatedParticipants(store);
    out.labels.stimuli = exp::stimulusDisplayLabels(store.protocol());
    return out;
}

an::RatingStudyAnalysis analyzeRatings(const StudyRatings& ratings,
                                       const StudyAnalysisOverrides& overrides) {
    const auto& fields = ratings.data.groupingFields;
    for (const auto& f : overrides.ratingGroupFields)
        if (std::find(fields.begin(), fields.end(), f) == fields.end()) {
            std::string known;
            for (const auto& k : fields) known += (known.empty() ? "" : ", ") + k;
            throw std::invalid_argument("grouping field '" + f +
                                        "': not a participant field of this study (fields: " +
                                        (known.empty() ? "none" : known) + ")");
        }
    an::RatingAnalysisOptions options;
    options.groupingFields = overrides.ratingGroupFields;
    return an::analyzeRatingStudy(ratings.data, options);
}

} // namespace underfoot::wiring
