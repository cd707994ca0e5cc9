// SPDX-License-Identifier: GPL-3.0-or-later
// Trial CSV for `underfoot analyze` (analysis/io/TrialCsv.h); refusal: std::runtime_error
// naming the source.
#include "FuzzSupport.h"
#include "analysis/io/TrialCsv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_trials.csv";
    fuzz::expectReadOrRefusal<std::runtime_error>(
        name, [&] { (void)analysis::parseTrialCsv(fuzz::text(data, size), name); });
    return 0;
}
