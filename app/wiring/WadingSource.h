// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Wading stimuli (`surface = "water"`; the wading study, docs/explanation/studies.md) for the live
/// scene: the wading node a stimulus asks for, fed by the live gyroscopes (a stimulus whose input
/// is the gyro sensor) or by the virtual gait at the stimulus's cadence
/// (`wading = { cadence = ... }`).
///
/// LivePlayer use (describeStimulus): when isWadingStimulus(s), set
/// `description.wading = makeWadingNode(s, seed, receiver)` instead of a GRF control, record no
/// GRF, and after the scene is retired write `scene->wading()->writeRecording(path)` next to the
/// study (a gait CSV that `underfoot wade --gait` re-renders).
#include "engine/scene/WadingNode.h"
#include "experiment/Protocol.h"

#include <cstdint>
#include <memory>

namespace underfoot::engine {
class OscGyroReceiver;
}

namespace underfoot::wiring {

/// True for stimuli that walk through water (surface "water").
bool isWadingStimulus(const experiment::Stimulus& stimulus) noexcept;

/// The node of a water stimulus: its wading parameters (depth, algorithm, filter, cadence,
/// stride_m; the seed is `seed`), gyroscopes from `receiver` when the stimulus's input is the
/// gyro sensor (the receiver must be given then, and no other scene may pop it at the same time),
/// else the virtual gait. Room for `maxSeconds` of gait recording. Throws std::invalid_argument
/// (WadingOptionError) naming the stimulus and the bad parameter, PresetError for a bad depth.
std::unique_ptr<engine::WadingNode>
makeWadingNode(const experiment::Stimulus& stimulus, std::uint64_t seed,
               std::shared_ptr<engine::OscGyroReceiver> receiver, double maxSeconds = 3600.0);

} // namespace underfoot::wiring
