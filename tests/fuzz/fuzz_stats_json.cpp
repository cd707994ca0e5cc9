// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot stats` JSON requests (analysis/io/StatsJson.h). The first byte picks the test; the
// answer must be a JSON object, never an exception or a crash.
#include "FuzzSupport.h"
#include "analysis/io/StatsJson.h"

#include <nlohmann/json.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    if (size == 0) return 0;
    const auto& names = analysis::statsTestNames();
    const std::string& test = names[data[0] % names.size()];
    analysis::StatsResponse r;
    try {
        r = analysis::runStatsRequest(test, fuzz::text(data + 1, size - 1));
    } catch (const std::exception& e) {
        fuzz::fail(std::string("runStatsRequest threw: ") + e.what());
    }
    const auto parsed = nlohmann::json::parse(r.json, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object()) fuzz::fail("answer is not a JSON object");
    if (!r.ok && !parsed.contains("error")) fuzz::fail("a refusal without an error message");
    return 0;
}
