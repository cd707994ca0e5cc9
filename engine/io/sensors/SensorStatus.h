// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Health of a live sensor stream (FSR shoes over serial, gyroscopes over OSC), as the GUI and
/// the CLI poll it and as the session uses it to pause instead of recording a broken trial.
///
/// A FaultMonitor is fed by one sensor thread (accepted frames, rejected lines, lost frames,
/// disconnects) and re-evaluated by that thread at least every 20 ms, so that every fault is
/// reported well within one second (docs/reference/sensors.md, "Sensor states"). Any thread may
/// read a snapshot (status()) or the state alone (state(), lock-free); a callback runs on the
/// sensor thread at each state change (and on the stopping thread for the final Stopped).
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

namespace underfoot::engine {

/// A sensor could not be opened or configured; the message names the device and the reason.
struct SensorError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// The state of a sensor stream. Only Running is fit for recording a trial.
enum class SensorState : std::uint8_t {
    Stopped,      ///< not started, or stopped by the user
    Waiting,      ///< opened, no data yet (within the start-up grace time)
    Running,      ///< frames arrive at the expected rate, no fault in the window
    Silent,       ///< no frame for longer than FaultThresholds::silenceMs
    Garbage,      ///< too many unparsable lines/packets in the window
    Lossy,        ///< too many lost frames/packets (gaps in time or sequence) in the window
    Disconnected, ///< port closed/unplugged (read error, EOF, hang-up); reopened when it returns
};

/// "stopped", "waiting", "running", "silent", "garbage", "lossy", "disconnected".
std::string_view sensorStateName(SensorState state) noexcept;
/// True for Silent, Garbage, Lossy and Disconnected.
constexpr bool isFault(SensorState s) noexcept {
    return s == SensorState::Silent || s == SensorState::Garbage || s == SensorState::Lossy ||
           s == SensorState::Disconnected;
}

/// When a stream is declared faulty. Counts are over a sliding window of `windowMs`.
struct FaultThresholds {
    double silenceMs = 400;       ///< no frame for this long -> Silent (USB hiccups are shorter)
    double startupGraceMs = 2500; ///< Waiting this long after opening (an Arduino resets on open)
    double windowMs = 500;        ///< sliding window for the rates below
    double garbageRatio = 0.02;   ///< rejected / (accepted + rejected) above this ...
    std::uint32_t garbageMinCount = 5; ///< ... and at least this many rejections -> Garbage
    double lossRatio = 0.01;           ///< lost / (accepted + lost) above this ...
    std::uint32_t lossMinCount = 3;    ///< ... and at least this many lost -> Lossy
};

/// A snapshot of a stream's health.
struct SensorStatus {
    SensorState state = SensorState::Stopped;
    std::string message;       ///< what the state means now ("no frame for 312 ms", ...)
    std::string lastRejection; ///< the last rejected input and why ("line 812: expected ...")
    std::string lastLoss;      ///< the last gap ("t_ms 1203 -> 1210: 6 frames lost")
    std::uint64_t framesAccepted = 0;
    std::uint64_t linesRejected = 0; ///< lines (serial) or packets (OSC) rejected
    std::uint64_t framesLost = 0;    ///< frames/packets missing from the sequence
    std::uint64_t framesDropped = 0; ///< accepted but dropped because a consumer queue was full
    std::uint64_t faults = 0;        ///< number of transitions into a fault state
    std::uint64_t reconnects = 0;    ///< successful reopenings after a disconnect
    double rateHz = 0;               ///< accepted frames per second over the window
    double lastFrameTimeS = 0;       ///< sensor clock of the last accepted frame (0 = none)
    double stateSinceS = 0;          ///< sensor clock of the last state change
};

/// Thread-safe fault bookkeeping for one stream (one writer thread, any number of readers).
class FaultMonitor {
  public:
    using Callback = std::function<void(const SensorStatus&)>;

    explicit FaultMonitor(FaultThresholds thresholds = {});

    /// Called on the sensor thread at every state change (set before the stream starts).
    void setCallback(Callback callback);
    const FaultThresholds& thresholds() const noexcept { return thresholds_; }

    // --- writer side (the sensor thread) ---
    /// The stream was (re)opened at `nowS`: Waiting until the first frame.
    void opened(double nowS);
    /// The stream was stopped by the user.
    void stopped(double nowS);
    void frameAccepted(double nowS);
    void lineRejected(double nowS, std::string reason);
    void framesLost(double nowS, std::uint64_t count, std::string reason);
    void framesDropped(std::uint64_t count);
    /// The port closed or failed; stays Disconnected until opened() is called again.
    void disconnected(double nowS, std::string reason);
    /// A fault found by the stream itself (e.g. one gyroscope limb silent while others run);
    /// an empty message clears it. Evaluated after Disconnected, before the window checks.
    void setExternalFault(SensorState state, std::string message);
    /// Re-evaluates the state; call at least every 20 ms. Returns true when the state changed.
    bool update(double nowS);

    // --- reader side (any thread) ---
    SensorStatus status() const;
    /// The current state (lock-free).
    SensorState state() const noexcept { return state_.load(std::memory_order_acquire); }
    /// True when a trial may be recorded (state Running).
    bool recordable() const noexcept { return state() == SensorState::Running; }

  private:
    static constexpr int kBuckets = 10;
    struct Bucket {
        std::int64_t id = -1;
        std::uint64_t accepted = 0, rejected = 0, lost = 0;
    };
    Bucket& bucketAt(double nowS);
    void sums(double nowS, std::uint64_t& accepted, std::uint64_t& rejected,
              std::uint64_t& lost) const;
    bool setStateLocked(SensorState s, std::string message, double nowS);

    FaultThresholds thresholds_;
    Callback callback_;
    mutable std::mutex mutex_;
    SensorStatus status_;
    Bucket buckets_[kBuckets];
    double openedAtS_ = 0;
    bool disconnected_ = false;
    SensorState externalState_ = SensorState::Running;
    std::string externalMessage_;
    std::atomic<SensorState> state_{SensorState::Stopped};
};

} // namespace underfoot::engine
