// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/OscGyroReceiver.h"

#include "engine/io/sensors/SensorClock.h"

#include <boost/lockfree/spsc_queue.hpp>
#include <fmt/core.h>
#include <lo/lo.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace underfoot::engine {

std::string_view limbName(Limb limb) noexcept {
    switch (limb) {
    case Limb::LeftThigh:
        return "left_thigh";
    case Limb::RightThigh:
        return "right_thigh";
    case Limb::LeftShank:
        return "left_shank";
    case Limb::RightShank:
        return "right_shank";
    }
    return "unknown";
}

std::optional<Limb> limbFromName(std::string_view name) noexcept {
    for (std::size_t i = 0; i < kLimbCount; ++i) {
        const auto limb = static_cast<Limb>(i);
        if (limbName(limb) == name) return limb;
    }
    return std::nullopt;
}

namespace {

std::string printable(std::string_view s) {
    std::string out;
    for (char c : s.substr(0, 60)) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f)
            out += c;
        else
            out += fmt::format("\\x{:02x}", u);
    }
    return out;
}

/// liblo's argument pointers point into the packet, 4-byte aligned, while lo_arg (a union with
/// doubles) needs 8: read the bytes instead of the union member.
template <typename T>
T argumentAs(const lo_arg* arg) {
    T value;
    std::memcpy(&value, reinterpret_cast<const unsigned char*>(arg), sizeof value);
    return value;
}

} // namespace

struct OscGyroReceiver::Impl {
    explicit Impl(OscGyroConfig c)
        : config(std::move(c)), monitor(config.faults), queue(config.queueCapacity) {}

    OscGyroConfig config;
    FaultMonitor monitor;
    boost::lockfree::spsc_queue<GyroSample> queue;
    SampleCallback callback;
    lo_server server = nullptr;
    std::thread thread;
    std::atomic<bool> stopRequested{false};
    std::atomic<int> boundPort{0};
    mutable std::mutex limbMutex;
    std::array<LimbCounters, kLimbCount> limbs{};
    std::array<std::uint32_t, kLimbCount> lastSequence{};
    std::uint64_t packets = 0;

    /// liblo reports undecodable datagrams through a handler without user data; it runs on the
    /// thread that called lo_server_recv*, so a thread-local pointer routes it to this receiver.
    static thread_local Impl* current;
    static thread_local std::string lastLiblError;

    static void onError(int number, const char* message, const char* where) {
        const std::string text =
            fmt::format("liblo error {}: {}{}{}", number, message ? message : "",
                        where ? " at " : "", where ? where : "");
        lastLiblError = text;
        if (current && current->server) {
            ++current->packets;
            current->monitor.lineRejected(
                sensorClockSeconds(),
                fmt::format("packet {}: expected an OSC message, {}", current->packets, text));
        }
    }

    static int onMessage(const char* path, const char* types, lo_arg** argv, int argc, lo_message,
                         void* user) {
        static_cast<Impl*>(user)->handle(path ? path : "", types ? types : "", argv, argc);
        return 0;
    }

    void reject(double nowS, std::string_view path, std::string_view types,
                std::string_view expected) {
        monitor.lineRejected(nowS, fmt::format("packet {}: {} ,{}: expected {}", packets,
                                               printable(path), printable(types), expected));
    }

    void handle(std::string_view path, std::string_view types, lo_arg** argv, int argc) {
        const double nowS = sensorClockSeconds();
        ++packets;
        const std::string_view prefix = config.prefix;
        std::optional<Limb> limb;
        if (path.substr(0, prefix.size()) == prefix)
            limb = limbFromName(path.substr(prefix.size()));
        if (!limb) {
            reject(nowS, path, types,
                   fmt::format("an address {}<left_thigh|right_thigh|left_shank|right_shank>",
                               prefix));
            return;
        }
        double value = 0;
        bool sequenced = false;
        std::uint32_t sequence = 0;
        if ((types == "f" || types == "fi") && argc >= 1)
            value = argumentAs<float>(argv[0]);
        else if ((types == "d" || types == "di") && argc >= 1)
            value = argumentAs<double>(argv[0]);
        else {
            reject(nowS, path, types, "type tags ,f or ,fi (deg/s [, sequence])");
            return;
        }
        if (types.size() == 2 && argc >= 2) {
            sequenced = true;
            sequence = static_cast<std::uint32_t>(argumentAs<std::int32_t>(argv[1]));
        }
        if (!std::isfinite(value)) {
            reject(nowS, path, types, fmt::format("a finite angular velocity, got {}", value));
            return;
        }
        const auto li = static_cast<std::size_t>(*limb);
        std::uint64_t lost = 0;
        std::string why;
        {
            std::lock_guard lock(limbMutex);
            LimbCounters& c = limbs[li];
            if (c.lastTimeS != 0) {
                if (sequenced && c.sequenced) {
                    const std::uint32_t delta = sequence - lastSequence[li];
                    if (delta > 1 && delta < 0x80000000u) {
                        lost = delta - 1;
                        why = fmt::format("{}: sequence {} -> {}: {} lost", limbName(*limb),
                                          lastSequence[li], sequence, lost);
                    }
                } else if (!sequenced) {
                    const double periods = (nowS - c.lastTimeS) * config.expectedRateHz;
                    if (periods >= 2.5) {
                        lost = static_cast<std::uint64_t>(std::llround(periods)) - 1;
                        why = fmt::format("{}: {:.0f} ms without a sample: about {} lost",
                                          limbName(*limb), (nowS - c.lastTimeS) * 1000, lost);
                    }
                }
            }
            c.sequenced = sequenced;
            c.lastTimeS = nowS;
            ++c.samples;
            c.lost += lost;
            lastSequence[li] = sequence;
        }
        if (lost > 0) monitor.framesLost(nowS, lost, std::move(why));
        GyroSample s;
        s.timeS = nowS;
        s.limb = *limb;
        s.angularVelocityDps = value;
        s.sequence = sequence;
        monitor.frameAccepted(nowS);
        if (callback) callback(s);
        if (!queue.push(s)) monitor.framesDropped(1);
    }

    /// A datagram that is not an OSC message or bundle (the hook's counterpart of onError).
    void rejectDatagram(std::size_t size, const std::string& why) {
        ++packets;
        monitor.lineRejected(
            sensorClockSeconds(),
            fmt::format("packet {} ({} bytes): expected an OSC message, {}", packets, size, why));
    }

    /// Collects the messages of a bundle (recursively, at most kMaxBundleDepth deep) into
    /// `messages`; false (with `why`) when the bundle is malformed.
    static constexpr int kMaxBundleDepth = 8;
    static bool isBundle(const unsigned char* data, std::size_t size) {
        return size >= 8 && std::memcmp(data, "#bundle", 8) == 0;
    }
    static bool collectBundle(const unsigned char* data, std::size_t size, int depth,
                              std::vector<std::pair<const unsigned char*, std::size_t>>& messages,
                              std::string& why) {
        if (depth > kMaxBundleDepth) {
            why = fmt::format("a bundle nested at most {} deep", kMaxBundleDepth);
            return false;
        }
        if (size < 16) {
            why = "a bundle with an 8-byte time tag";
            return false;
        }
        std::size_t pos = 16;
        while (pos < size) {
            if (size - pos < 4) {
                why = fmt::format("a 4-byte element size at byte {} of the bundle", pos);
                return false;
            }
            const std::uint32_t n = (std::uint32_t{data[pos]} << 24) |
                                    (std::uint32_t{data[pos + 1]} << 16) |
                                    (std::uint32_t{data[pos + 2]} << 8) | data[pos + 3];
            pos += 4;
            if (n == 0 || n % 4 != 0 || n > size - pos) {
                why = fmt::format("a bundle element of a positive multiple of 4 bytes within the "
                                  "datagram at byte {}, got a size of {}",
                                  pos - 4, n);
                return false;
            }
            if (isBundle(data + pos, n)) {
                if (!collectBundle(data + pos, n, depth + 1, messages, why)) return false;
            } else {
                messages.emplace_back(data + pos, n);
            }
            pos += n;
        }
        return true;
    }

    void handleMessageBytes(const unsigned char* data, std::size_t size) {
        int result = 0;
        // liblo copies what it decodes and does not write to `data`.
        void* bytes = const_cast<unsigned char*>(data);
        lo_message m = lo_message_deserialise(bytes, size, &result);
        if (!m) {
            rejectDatagram(size, fmt::format("liblo error {} decoding it", result));
            return;
        }
        const char* path = lo_get_path(bytes, static_cast<ssize_t>(size));
        const char* types = lo_message_get_types(m);
        handle(path ? path : "", types ? types : "", lo_message_get_argv(m),
               lo_message_get_argc(m));
        lo_message_free(m);
    }

    void handlePacket(const unsigned char* data, std::size_t size) {
        if (!isBundle(data, size)) {
            handleMessageBytes(data, size);
            return;
        }
        std::vector<std::pair<const unsigned char*, std::size_t>> messages;
        std::string why;
        if (!collectBundle(data, size, 1, messages, why)) {
            rejectDatagram(size, "an invalid OSC bundle: expected " + why);
            return;
        }
        for (const auto& [bytes, n] : messages) handleMessageBytes(bytes, n);
    }

    void checkLimbs(double nowS) {
        std::string message;
        {
            std::lock_guard lock(limbMutex);
            for (std::size_t i = 0; i < kLimbCount; ++i) {
                const LimbCounters& c = limbs[i];
                const double sinceMs = (nowS - c.lastTimeS) * 1000;
                if (c.lastTimeS != 0 && sinceMs > config.faults.silenceMs)
                    message +=
                        fmt::format("{}{}: no sample for {:.0f} ms", message.empty() ? "" : "; ",
                                    limbName(static_cast<Limb>(i)), sinceMs);
            }
        }
        monitor.setExternalFault(SensorState::Silent, std::move(message));
    }

    void run() {
        current = this;
        while (!stopRequested.load(std::memory_order_relaxed)) {
            lo_server_recv_noblock(server, 20);
            const double nowS = sensorClockSeconds();
            checkLimbs(nowS);
            monitor.update(nowS);
        }
        current = nullptr;
    }
};

thread_local OscGyroReceiver::Impl* OscGyroReceiver::Impl::current = nullptr;
thread_local std::string OscGyroReceiver::Impl::lastLiblError;

OscGyroReceiver::OscGyroReceiver(OscGyroConfig config)
    : impl_(std::make_unique<Impl>(std::move(config))) {
    if (impl_->config.queueCapacity < 2) throw SensorError("OscGyroConfig: queueCapacity < 2");
    if (!(impl_->config.expectedRateHz > 0) || !std::isfinite(impl_->config.expectedRateHz))
        throw SensorError("OscGyroConfig: expectedRateHz must be a finite number > 0");
}

OscGyroReceiver::~OscGyroReceiver() {
    stop();
}

void OscGyroReceiver::setSampleCallback(SampleCallback callback) {
    impl_->callback = std::move(callback);
}
void OscGyroReceiver::setStatusCallback(FaultMonitor::Callback callback) {
    impl_->monitor.setCallback(std::move(callback));
}

void OscGyroReceiver::start() {
    if (impl_->thread.joinable()) return;
    const int p = impl_->config.port;
    if (p < 0 || p > 65535) throw SensorError(fmt::format("OSC port {}: expected 0..65535", p));
    Impl::lastLiblError.clear();
    const std::string portText = std::to_string(p);
    impl_->server =
        lo_server_new_with_proto(p == 0 ? nullptr : portText.c_str(), LO_UDP, &Impl::onError);
    if (!impl_->server)
        throw SensorError(
            fmt::format("OSC: could not listen on UDP port {}: {}", p,
                        Impl::lastLiblError.empty() ? "unknown error" : Impl::lastLiblError));
    lo_server_add_method(impl_->server, nullptr, nullptr, &Impl::onMessage, impl_.get());
    impl_->boundPort = lo_server_get_port(impl_->server);
    impl_->stopRequested = false;
    impl_->monitor.opened(sensorClockSeconds());
    impl_->thread = std::thread([this] { impl_->run(); });
}

void OscGyroReceiver::stop() {
    if (!impl_->thread.joinable()) return;
    impl_->stopRequested = true;
    impl_->thread.join();
    lo_server_free(impl_->server);
    impl_->server = nullptr;
    impl_->monitor.stopped(sensorClockSeconds());
}

int OscGyroReceiver::port() const noexcept {
    return impl_->boundPort.load();
}
bool OscGyroReceiver::popSample(GyroSample& sample) {
    return impl_->queue.pop(sample);
}
SensorStatus OscGyroReceiver::status() const {
    return impl_->monitor.status();
}
SensorState OscGyroReceiver::state() const noexcept {
    return impl_->monitor.state();
}
void OscGyroReceiver::handlePacket(const void* data, std::size_t size) {
    impl_->handlePacket(static_cast<const unsigned char*>(data), size);
}
LimbCounters OscGyroReceiver::limbCounters(Limb limb) const {
    std::lock_guard lock(impl_->limbMutex);
    return impl_->limbs[static_cast<std::size_t>(limb)];
}

} // namespace underfoot::engine
