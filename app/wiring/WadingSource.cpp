// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/WadingSource.h"

#include "engine/io/sensors/OscGyroReceiver.h"
#include "experiment/Clips.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::wiring {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;

bool isWadingStimulus(const exp::Stimulus& stimulus) noexcept {
    return stimulus.surface == "water";
}

std::unique_ptr<eng::WadingNode> makeWadingNode(const exp::Stimulus& s, std::uint64_t seed,
                                                std::shared_ptr<eng::OscGyroReceiver> receiver,
                                                double maxSeconds) {
    if (!std::isfinite(maxSeconds) || maxSeconds <= 0 || maxSeconds > 24 * 3600)
        throw std::invalid_argument(
            fmt::format("makeWadingNode: {} s of gait recording; expected (0, 86400]", maxSeconds));
    eng::WadingOptions o;
    try {
        o = eng::wadingOptionsFromParameters(exp::parameterStrings(s.wading));
    } catch (const eng::WadingOptionError& e) {
        throw eng::WadingOptionError(fmt::format("stimulus `{}`: {}", s.id, e.what()));
    }
    o.seed = seed;
    const bool gyro =
        s.input.kind == exp::InputKind::Sensor && s.input.sensor == exp::SensorKind::Gyro;
    std::unique_ptr<eng::GaitSource> source;
    if (gyro) {
        if (!receiver)
            throw std::invalid_argument(fmt::format(
                "stimulus `{}` wades with the gyroscopes, but no OSC gyroscope receiver is "
                "connected",
                s.id));
        source = std::make_unique<eng::LiveGyroGaitSource>(std::move(receiver));
    } else {
        eng::VirtualGaitParameters p;
        p.cadenceStepsPerMin = o.cadenceStepsPerMin;
        p.strideM = o.strideM;
        source = std::make_unique<eng::VirtualGaitSource>(p, std::min(600.0, maxSeconds + 1.0));
    }
    return std::make_unique<eng::WadingNode>(o, std::move(source),
                                             static_cast<std::size_t>(maxSeconds * 110.0) + 1000);
}

} // namespace underfoot::wiring
