// SPDX-License-Identifier: GPL-3.0-or-later
// Rating model TOML of simulated participants (experiment/RatingModel.h: parseRatingModel, then
// checkRatingModel against a shipped rating protocol); refusal: ProtocolError naming it.
#include "FuzzSupport.h"
#include "experiment/Protocol.h"
#include "experiment/RatingModel.h"

#include <optional>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    // A rating protocol to check a parsed model against (its scales, factors and stimuli).
    static const std::optional<experiment::Protocol> protocol = [] {
        try {
            return std::optional(experiment::loadProtocol(std::string(UNDERFOOT_FUZZ_SOURCE_DIR) +
                                                          "/protocols/wading_listening.toml"));
        } catch (const std::exception& e) {
            fuzz::fail(std::string("cannot load the reference protocol: ") + e.what());
        }
    }();
    const std::string name = "fuzz_rating_model.toml";
    fuzz::expectReadOrRefusal<experiment::ProtocolError>(name, [&] {
        const auto model = experiment::parseRatingModel(fuzz::text(data, size), name);
        (void)experiment::checkRatingModel(model, *protocol);
    });
    return 0;
}
