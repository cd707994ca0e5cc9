// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/WalkerPlayer.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace underfoot::gui {

namespace exp = underfoot::experiment;

engine::WalkerParameters walkerParametersOf(const exp::Stimulus& stimulus) {
    std::string spec;
    for (const auto& [key, value] : stimulus.input.walker) {
        if (!(key == "cadence" || key == "mass" || key == "shoe" || key == "variability")) continue;
        if (const double* v = std::get_if<double>(&value))
            spec += (spec.empty() ? "" : ",") + key + "=" + std::to_string(*v);
    }
    return spec.empty() ? engine::WalkerParameters{} : engine::WalkerParameters::parse(spec);
}

WalkerPlayer::WalkerPlayer(QObject* parent) : QObject(parent) {
    timer_.setInterval(33);
    connect(&timer_, &QTimer::timeout, this, &WalkerPlayer::tick);
}

exp::StimulusStart WalkerPlayer::start(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) {
    stop();
    walker_.reset();
    if (stimulus.input.kind == exp::InputKind::Walker) {
        try {
            walker_ = std::make_unique<engine::VirtualWalker>(walkerParametersOf(stimulus));
            walker_->prepare({kControlRateHz, 256});
            walker_->reset(plannedSeed);
        } catch (const std::exception&) {
            walker_.reset(); // the protocol's walker table is not for this walker: no meter
        }
    }
    steps_ = 0;
    samplesDone_ = 0;
    leftDown_ = rightDown_ = false;
    primed_ = false;
    playing_ = true;
    clock_.start();
    timer_.start();
    emit started(walker_ != nullptr);
    return {plannedSeed, std::nullopt};
}

void WalkerPlayer::stop() {
    if (!playing_) return;
    playing_ = false;
    timer_.stop();
    emit stopped();
}

void WalkerPlayer::setPaused(bool paused) {
    if (!playing_) return;
    if (paused) {
        timer_.stop();
    } else {
        // Resume from where the walk stopped: no catching up on the paused time.
        clock_.start();
        samplesDone_ = 0;
        timer_.start();
    }
}

void WalkerPlayer::tick() {
    GrfMeter m;
    m.steps = steps_;
    if (walker_) {
        const double due = static_cast<double>(clock_.elapsed()) * 1e-3 * kControlRateHz;
        const int n = std::clamp(static_cast<int>(due - samplesDone_), 0, 2000);
        samplesDone_ += n;
        left_.resize(static_cast<std::size_t>(n));
        right_.resize(static_cast<std::size_t>(n));
        int done = 0;
        while (done < n) {
            const int block = std::min(256, n - done);
            walker_->process(left_.data() + done, right_.data() + done, block);
            done += block;
        }
        const double bw = walker_->bodyWeightNewtons();
        if (!primed_ && n > 0) {
            // The right foot is already in its stance when the walk starts: not a new step.
            leftDown_ = left_[0] > 0.0f;
            rightDown_ = right_[0] > 0.0f;
            primed_ = true;
        }
        for (int i = 0; i < n; ++i) {
            const auto k = static_cast<std::size_t>(i);
            m.leftBw = std::max(m.leftBw, static_cast<double>(left_[k]) / bw);
            m.rightBw = std::max(m.rightBw, static_cast<double>(right_[k]) / bw);
            const bool l = left_[k] > 0.0f, r = right_[k] > 0.0f;
            if (l && !leftDown_) m.leftStrike = true, ++steps_;
            if (r && !rightDown_) m.rightStrike = true, ++steps_;
            leftDown_ = l;
            rightDown_ = r;
        }
        m.steps = steps_;
    }
    emit meter(m);
}

} // namespace underfoot::gui
