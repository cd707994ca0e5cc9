// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/SensorStatus.h"

#include <fmt/core.h>

#include <cmath>
#include <utility>

namespace underfoot::engine {

std::string_view sensorStateName(SensorState state) noexcept {
    switch (state) {
    case SensorState::Stopped:
        return "stopped";
    case SensorState::Waiting:
        return "waiting";
    case SensorState::Running:
        return "running";
    case SensorState::Silent:
        return "silent";
    case SensorState::Garbage:
        return "garbage";
    case SensorState::Lossy:
        return "lossy";
    case SensorState::Disconnected:
        return "disconnected";
    }
    return "unknown";
}

FaultMonitor::FaultMonitor(FaultThresholds thresholds) : thresholds_(thresholds) {
    if (!(thresholds_.windowMs > 0)) thresholds_.windowMs = 500;
    if (!(thresholds_.silenceMs > 0)) thresholds_.silenceMs = 400;
}

void FaultMonitor::setCallback(Callback callback) {
    callback_ = std::move(callback);
}

FaultMonitor::Bucket& FaultMonitor::bucketAt(double nowS) {
    const double widthS = thresholds_.windowMs * 0.001 / kBuckets;
    const auto id = static_cast<std::int64_t>(std::floor(nowS / widthS));
    Bucket& b = buckets_[static_cast<std::size_t>(((id % kBuckets) + kBuckets) % kBuckets)];
    if (b.id != id) b = Bucket{id, 0, 0, 0};
    return b;
}

void FaultMonitor::sums(double nowS, std::uint64_t& accepted, std::uint64_t& rejected,
                        std::uint64_t& lost) const {
    const double widthS = thresholds_.windowMs * 0.001 / kBuckets;
    const auto id = static_cast<std::int64_t>(std::floor(nowS / widthS));
    accepted = rejected = lost = 0;
    for (const Bucket& b : buckets_)
        if (b.id > id - kBuckets && b.id <= id) {
            accepted += b.accepted;
            rejected += b.rejected;
            lost += b.lost;
        }
}

void FaultMonitor::opened(double nowS) {
    bool changed = false;
    SensorStatus copy;
    {
        std::lock_guard lock(mutex_);
        if (disconnected_) ++status_.reconnects;
        disconnected_ = false;
        openedAtS_ = nowS;
        status_.lastFrameTimeS = 0;
        for (Bucket& b : buckets_) b = Bucket{};
        changed = setStateLocked(SensorState::Waiting, "opened, waiting for the first frame", nowS);
        copy = status_;
    }
    if (changed && callback_) callback_(copy);
}

void FaultMonitor::stopped(double nowS) {
    bool changed = false;
    SensorStatus copy;
    {
        std::lock_guard lock(mutex_);
        changed = setStateLocked(SensorState::Stopped, "stopped", nowS);
        copy = status_;
    }
    if (changed && callback_) callback_(copy);
}

void FaultMonitor::frameAccepted(double nowS) {
    std::lock_guard lock(mutex_);
    ++bucketAt(nowS).accepted;
    ++status_.framesAccepted;
    status_.lastFrameTimeS = nowS;
}

void FaultMonitor::lineRejected(double nowS, std::string reason) {
    std::lock_guard lock(mutex_);
    ++bucketAt(nowS).rejected;
    ++status_.linesRejected;
    status_.lastRejection = std::move(reason);
}

void FaultMonitor::framesLost(double nowS, std::uint64_t count, std::string reason) {
    std::lock_guard lock(mutex_);
    bucketAt(nowS).lost += count;
    status_.framesLost += count;
    status_.lastLoss = std::move(reason);
}

void FaultMonitor::framesDropped(std::uint64_t count) {
    std::lock_guard lock(mutex_);
    status_.framesDropped += count;
}

void FaultMonitor::disconnected(double nowS, std::string reason) {
    bool changed = false;
    SensorStatus copy;
    {
        std::lock_guard lock(mutex_);
        disconnected_ = true;
        changed = setStateLocked(SensorState::Disconnected, std::move(reason), nowS);
        copy = status_;
    }
    if (changed && callback_) callback_(copy);
}

void FaultMonitor::setExternalFault(SensorState state, std::string message) {
    std::lock_guard lock(mutex_);
    externalState_ = message.empty() ? SensorState::Running : state;
    externalMessage_ = std::move(message);
}

bool FaultMonitor::setStateLocked(SensorState s, std::string message, double nowS) {
    const SensorState old = status_.state;
    status_.message = std::move(message);
    if (old == s) return false;
    status_.state = s;
    status_.stateSinceS = nowS;
    if (isFault(s) && !isFault(old)) ++status_.faults;
    state_.store(s, std::memory_order_release);
    return true;
}

bool FaultMonitor::update(double nowS) {
    bool changed = false;
    SensorStatus copy;
    {
        std::lock_guard lock(mutex_);
        if (status_.state == SensorState::Stopped || disconnected_) return false;
        std::uint64_t accepted = 0, rejected = 0, lost = 0;
        sums(nowS, accepted, rejected, lost);
        status_.rateHz = static_cast<double>(accepted) / (thresholds_.windowMs * 0.001);
        const FaultThresholds& t = thresholds_;
        const double sinceFrameMs = (nowS - status_.lastFrameTimeS) * 1000.0;
        const double sinceOpenMs = (nowS - openedAtS_) * 1000.0;
        SensorState s = SensorState::Running;
        std::string message;
        if (status_.lastFrameTimeS == 0 && sinceOpenMs <= t.startupGraceMs) {
            s = SensorState::Waiting;
            message = "opened, waiting for the first frame";
        } else if (status_.lastFrameTimeS == 0) {
            s = SensorState::Silent;
            message =
                fmt::format("no frame since the stream was opened {:.0f} ms ago", sinceOpenMs);
        } else if (sinceFrameMs > t.silenceMs) {
            s = SensorState::Silent;
            message =
                fmt::format("no frame for {:.0f} ms (limit {:.0f} ms)", sinceFrameMs, t.silenceMs);
        } else if (!externalMessage_.empty()) {
            s = externalState_;
            message = externalMessage_;
        } else if (rejected >= t.garbageMinCount &&
                   static_cast<double>(rejected) >
                       t.garbageRatio * static_cast<double>(accepted + rejected)) {
            s = SensorState::Garbage;
            message = fmt::format("{} of {} lines rejected in the last {:.0f} ms; last: {}",
                                  rejected, accepted + rejected, t.windowMs, status_.lastRejection);
        } else if (lost >= t.lossMinCount &&
                   static_cast<double>(lost) > t.lossRatio * static_cast<double>(accepted + lost)) {
            s = SensorState::Lossy;
            message = fmt::format("{} of {} frames lost in the last {:.0f} ms; last: {}", lost,
                                  accepted + lost, t.windowMs, status_.lastLoss);
        } else {
            message = fmt::format("{:.0f} frames/s", status_.rateHz);
        }
        changed = setStateLocked(s, std::move(message), nowS);
        if (changed) copy = status_;
    }
    if (changed && callback_) callback_(copy);
    return changed;
}

SensorStatus FaultMonitor::status() const {
    std::lock_guard lock(mutex_);
    return status_;
}

} // namespace underfoot::engine
