// SPDX-License-Identifier: GPL-3.0-or-later
// Step-threshold calibration file (engine/control/StepCalibration.h: loadStepThresholds);
// refusal: std::runtime_error naming the file.
#include "FuzzSupport.h"
#include "engine/control/StepCalibration.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string path = fuzz::writeInput("thresholds.toml", data, size);
    fuzz::expectReadOrRefusal<std::runtime_error>(path,
                                                  [&] { (void)engine::loadStepThresholds(path); });
    return 0;
}
