// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/scene/WadingNode.h"

#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SensorClock.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

// ---------------------------------------------------------------------------------------------
// Live gyroscopes

LiveGyroGaitSource::LiveGyroGaitSource(std::shared_ptr<OscGyroReceiver> receiver)
    : receiver_(std::move(receiver)) {
    if (!receiver_) throw std::invalid_argument("LiveGyroGaitSource: no OSC gyroscope receiver");
}

void LiveGyroGaitSource::prepare(const ProcessSpec& spec) {
    rateHz_ = spec.sampleRateHz;
}

void LiveGyroGaitSource::reset(std::uint64_t) noexcept {
    assembler_.reset();
    sinceFrame_ = 0;
    silentMode_ = false;
    rejectedBefore_ = 0;
    popped_ = 0;
    rejected_ = 0;
    silent_ = 0;
}

int LiveGyroGaitSource::pull(int n, TimedGaitFrame* frames, int capacity) noexcept {
    int count = 0;
    GyroSample sample;
    GaitFrame frame;
    // Everything that arrived since the last block; frames become effective at this block's
    // first sample. A bounded loop: a flood cannot hold the audio thread (the rest waits).
    for (int k = 0; k < 4096 && receiver_->popSample(sample); ++k) {
        popped_.fetch_add(1, std::memory_order_relaxed);
        if (assembler_.push(sample, frame)) {
            silentMode_ = false;
            sinceFrame_ = 0;
            if (count < capacity) frames[count++] = {0, frame};
        }
    }
    rejected_.store(rejectedBefore_ + assembler_.rejectedSamples(), std::memory_order_relaxed);
    // Silence: after kGyroSilenceSeconds without a frame, stand still (a zero frame every
    // period, at the sample where it is due, stamped on the sensor clock) and let the next real
    // sample start afresh.
    const auto silence = static_cast<std::int64_t>(std::llround(kGyroSilenceSeconds * rateHz_));
    const auto period = static_cast<std::int64_t>(std::llround(rateHz_ / kGaitFrameRateHz));
    if (count == 0) {
        const double nowS = sensorClockSeconds();
        while (count < capacity) {
            const std::int64_t limit = silentMode_ ? period : silence;
            const std::int64_t due = std::max<std::int64_t>(0, limit - sinceFrame_);
            if (due >= n) break;
            if (!silentMode_) {
                rejectedBefore_ += assembler_.rejectedSamples();
                assembler_.reset(); // the limbs' held readings are stale now
                silentMode_ = true;
            }
            GaitFrame still{};
            still.timeS = nowS + static_cast<double>(due) / rateHz_;
            frames[count++] = {static_cast<int>(due), still};
            silent_.fetch_add(1, std::memory_order_relaxed);
            sinceFrame_ = -due; // counts from the made-up frame
        }
    }
    sinceFrame_ += n;
    return count;
}

// ---------------------------------------------------------------------------------------------
// Virtual gait

VirtualGaitSource::VirtualGaitSource(VirtualGaitParameters parameters, double loopSeconds)
    : parameters_(parameters), loopSeconds_(loopSeconds) {
    parameters_.validate();
    if (!std::isfinite(loopSeconds_) || loopSeconds_ < 1.0 || loopSeconds_ > 3600.0)
        throw std::invalid_argument(
            fmt::format("VirtualGaitSource: loop of {} s; expected [1, 3600] s", loopSeconds));
}

void VirtualGaitSource::prepare(const ProcessSpec& spec) {
    rateHz_ = spec.sampleRateHz;
    gait_ = virtualGait(parameters_, loopSeconds_, seed_);
    if (gait_.empty()) throw std::invalid_argument("VirtualGaitSource: no gait frames");
}

void VirtualGaitSource::reset(std::uint64_t seed) noexcept {
    // The gait of a new seed is computed in prepare(); reset only rewinds (the seed given at
    // prepare time, i.e. the node's first reset before prepare, selects the gait).
    seed_ = seed;
    sample_ = 0;
    nextFrame_ = 0;
}

int VirtualGaitSource::pull(int n, TimedGaitFrame* frames, int capacity) noexcept {
    int count = 0;
    const auto size = static_cast<std::int64_t>(gait_.size());
    while (count < capacity && size > 0) {
        // Frame k (at k / 100 s) takes effect at the sample where it is due, as renderWading.
        const auto at = static_cast<std::int64_t>(
            std::llround(static_cast<double>(nextFrame_) / kGaitFrameRateHz * rateHz_));
        if (at >= sample_ + n) break;
        GaitFrame f = gait_[static_cast<std::size_t>(nextFrame_ % size)];
        f.timeS = static_cast<double>(nextFrame_) / kGaitFrameRateHz;
        frames[count++] = {static_cast<int>(std::max<std::int64_t>(0, at - sample_)), f};
        ++nextFrame_;
    }
    sample_ += n;
    return count;
}

std::string VirtualGaitSource::name() const {
    if (parameters_.cadenceStepsPerMin <= 0) return "virtual gait, standing";
    return fmt::format("virtual gait {:g} steps/min", parameters_.cadenceStepsPerMin);
}

// ---------------------------------------------------------------------------------------------
// Node

WadingNode::WadingNode(const WadingOptions& options, std::unique_ptr<GaitSource> source,
                       std::size_t recordCapacityFrames)
    : options_(options), source_(std::move(source)) {
    if (!source_) throw std::invalid_argument("WadingNode: no gait source");
    validateWadingOptions(options_);
    scene_.configure(loadWadingPreset(options_.depth), parseWadingAlgorithm(options_.algorithm),
                     parseGyroFilter(options_.filter));
    record_.resize(recordCapacityFrames);
    frames_.resize(kMaxFramesPerBlock);
}

void WadingNode::prepare(const ProcessSpec& spec) {
    source_->reset(options_.seed); // selects the virtual gait's seed before it is computed
    source_->prepare(spec);
    scene_.prepare(spec);
}

void WadingNode::reset(std::uint64_t seed) noexcept {
    source_->reset(seed);
    scene_.reset(seed);
    recorded_ = 0;
    overflow_ = 0;
    applied_ = 0;
}

void WadingNode::process(float* left, float* right, int n) noexcept {
    const int count = source_->pull(n, frames_.data(), kMaxFramesPerBlock);
    if (count > 0) {
        std::size_t r = recorded_.load(std::memory_order_relaxed);
        for (int k = 0; k < count; ++k) {
            if (r < record_.size())
                record_[r++] = frames_[static_cast<std::size_t>(k)].frame;
            else
                overflow_.fetch_add(1, std::memory_order_relaxed);
        }
        recorded_.store(r, std::memory_order_release);
        applied_.fetch_add(static_cast<std::uint64_t>(count), std::memory_order_relaxed);
    }
    scene_.process(frames_.data(), count, left, right, n);
}

std::vector<GaitFrame> WadingNode::recording() const {
    const std::size_t n = recorded_.load(std::memory_order_acquire);
    std::vector<GaitFrame> out(record_.begin(), record_.begin() + static_cast<std::ptrdiff_t>(n));
    if (out.empty()) return out;
    // Relative times, strictly increasing at the CSV's 0.1 ms resolution.
    const double t0 = out.front().timeS;
    double last = -1.0;
    for (auto& f : out) {
        double t = std::round((f.timeS - t0) * 1e4) / 1e4;
        if (t <= last) t = last + 1e-4;
        f.timeS = last = t;
    }
    return out;
}

void WadingNode::writeRecording(const std::string& path) const {
    writeGaitCsv(path, recording());
}

std::string WadingNode::summary() const {
    return fmt::format("water ({}, {}, {}), {}", options_.depth, options_.algorithm,
                       options_.filter, source_->name());
}

} // namespace underfoot::engine
