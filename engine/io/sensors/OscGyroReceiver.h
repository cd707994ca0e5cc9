// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Gyroscopes over OSC/UDP (the wading study; docs/reference/sensors.md, "Gyroscopes: OSC
/// messages"): one message per limb per sample at 100 Hz,
///
///     /underfoot/gyro/left_thigh   ,f   <deg/s>
///     /underfoot/gyro/left_thigh   ,fi  <deg/s> <sequence>
///
/// with limbs left_thigh, right_thigh, left_shank, right_shank (engine/control/GyroFrame.h;
/// ",d"/",di" doubles are accepted too). A liblo server on its own thread receives them, stamps
/// each sample with the sensor clock, pushes GyroSample to a lock-free SPSC queue and runs the
/// sample callback. Malformed packets (unknown address, wrong type tags, NaN/Inf, undecodable
/// datagrams) are counted with a reason; loss is counted from sequence gaps or, for limbs
/// without sequence numbers, from arrival gaps of 2.5 periods or more; a limb that sent before
/// and has gone silent for FaultThresholds::silenceMs is a Silent fault naming it.
#include "engine/control/GyroFrame.h"
#include "engine/io/sensors/SensorStatus.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace underfoot::engine {

/// "left_thigh", "right_thigh", "left_shank", "right_shank".
std::string_view limbName(Limb limb) noexcept;
/// The limb named `name` (as above), if any.
std::optional<Limb> limbFromName(std::string_view name) noexcept;

/// Settings of an OscGyroReceiver.
struct OscGyroConfig {
    int port = 9000;                         ///< UDP port; 0 picks a free one (see port())
    std::string prefix = "/underfoot/gyro/"; ///< address = prefix + limb name
    double expectedRateHz = 100;             ///< per limb
    std::size_t queueCapacity = 4096;        ///< samples buffered for the consumer
    FaultThresholds faults{};
};

/// Per-limb counters.
struct LimbCounters {
    std::uint64_t samples = 0;
    std::uint64_t lost = 0;
    double lastTimeS = 0; ///< 0 = never seen
    bool sequenced = false;
};

/// Receives gyroscope samples over OSC on a liblo server thread.
class OscGyroReceiver {
  public:
    /// Runs on the receiver thread for each accepted sample (must be quick and not block).
    using SampleCallback = std::function<void(const GyroSample&)>;

    explicit OscGyroReceiver(OscGyroConfig config);
    ~OscGyroReceiver();
    OscGyroReceiver(const OscGyroReceiver&) = delete;
    OscGyroReceiver& operator=(const OscGyroReceiver&) = delete;

    /// Set before start().
    void setSampleCallback(SampleCallback callback);
    /// Set before start(); runs on the receiver thread at each state change.
    void setStatusCallback(FaultMonitor::Callback callback);

    /// Binds the UDP port and starts the thread. Throws SensorError (port in use, ...).
    void start();
    /// Stops the thread and closes the socket (idempotent).
    void stop();
    /// The bound UDP port (after start()).
    int port() const noexcept;

    /// Pops the oldest sample (single consumer). False when none is waiting.
    bool popSample(GyroSample& sample);
    SensorStatus status() const;
    SensorState state() const noexcept;
    /// True when a trial may be recorded (state Running); the session pauses otherwise.
    bool recordable() const noexcept { return state() == SensorState::Running; }
    /// Counters of one limb.
    LimbCounters limbCounters(Limb limb) const;

    /// Decodes one raw UDP payload (an OSC message, or a bundle of them) with liblo's decoder
    /// and handles it as a datagram arriving on the port: the same address and type checks,
    /// counters, faults, queue and callback. No socket is involved; this is the hook of the
    /// tests and of the fuzz target (tests/fuzz/fuzz_osc_packet.cpp). Call it from one thread,
    /// and not while the receiver thread runs (between construction and start(), or after
    /// stop()). Bundle elements are handled at once (their time tags are not scheduled), and an
    /// invalid bundle is rejected as a whole, as liblo does.
    void handlePacket(const void* data, std::size_t size);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace underfoot::engine
