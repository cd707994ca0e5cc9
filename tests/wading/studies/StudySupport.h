// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared helpers of the wading-study tests: shipped protocols, scratch files, and a simulated
// study run end to end through the same calls the CLI makes.
#include "../../common/ScratchDir.h"
#include "analysis/ratings/RatingData.h"
#include "experiment/Export.h"
#include "experiment/Protocol.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <atomic>
#include <filesystem>
#include <sstream>
#include <string>

namespace underfoot::wading::test {

inline std::string shippedProtocol(const std::string& name) {
    return experiment::shippedProtocolDir() + "/" + name;
}
inline std::string ratingModel(const std::string& name) {
    return experiment::shippedProtocolDir() + "/simulation/" + name;
}

/// A fresh path in the program's scratch folder.
inline std::string scratchFile(const std::string& name) {
    static std::atomic<int> counter{0};
    const auto dir = underfoot::test::scratchDir("wading_studies");
    const auto path = dir / (std::to_string(counter++) + "_" + name);
    std::filesystem::remove_all(path);
    return path.string();
}

/// Exports of a study as the analysis reads them (ratings, participants, scales).
inline analysis::RatingData exportedRatings(const experiment::StudyStore& store) {
    std::ostringstream ratings, participants, scales;
    experiment::writeRatingsCsv(store, ratings);
    experiment::writeParticipantsCsv(store, participants);
    experiment::writeScalesCsv(store, scales);
    auto data = analysis::parseRatingData(ratings.str(), "ratings.csv", participants.str(),
                                          "participants.csv", scales.str(), "scales.csv");
    data.title = store.protocol().title;
    return data;
}

/// Creates a study of `protocolFile` with `seed` and simulates `participants` with the model.
inline experiment::StudyStore simulatedStudy(const std::string& protocolFile,
                                             const std::string& modelFile, int participants,
                                             std::uint64_t seed, const std::string& path) {
    auto store = experiment::StudyStore::create(
        path, experiment::loadProtocol(shippedProtocol(protocolFile)), {"T", "lab", seed, "test"});
    experiment::SimulationSettings settings;
    settings.ratingModel = std::make_shared<experiment::RatingModel>(
        experiment::loadRatingModel(ratingModel(modelFile)));
    experiment::simulateStudy(store, {{"", experiment::ConfusionMatrix{}}}, participants, settings);
    return store;
}

} // namespace underfoot::wading::test
