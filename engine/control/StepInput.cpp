// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/StepInput.h"

#include "engine/control/StepGrfPlayer.h"
#include "engine/io/sensors/SerialSource.h"

#include <algorithm>

namespace underfoot::engine {

StepInput::StepInput(const StepThresholds& thresholds, std::size_t eventCapacity)
    : detector_(thresholds), events_(std::max<std::size_t>(eventCapacity, 2)) {}

void StepInput::attach(SerialSource& source, StepGrfPlayer* player) {
    player_ = player;
    source.setFrameCallback([this](const ShoeFrame& frame) { onFrame(frame); });
}

void StepInput::onFrame(const ShoeFrame& frame) noexcept {
    StepDetector::Events out;
    const std::size_t n = detector_.process(frame, out);
    for (std::size_t i = 0; i < n; ++i) {
        steps_.fetch_add(1, std::memory_order_relaxed);
        if (player_) player_->pushStep(out[i]);
        if (!events_.push(out[i])) dropped_.fetch_add(1, std::memory_order_relaxed);
    }
}

bool StepInput::popEvent(StepEvent& event) noexcept {
    return events_.pop(event);
}

} // namespace underfoot::engine
