// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot stats` JSON requests (analysis/io/StatsJson.h). An input is the test's name, a
// newline, then the request body: `wilcoxon\n{"x": [...], "conf_int": true}`. The name is taken
// as written (not a byte modulo the number of tests, which drifted as tests were added): a seed
// keeps selecting its test, and an unknown or mutated name exercises the refusal of an unknown
// test. The answer must be a JSON object, never an exception or a crash.
#include "FuzzSupport.h"
#include "analysis/io/StatsJson.h"

#include <nlohmann/json.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string input = fuzz::text(data, size);
    const std::size_t newline = input.find('\n');
    if (newline == std::string::npos || newline > 64) return 0; // not "<test>\n<json>"
    const std::string_view test(input.data(), newline);
    const std::string_view body(input.data() + newline + 1, input.size() - newline - 1);
    analysis::StatsResponse r;
    try {
        r = analysis::runStatsRequest(test, body);
    } catch (const std::exception& e) {
        fuzz::fail(std::string("runStatsRequest threw: ") + e.what());
    }
    const auto parsed = nlohmann::json::parse(r.json, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object()) fuzz::fail("answer is not a JSON object");
    if (!r.ok && !parsed.contains("error")) fuzz::fail("a refusal without an error message");
    return 0;
}
