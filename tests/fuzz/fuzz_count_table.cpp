// SPDX-License-Identifier: GPL-3.0-or-later
// Count (confusion) tables for `underfoot analyze` (analysis/io/CountTables.h) and the published
// confusion matrices of simulated participants (experiment/Simulation.h); refusal:
// std::runtime_error naming the source.
#include "FuzzSupport.h"
#include "analysis/io/CountTables.h"
#include "experiment/Simulation.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_counts.csv";
    const std::string t = fuzz::text(data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(
        name, [&] { (void)analysis::parseCountTable(t, name, "g", std::nan("")); });
    fuzz::expectReadOrRefusal<std::runtime_error>(
        name, [&] { (void)experiment::parseConfusionMatrix(t, name); });
    return 0;
}
