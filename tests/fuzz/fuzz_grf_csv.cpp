// SPDX-License-Identifier: GPL-3.0-or-later
// GRF CSV file (engine/control/GrfFile.h: loadGrfFile on a .csv); refusal: FileError naming it.
#include "FuzzSupport.h"
#include "engine/control/GrfFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string path = fuzz::writeInput("grf.csv", data, size);
    // Odd sizes also measure and take off the force-plate zero (render and live --grf do).
    engine::GrfLoadOptions options;
    options.tare = size % 2 == 1 ? engine::GrfTareMode::Apply : engine::GrfTareMode::Off;
    fuzz::expectReadOrRefusal<engine::FileError>(path,
                                                 [&] { (void)engine::loadGrfFile(path, options); });
    return 0;
}
