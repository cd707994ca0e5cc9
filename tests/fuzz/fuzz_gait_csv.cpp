// SPDX-License-Identifier: GPL-3.0-or-later
// Gyroscope gait CSV (engine/wading/Gait.h: parseGaitCsv); refusal: GaitFileError naming it.
#include "FuzzSupport.h"
#include "engine/wading/Gait.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_gait.csv";
    fuzz::expectReadOrRefusal<engine::GaitFileError>(
        name, [&] { (void)engine::parseGaitCsv(fuzz::text(data, size), name); });
    return 0;
}
