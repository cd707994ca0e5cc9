// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/SerialSource.h"

#include "engine/io/sensors/SensorClock.h"
#include "engine/io/sensors/ShoeProtocol.h"

#include <boost/lockfree/spsc_queue.hpp>
#include <fmt/core.h>
#include <libserialport.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <mutex>
#include <poll.h>
#include <termios.h>
#include <thread>
#include <unistd.h>

namespace underfoot::engine {

namespace {

std::string spError() {
    char* msg = sp_last_error_message();
    std::string s = msg ? msg : "unknown error";
    sp_free_error_message(msg);
    return s;
}

speed_t termiosSpeed(int baud) {
    switch (baud) {
    case 9600:
        return B9600;
    case 19200:
        return B19200;
    case 38400:
        return B38400;
    case 57600:
        return B57600;
    case 115200:
        return B115200;
    case 230400:
        return B230400;
    case 460800:
        return B460800;
    case 500000:
        return B500000;
    case 921600:
        return B921600;
    case 1000000:
        return B1000000;
    case 2000000:
        return B2000000;
    default:
        return 0;
    }
}

bool isPseudoTerminal(const std::string& path) {
    std::error_code ec;
    const auto real = std::filesystem::canonical(path, ec);
    const std::string p = ec ? path : real.string();
    return p.rfind("/dev/pts/", 0) == 0 || p == "/dev/ptmx";
}

/// An open port: a file descriptor, owned either by libserialport or by us.
struct Port {
    sp_port* sp = nullptr;
    int fd = -1;
    std::string backend;

    void close() {
        if (sp) {
            sp_close(sp);
            sp_free_port(sp);
            sp = nullptr;
        } else if (fd >= 0) {
            ::close(fd);
        }
        fd = -1;
    }
};

/// Opens with libserialport; returns an error message (empty on success).
std::string openLibSerialPort(const SerialConfig& c, Port& port) {
    sp_port* sp = nullptr;
    if (sp_get_port_by_name(c.path.c_str(), &sp) != SP_OK)
        return fmt::format("libserialport does not know the port: {}", spError());
    auto fail = [&](const char* what) {
        std::string msg = fmt::format("libserialport could not {}: {}", what, spError());
        sp_close(sp);
        sp_free_port(sp);
        return msg;
    };
    if (sp_open(sp, SP_MODE_READ) != SP_OK) {
        std::string msg = fmt::format("libserialport could not open it: {}", spError());
        sp_free_port(sp);
        return msg;
    }
    if (sp_set_baudrate(sp, c.baud) != SP_OK) return fail("set the baud rate");
    if (sp_set_bits(sp, 8) != SP_OK) return fail("set 8 data bits");
    if (sp_set_parity(sp, SP_PARITY_NONE) != SP_OK) return fail("set no parity");
    if (sp_set_stopbits(sp, 1) != SP_OK) return fail("set 1 stop bit");
    if (sp_set_flowcontrol(sp, SP_FLOWCONTROL_NONE) != SP_OK) return fail("disable flow control");
    int fd = -1;
    if (sp_get_port_handle(sp, &fd) != SP_OK || fd < 0) return fail("give its file descriptor");
    port.sp = sp;
    port.fd = fd;
    port.backend = "libserialport";
    return {};
}

/// Opens with POSIX termios (raw 8N1, non-blocking); returns an error message (empty on success).
std::string openTermios(const SerialConfig& c, Port& port) {
    const speed_t speed = termiosSpeed(c.baud);
    if (speed == 0) return fmt::format("termios has no constant for {} baud", c.baud);
    const int fd = ::open(c.path.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return fmt::format("open() failed: {}", std::strerror(errno));
    termios t{};
    if (::tcgetattr(fd, &t) != 0) {
        std::string msg = fmt::format("not a terminal (tcgetattr: {})", std::strerror(errno));
        ::close(fd);
        return msg;
    }
    ::cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    ::cfsetispeed(&t, speed);
    ::cfsetospeed(&t, speed);
    if (::tcsetattr(fd, TCSANOW, &t) != 0) {
        std::string msg = fmt::format("tcsetattr failed: {}", std::strerror(errno));
        ::close(fd);
        return msg;
    }
    port.fd = fd;
    port.backend = "termios";
    return {};
}

std::string openPort(const SerialConfig& c, Port& port) {
    switch (c.backend) {
    case SerialBackend::LibSerialPort:
        return openLibSerialPort(c, port);
    case SerialBackend::Termios:
        return openTermios(c, port);
    case SerialBackend::Auto:
        break;
    }
    if (isPseudoTerminal(c.path)) return openTermios(c, port);
    const std::string spFailure = openLibSerialPort(c, port);
    if (spFailure.empty()) return {};
    const std::string tFailure = openTermios(c, port);
    if (tFailure.empty()) return {};
    return fmt::format("{}; {}", spFailure, tFailure);
}

} // namespace

struct SerialSource::Impl {
    explicit Impl(SerialConfig c)
        : config(std::move(c)), monitor(config.faults), queue(config.queueCapacity) {}

    SerialConfig config;
    FaultMonitor monitor;
    boost::lockfree::spsc_queue<ShoeFrame> queue;
    FrameCallback frameCallback;
    std::thread thread;
    std::atomic<bool> stopRequested{false};
    std::atomic<int> versionSeen{0};
    mutable std::mutex backendMutex;
    std::string backend;
    Port port;

    // Reader-thread state.
    ShoeLineParser parser;
    std::string line;
    bool discarding = false;
    std::uint64_t nextIndex = 0;

    void handleLine(double nowS) {
        ShoeFrame frame;
        switch (parser.parse(line, frame)) {
        case ShoeLineKind::Frame: {
            std::string why;
            const std::uint64_t lost = parser.gapBefore(frame.deviceMs, why);
            if (lost > 0) monitor.framesLost(nowS, lost, std::move(why));
            frame.timeS = nowS;
            frame.index = nextIndex++;
            monitor.frameAccepted(nowS);
            if (frameCallback) frameCallback(frame);
            if (!queue.push(frame)) monitor.framesDropped(1);
            break;
        }
        case ShoeLineKind::Header:
            versionSeen.store(parser.version(), std::memory_order_relaxed);
            break;
        case ShoeLineKind::Comment:
            break;
        case ShoeLineKind::Rejected:
            // The first line after opening is usually the tail of a line the device sent before
            // the port was opened: skip it without counting it as garbage.
            if (parser.lineNumber() > 1) monitor.lineRejected(nowS, parser.error());
            break;
        }
    }

    void consume(const char* data, std::size_t n, double nowS) {
        for (std::size_t i = 0; i < n; ++i) {
            const char c = data[i];
            if (c == '\n') {
                if (!discarding) handleLine(nowS);
                discarding = false;
                line.clear();
            } else if (!discarding) {
                if (line.size() > kShoeMaxLineBytes) { // +1 allows the '\r' of "\r\n"
                    parser.lineTooLong(line.size());
                    monitor.lineRejected(nowS, parser.error());
                    discarding = true;
                    line.clear();
                } else {
                    line += c;
                }
            }
        }
    }

    void lostPort(double nowS, std::string why) {
        port.close();
        line.clear();
        discarding = false;
        monitor.disconnected(nowS, fmt::format("{}: {}", config.path, why));
    }

    void run() {
        char buffer[4096];
        double lastAttemptS = sensorClockSeconds();
        while (!stopRequested.load(std::memory_order_relaxed)) {
            double nowS = sensorClockSeconds();
            if (port.fd < 0) {
                if (config.reconnect && nowS - lastAttemptS >= 0.5) {
                    lastAttemptS = nowS;
                    Port p;
                    if (openPort(config, p).empty()) {
                        port = p;
                        {
                            std::lock_guard lock(backendMutex);
                            backend = port.backend;
                        }
                        parser = ShoeLineParser{};
                        monitor.opened(nowS);
                    }
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                continue;
            }
            pollfd pfd{port.fd, POLLIN, 0};
            const int r = ::poll(&pfd, 1, 20);
            nowS = sensorClockSeconds();
            if (r < 0 && errno != EINTR) {
                lostPort(nowS, fmt::format("poll failed: {}", std::strerror(errno)));
                continue;
            }
            if (r > 0) {
                if (pfd.revents & POLLNVAL) {
                    lostPort(nowS, "descriptor closed");
                    continue;
                }
                if (pfd.revents & (POLLIN | POLLHUP | POLLERR)) {
                    const ssize_t got = ::read(port.fd, buffer, sizeof buffer);
                    if (got > 0) {
                        consume(buffer, static_cast<std::size_t>(got), nowS);
                    } else if (got == 0) {
                        lostPort(nowS, "end of file (device closed or unplugged)");
                        continue;
                    } else if (errno != EAGAIN && errno != EINTR) {
                        lostPort(nowS, fmt::format("read failed: {} (device unplugged?)",
                                                   std::strerror(errno)));
                        continue;
                    }
                }
            }
            monitor.update(nowS);
        }
    }
};

SerialSource::SerialSource(SerialConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {
    if (impl_->config.queueCapacity < 2) throw SensorError("SerialConfig: queueCapacity < 2");
}

SerialSource::~SerialSource() {
    stop();
}

void SerialSource::setFrameCallback(FrameCallback callback) {
    impl_->frameCallback = std::move(callback);
}
void SerialSource::setStatusCallback(FaultMonitor::Callback callback) {
    impl_->monitor.setCallback(std::move(callback));
}

void SerialSource::start() {
    if (impl_->thread.joinable()) return;
    const SerialConfig& c = impl_->config;
    if (c.baud <= 0) throw SensorError(fmt::format("{}: baud {} is not positive", c.path, c.baud));
    const std::string failure = openPort(c, impl_->port);
    if (!failure.empty())
        throw SensorError(fmt::format("serial port {} at {} baud: {}", c.path, c.baud, failure));
    {
        std::lock_guard lock(impl_->backendMutex);
        impl_->backend = impl_->port.backend;
    }
    impl_->stopRequested = false;
    impl_->parser = ShoeLineParser{}; // a restart begins a new stream (line numbers, clock)
    impl_->line.clear();
    impl_->discarding = false;
    impl_->monitor.opened(sensorClockSeconds());
    impl_->thread = std::thread([this] { impl_->run(); });
}

void SerialSource::stop() {
    if (!impl_->thread.joinable()) return;
    impl_->stopRequested = true;
    impl_->thread.join();
    impl_->port.close();
    impl_->monitor.stopped(sensorClockSeconds());
}

bool SerialSource::popFrame(ShoeFrame& frame) {
    return impl_->queue.pop(frame);
}
SensorStatus SerialSource::status() const {
    return impl_->monitor.status();
}
SensorState SerialSource::state() const noexcept {
    return impl_->monitor.state();
}
std::string SerialSource::backendName() const {
    std::lock_guard lock(impl_->backendMutex);
    return impl_->backend;
}
int SerialSource::protocolVersionSeen() const noexcept {
    return impl_->versionSeen.load(std::memory_order_relaxed);
}
const SerialConfig& SerialSource::config() const noexcept {
    return impl_->config;
}

std::vector<SerialPortInfo> SerialSource::listPorts() {
    sp_port** ports = nullptr;
    if (sp_list_ports(&ports) != SP_OK)
        throw SensorError(fmt::format("listing serial ports failed: {}", spError()));
    std::vector<SerialPortInfo> out;
    for (sp_port** p = ports; *p; ++p) {
        SerialPortInfo info;
        const char* name = sp_get_port_name(*p);
        const char* desc = sp_get_port_description(*p);
        info.path = name ? name : "";
        info.description = desc ? desc : "";
        switch (sp_get_port_transport(*p)) {
        case SP_TRANSPORT_USB: {
            info.transport = "usb";
            int vid = -1, pid = -1;
            if (sp_get_port_usb_vid_pid(*p, &vid, &pid) == SP_OK) {
                info.usbVendorId = vid;
                info.usbProductId = pid;
            }
            break;
        }
        case SP_TRANSPORT_NATIVE:
            info.transport = "native";
            break;
        case SP_TRANSPORT_BLUETOOTH:
            info.transport = "bluetooth";
            break;
        default:
            info.transport = "unknown";
            break;
        }
        out.push_back(std::move(info));
    }
    sp_free_port_list(ports);
    return out;
}

} // namespace underfoot::engine
