// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot sensors`: the live inputs (docs/reference/sensors.md).
//   sensors ports                                           serial ports (libserialport)
//   sensors monitor --serial PATH [--baud N] [--thresholds F] [--seconds S] [--log F] [--frames]
//   sensors monitor --osc PORT [--seconds S] [--log F]      gyroscopes over OSC/UDP
//   sensors calibrate --serial PATH --seconds 20 -o thresholds.toml [--participant P]
//   sensors simulate --serial PATH [--seconds S] [--seed N] [--weight light|normal]
//   sensors simulate --osc PORT [--host H] [--seconds S]    emulates shoes / gyroscopes
#include "app/cli/CommandRegistry.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepDetector.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SensorClock.h"
#include "engine/io/sensors/SensorLog.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"

#include <fmt/core.h>
#include <lo/lo.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <termios.h>
#include <thread>
#include <unistd.h>

namespace underfoot::cli::sensors_command {
namespace {

using namespace underfoot::engine;
using underfoot::cli::UserError;

struct Options {
    std::string serial;
    int baud = 500000;
    int oscPort = -1;
    std::string host = "127.0.0.1";
    double seconds = 10;
    std::string thresholds;
    std::string log;
    std::string output;
    std::string participant;
    std::string weight = "normal";
    std::uint64_t seed = 1;
    bool frames = false;
};

Options& opts() {
    static Options o;
    return o;
}

void checkSeconds(double s) {
    if (!(s > 0 && s <= 24 * 3600))
        throw UserError(fmt::format("--seconds {}: expected a number in (0, 86400]", s));
}

std::string counters(const SensorStatus& s) {
    return fmt::format("{:.0f}/s, accepted {}, rejected {}, lost {}, dropped {}", s.rateHz,
                       s.framesAccepted, s.linesRejected, s.framesLost, s.framesDropped);
}

int portsCommand() {
    std::vector<SerialPortInfo> ports;
    try {
        ports = SerialSource::listPorts();
    } catch (const SensorError& e) {
        throw UserError(e.what());
    }
    if (ports.empty()) {
        fmt::print("no serial ports found (pseudo-terminals are not listed; pass their path "
                   "to --serial directly)\n");
        return 0;
    }
    for (const SerialPortInfo& p : ports) {
        fmt::print("{}  {}  {}", p.path, p.transport, p.description);
        if (p.usbVendorId >= 0) fmt::print("  usb {:04x}:{:04x}", p.usbVendorId, p.usbProductId);
        fmt::print("\n");
    }
    return 0;
}

StepThresholds thresholdsFrom(const std::string& path) {
    if (path.empty()) return StepThresholds{};
    try {
        return loadStepThresholds(path);
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
}

/// Prints state changes as they happen (called on the sensor thread; fmt::print is atomic per
/// call on a line-buffered stdout, good enough for a console monitor).
FaultMonitor::Callback printTransitions(double originS) {
    return [originS](const SensorStatus& s) {
        fmt::print("[{:8.3f} s] state {}: {}\n", s.stateSinceS - originS, sensorStateName(s.state),
                   s.message);
        std::fflush(stdout);
    };
}

int monitorSerial(const Options& o) {
    SerialConfig config;
    config.path = o.serial;
    config.baud = o.baud;
    SerialSource source(config);
    StepInput steps(thresholdsFrom(o.thresholds));
    steps.attach(source);
    const double origin = sensorClockSeconds();
    source.setStatusCallback(printTransitions(origin));
    std::unique_ptr<SensorLogWriter> log;
    try {
        if (!o.log.empty()) log = std::make_unique<SensorLogWriter>(o.log, origin);
        source.start();
    } catch (const SensorError& e) {
        throw UserError(e.what());
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    fmt::print("reading {} at {} baud ({}), thresholds {}\n", o.serial, o.baud,
               source.backendName(), o.thresholds.empty() ? "default" : o.thresholds);
    std::array<std::uint64_t, kShoeSensorCount> perSensor{};
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<long>(o.seconds * 1000));
    auto nextReport = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (std::chrono::steady_clock::now() < end) {
        ShoeFrame f;
        while (source.popFrame(f)) {
            if (log) log->write(f);
            if (o.frames && f.index % 100 == 0)
                fmt::print("[{:8.3f} s] frame t_ms={} lh={} lt={} rh={} rt={}\n", f.timeS - origin,
                           f.deviceMs, f.raw[0], f.raw[1], f.raw[2], f.raw[3]);
        }
        StepEvent e;
        while (steps.popEvent(e)) {
            if (log) log->write(e);
            ++perSensor[shoeSensorIndex(e.foot, e.part)];
            fmt::print("[{:8.3f} s] step {} {} strength {:.2f} (d = {:.0f}/s, pressure {})\n",
                       e.timeS - origin, footName(e.foot), footPartName(e.part), e.strength,
                       e.derivativePerS, e.pressure);
        }
        if (std::chrono::steady_clock::now() >= nextReport) {
            nextReport += std::chrono::seconds(1);
            const SensorStatus s = source.status();
            fmt::print("[{:8.3f} s] {}: {}\n", sensorClockSeconds() - origin,
                       sensorStateName(s.state), counters(s));
            if (log) log->flush();
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    source.stop();
    const SensorStatus s = source.status();
    fmt::print("summary: {}; faults {}; steps left heel {}, left toe {}, right heel {}, right toe "
               "{}\n",
               counters(s), s.faults, perSensor[0], perSensor[1], perSensor[2], perSensor[3]);
    if (!s.lastRejection.empty()) fmt::print("last rejected line: {}\n", s.lastRejection);
    if (!s.lastLoss.empty()) fmt::print("last gap: {}\n", s.lastLoss);
    if (log) {
        log->flush();
        fmt::print("wrote {} rows to {}\n", log->rows(), o.log);
    }
    return 0;
}

int monitorOsc(const Options& o) {
    OscGyroConfig config;
    config.port = o.oscPort;
    OscGyroReceiver receiver(config);
    const double origin = sensorClockSeconds();
    receiver.setStatusCallback(printTransitions(origin));
    std::unique_ptr<SensorLogWriter> log;
    try {
        if (!o.log.empty()) log = std::make_unique<SensorLogWriter>(o.log, origin);
        receiver.start();
    } catch (const SensorError& e) {
        throw UserError(e.what());
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    fmt::print("listening for {}<limb> on UDP port {}\n", config.prefix, receiver.port());
    std::array<double, kLimbCount> last{};
    std::array<std::uint64_t, kLimbCount> count{};
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<long>(o.seconds * 1000));
    auto nextReport = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (std::chrono::steady_clock::now() < end) {
        GyroSample g;
        while (receiver.popSample(g)) {
            if (log) log->write(g);
            last[static_cast<std::size_t>(g.limb)] = g.angularVelocityDps;
            ++count[static_cast<std::size_t>(g.limb)];
        }
        if (std::chrono::steady_clock::now() >= nextReport) {
            nextReport += std::chrono::seconds(1);
            const SensorStatus s = receiver.status();
            std::string limbs;
            for (std::size_t l = 0; l < kLimbCount; ++l)
                limbs += fmt::format(" {} {:+7.1f} deg/s ({})", limbName(static_cast<Limb>(l)),
                                     last[l], count[l]);
            fmt::print("[{:8.3f} s] {}: {};{}\n", sensorClockSeconds() - origin,
                       sensorStateName(s.state), counters(s), limbs);
            if (log) log->flush();
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    receiver.stop();
    const SensorStatus s = receiver.status();
    fmt::print("summary: {}; faults {}\n", counters(s), s.faults);
    if (!s.lastRejection.empty()) fmt::print("last rejected packet: {}\n", s.lastRejection);
    if (!s.lastLoss.empty()) fmt::print("last gap: {}\n", s.lastLoss);
    if (log) {
        log->flush();
        fmt::print("wrote {} rows to {}\n", log->rows(), o.log);
    }
    return 0;
}

int calibrateCommand(const Options& o) {
    if (o.serial.empty()) throw UserError("calibrate: expected --serial PATH");
    SerialConfig config;
    config.path = o.serial;
    config.baud = o.baud;
    config.queueCapacity = static_cast<std::size_t>(o.seconds * 1000) + 4096;
    SerialSource source(config);
    try {
        source.start();
    } catch (const SensorError& e) {
        throw UserError(e.what());
    }
    fmt::print("recording {:.0f} s from {}: ask the participant to stand still for 2 s, then "
               "walk normally\n",
               o.seconds, o.serial);
    std::vector<ShoeFrame> frames;
    frames.reserve(config.queueCapacity);
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<long>(o.seconds * 1000));
    while (std::chrono::steady_clock::now() < end) {
        ShoeFrame f;
        while (source.popFrame(f)) frames.push_back(f);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    source.stop();
    ShoeFrame f;
    while (source.popFrame(f)) frames.push_back(f);
    const SensorStatus s = source.status();
    if (s.faults > 0 || s.framesLost > 0 || s.linesRejected > 0)
        throw UserError(fmt::format(
            "{}: the stream was not clean during the recording ({}; faults {}; last: {}{}): fix "
            "the connection and calibrate again",
            o.serial, counters(s), s.faults, s.lastRejection, s.lastLoss));
    StepCalibrationOptions options;
    options.participant = o.participant;
    StepCalibrationResult result;
    try {
        result = calibrateSteps(frames, options);
        saveStepThresholds(o.output, result.thresholds, &result);
    } catch (const CalibrationError& e) {
        throw UserError(e.what());
    } catch (const std::exception& e) {
        throw UserError(e.what());
    }
    fmt::print("{:<11} {:>6} {:>6} {:>8} {:>12} {:>12} {:>12} {:>8} {:>8}\n", "sensor", "rest",
               "peak", "strikes", "noise d/s", "strike d/s", "onset d/s", "contact", "release");
    for (std::size_t i = 0; i < kShoeSensorCount; ++i) {
        const SensorCalibrationStats& st = result.stats[i];
        const StepSensorThresholds& t = result.thresholds.sensors[i];
        fmt::print(
            "{:<11} {:>6.0f} {:>6.0f} {:>8} {:>12.0f} {:>12.0f} {:>12.0f} {:>8.0f} {:>8.0f}\n",
            shoeSensorName(i), st.restLevel, st.peakLevel, st.strikes, st.noiseDerivativePerS,
            st.strikePeakMedianPerS, t.onsetDerivativePerS, t.contactLevel, t.releaseLevel);
    }
    for (const std::string& w : result.warnings) fmt::print("warning: {}\n", w);
    fmt::print("wrote {} ({} frames, {:.1f} s)\n", o.output, frames.size(),
               static_cast<double>(frames.size()) / 1000.0);
    return 0;
}

int simulateSerial(const Options& o) {
    ShoeWalkOptions walk;
    if (o.weight == "light") {
        walk.heelPeak = 260;
        walk.toePeak = 220;
        walk.standHeel = 170;
        walk.standToe = 140;
        walk.riseMs = 45;
    } else if (o.weight != "normal") {
        throw UserError(fmt::format("--weight {}: expected light or normal", o.weight));
    }
    ShoeScript script(walk, o.seed);
    script.stand(1000);
    int phase = 0;
    while (script.durationMs() < o.seconds * 1000) {
        script.walk(12, phase % 2 == 0 ? Foot::Left : Foot::Right);
        script.bump(shoeSensorIndex(Foot::Left, FootPart::Heel), 600, 80);
        script.stand(2000);
        ++phase;
    }
    const int fd = ::open(o.serial.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        throw UserError(
            fmt::format("{}: cannot open for writing: {}", o.serial, std::strerror(errno)));
    termios t{};
    if (::tcgetattr(fd, &t) == 0) {
        ::cfmakeraw(&t);
        ::tcsetattr(fd, TCSANOW, &t);
    }
    const auto frames = static_cast<std::size_t>(o.seconds * 1000);
    std::array<std::size_t, kShoeSensorCount> strikes{};
    for (const ShoeContact& c : script.strikes())
        if (c.onMs < static_cast<double>(frames)) ++strikes[c.sensor];
    fmt::print("emulating the shoes on {}: {} frames at 1 kHz (seed {}); strikes scripted: left "
               "heel {}, left toe {}, right heel {}, right toe {}\n",
               o.serial, frames, o.seed, strikes[0], strikes[1], strikes[2], strikes[3]);
    std::fflush(stdout);
    Random noise(Random::deriveSeed(o.seed, 1));
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < frames; ++i) {
        std::this_thread::sleep_until(start + std::chrono::milliseconds(i));
        std::string s = i % 1000 == 0 ? shoeHeaderLine() : std::string{};
        s += formatShoeLine(static_cast<std::uint32_t>(i), script.sample(i, noise));
        std::size_t done = 0;
        while (done < s.size()) {
            const ssize_t n = ::write(fd, s.data() + done, s.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                ::close(fd);
                throw UserError(fmt::format("{}: write failed after {} frames: {}", o.serial, i,
                                            std::strerror(errno)));
            }
            done += static_cast<std::size_t>(n);
        }
    }
    ::close(fd);
    return 0;
}

int simulateOsc(const Options& o) {
    const std::string port = std::to_string(o.oscPort);
    lo_address to = lo_address_new(o.host.c_str(), port.c_str());
    if (!to) throw UserError(fmt::format("--host {} --osc {}: not an address", o.host, port));
    fmt::print("sending /underfoot/gyro/<limb> ,fi to {}:{} at 100 Hz for {} s\n", o.host, port,
               o.seconds);
    const auto ticks = static_cast<std::size_t>(o.seconds * 100);
    const auto start = std::chrono::steady_clock::now();
    constexpr double kPi = 3.141592653589793;
    for (std::size_t i = 0; i < ticks; ++i) {
        std::this_thread::sleep_until(start + std::chrono::milliseconds(10 * i));
        const double tS = static_cast<double>(i) * 0.01;
        for (std::size_t l = 0; l < kLimbCount; ++l) {
            // Gait at 0.9 strides/s: left and right in antiphase, shanks lead thighs by 0.1 s;
            // forward swing up to 150 (thigh) / 300 (shank) deg/s, slow backward stance.
            const double side = (l % 2 == 0) ? 0 : kPi;
            const double lead = l >= 2 ? 0.1 : 0;
            const double phase = 2 * kPi * 0.9 * (tS + lead) + side;
            const double swing = std::max(0.0, std::sin(phase));
            const double amplitude = l >= 2 ? 300 : 150;
            const double v = amplitude * swing * swing - 20 * std::max(0.0, -std::sin(phase));
            const std::string path =
                "/underfoot/gyro/" + std::string(limbName(static_cast<Limb>(l)));
            if (lo_send(to, path.c_str(), "fi", static_cast<float>(v), static_cast<int>(i)) < 0) {
                const std::string err = lo_address_errstr(to);
                lo_address_free(to);
                throw UserError(fmt::format("sending to {}:{} failed: {}", o.host, port, err));
            }
        }
    }
    lo_address_free(to);
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "sensors", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand(
            "sensors", "Live inputs: serial FSR shoes and OSC gyroscopes (list, monitor, "
                       "calibrate, simulate)");
        cmd->require_subcommand(1);

        auto* ports = cmd->add_subcommand("ports", "List the serial ports (libserialport)");
        ports->callback([&exitCode] { exitCode = portsCommand(); });

        auto* monitor = cmd->add_subcommand(
            "monitor", "Print frames, steps and the stream's health for --seconds");
        auto* serialOpt = monitor->add_option("--serial", o.serial, "serial port or pty path");
        auto* oscOpt = monitor->add_option("--osc", o.oscPort, "UDP port of the gyroscopes");
        serialOpt->excludes(oscOpt);
        monitor->add_option("--baud", o.baud, "baud rate (default 500000)");
        monitor->add_option("--thresholds", o.thresholds,
                            "step thresholds (TOML from `sensors calibrate`; default built-in)");
        monitor->add_option("--seconds", o.seconds, "duration (default 10)");
        monitor->add_option("--log", o.log, "write a sensor log (CSV)");
        monitor->add_flag("--frames", o.frames, "print every 100th frame");
        monitor->callback([&exitCode, &o] {
            checkSeconds(o.seconds);
            if (!o.serial.empty())
                exitCode = monitorSerial(o);
            else if (o.oscPort >= 0)
                exitCode = monitorOsc(o);
            else
                throw UserError("monitor: expected --serial PATH or --osc PORT");
        });

        auto* calibrate = cmd->add_subcommand(
            "calibrate", "Record the participant walking and propose step thresholds");
        calibrate->add_option("--serial", o.serial, "serial port or pty path")->required();
        calibrate->add_option("--baud", o.baud, "baud rate (default 500000)");
        calibrate->add_option("--seconds", o.seconds, "recording length (20 recommended)");
        calibrate->add_option("--participant", o.participant,
                              "participant code stored in the file");
        calibrate->add_option("-o,--output", o.output, "thresholds .toml")->required();
        calibrate->callback([&exitCode, &o] {
            checkSeconds(o.seconds);
            exitCode = calibrateCommand(o);
        });

        auto* simulate = cmd->add_subcommand(
            "simulate", "Emulate the shoes on a serial port/pty, or the gyroscopes over OSC");
        auto* simSerial = simulate->add_option("--serial", o.serial,
                                               "write the shoes' protocol here (e.g. a socat pty)");
        auto* simOsc = simulate->add_option("--osc", o.oscPort, "send gyroscope OSC to this port");
        simSerial->excludes(simOsc);
        simulate->add_option("--host", o.host, "OSC destination host (default 127.0.0.1)");
        simulate->add_option("--seconds", o.seconds, "duration (default 10)");
        simulate->add_option("--seed", o.seed, "walk script seed (default 1)");
        simulate->add_option("--weight", o.weight, "light or normal (pressure levels)");
        simulate->callback([&exitCode, &o] {
            checkSeconds(o.seconds);
            if (!o.serial.empty())
                exitCode = simulateSerial(o);
            else if (o.oscPort >= 0)
                exitCode = simulateOsc(o);
            else
                throw UserError("simulate: expected --serial PATH or --osc PORT");
        });
    }};

} // namespace
} // namespace underfoot::cli::sensors_command
