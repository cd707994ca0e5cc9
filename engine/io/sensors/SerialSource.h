// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The FSR shoes over a serial port (docs/reference/sensors.md).
///
/// Real ports (USB CDC /dev/ttyACM*, FTDI /dev/ttyUSB*, ...) are looked up, opened and configured
/// (baud, 8N1, no flow control) through libserialport; pseudo-terminals (/dev/pts/*, e.g. socat
/// test pairs), which libserialport cannot open because it looks ports up in /sys, are opened and
/// configured with POSIX termios; so is any path libserialport fails on. Either way a reader
/// thread polls the descriptor (20 ms timeout), splits lines, parses them (ShoeProtocol.h),
/// stamps each frame with the sensor clock, runs the frame callback (step detection) and pushes
/// the frame to a lock-free SPSC queue for one consumer (logging, GUI). A bad first line after
/// opening is skipped uncounted (the tail of a line sent before the port was opened). Faults are
/// tracked by a FaultMonitor (SensorStatus.h); after a disconnect the port is reopened every 500
/// ms.
#include "engine/io/sensors/SensorStatus.h"
#include "engine/io/sensors/ShoeFrame.h"

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace underfoot::engine {

/// How the port is opened.
enum class SerialBackend : std::uint8_t {
    Auto,          ///< termios for /dev/pts/* and when libserialport fails, libserialport otherwise
    LibSerialPort, ///< libserialport only
    Termios,       ///< POSIX termios only
};

/// Settings of a SerialSource.
struct SerialConfig {
    std::string path;  ///< e.g. /dev/ttyACM0 or a socat pty link
    int baud = 500000; ///< the sketch's rate (docs/reference/sensors.md explains 500000)
    SerialBackend backend = SerialBackend::Auto;
    std::size_t queueCapacity = 8192; ///< frames buffered for the consumer (8 s at 1 kHz)
    FaultThresholds faults{};
    bool reconnect = true; ///< reopen the port after a disconnect
};

/// A serial port as listed by libserialport.
struct SerialPortInfo {
    std::string path;
    std::string description;
    std::string transport; ///< "usb", "native", "bluetooth" or "unknown"
    int usbVendorId = -1;  ///< -1 when not USB
    int usbProductId = -1;
};

/// Reads the shoes' line protocol from one serial port on its own thread.
class SerialSource {
  public:
    /// Runs on the reader thread for each accepted frame (must be quick and not block).
    using FrameCallback = std::function<void(const ShoeFrame&)>;

    explicit SerialSource(SerialConfig config);
    ~SerialSource();
    SerialSource(const SerialSource&) = delete;
    SerialSource& operator=(const SerialSource&) = delete;

    /// Set before start().
    void setFrameCallback(FrameCallback callback);
    /// Set before start(); runs on the reader thread at each state change (e.g. pause a session).
    void setStatusCallback(FaultMonitor::Callback callback);

    /// Opens the port and starts the reader thread. Throws SensorError naming the port and the
    /// reason (missing, busy, permission, unsupported baud).
    void start();
    /// Stops the thread and closes the port (idempotent).
    void stop();

    /// Pops the oldest frame (single consumer). False when none is waiting.
    bool popFrame(ShoeFrame& frame);
    /// Health snapshot (any thread).
    SensorStatus status() const;
    /// The current state only (lock-free).
    SensorState state() const noexcept;
    /// True when a trial may be recorded (state Running); the session pauses otherwise.
    bool recordable() const noexcept { return state() == SensorState::Running; }
    /// Which backend opened the port ("libserialport" or "termios"; empty before start).
    std::string backendName() const;
    /// Header settings seen on the stream (rate_hz, protocol version); 0 until a header arrived.
    int protocolVersionSeen() const noexcept;
    const SerialConfig& config() const noexcept;

    /// Serial ports present on this machine (libserialport). Throws SensorError on failure.
    static std::vector<SerialPortInfo> listPorts();

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace underfoot::engine
