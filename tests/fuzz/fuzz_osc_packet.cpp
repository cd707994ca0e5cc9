// SPDX-License-Identifier: GPL-3.0-or-later
// Raw UDP payloads to the OSC gyroscope receiver (engine::OscGyroReceiver::handlePacket: liblo's
// decoder, bundles, then the receiver's address, type-tag and value checks, counters and queue),
// without a socket. Every datagram must be accepted as samples or rejected with a reason saying
// what was expected; accepted samples are finite and of a known limb; counters never go back.
#include "FuzzSupport.h"
#include "engine/io/sensors/OscGyroReceiver.h"

#include <cmath>
#include <cstring>

namespace {

using namespace underfoot;

engine::OscGyroReceiver& receiver() {
    static engine::OscGyroReceiver r([] {
        engine::OscGyroConfig c;
        c.port = 0; // never bound: the receiver is not started
        return c;
    }());
    return r;
}

std::string message(const std::string& path, const std::string& types, float value, int seq) {
    auto pad = [](std::string s) {
        s.push_back('\0');
        while (s.size() % 4) s.push_back('\0');
        return s;
    };
    std::string out = pad(path) + pad("," + types);
    auto be32 = [&](std::uint32_t v) {
        for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>(v >> shift));
    };
    std::uint32_t bits;
    std::memcpy(&bits, &value, 4);
    be32(bits);
    if (types == "fi") be32(static_cast<std::uint32_t>(seq));
    return out;
}

void drain(std::size_t& popped, bool check) {
    engine::GyroSample s;
    while (receiver().popSample(s)) {
        ++popped;
        if (check && !std::isfinite(s.angularVelocityDps))
            fuzz::fail("a non-finite angular velocity was accepted");
        if (check && static_cast<std::size_t>(s.limb) >= engine::kLimbCount)
            fuzz::fail("a sample of an unknown limb was accepted");
    }
}

} // namespace

// The hook must accept a well-formed packet (a check that the target fuzzes the real path).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    const std::string good = message("/underfoot/gyro/left_shank", "fi", 12.5f, 7);
    receiver().handlePacket(good.data(), good.size());
    engine::GyroSample s;
    if (!receiver().popSample(s) || s.limb != engine::Limb::LeftShank ||
        s.angularVelocityDps != 12.5 || s.sequence != 7)
        fuzz::fail("a well-formed ,fi message was not accepted as a left_shank sample");
    const std::string bad = message("/underfoot/gyro/left_knee", "f", 1.0f, 0);
    receiver().handlePacket(bad.data(), bad.size());
    if (receiver().status().linesRejected != 1) fuzz::fail("an unknown limb was not rejected");
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 65507) return 0; // the largest UDP payload
    const engine::SensorStatus before = receiver().status();
    std::size_t popped = 0;
    receiver().handlePacket(data, size);
    drain(popped, true);
    const engine::SensorStatus after = receiver().status();
    if (after.framesAccepted < before.framesAccepted || after.linesRejected < before.linesRejected)
        fuzz::fail("a counter went back");
    if (after.framesAccepted - before.framesAccepted !=
        popped + (after.framesDropped - before.framesDropped))
        fuzz::fail("accepted samples differ from those queued plus those dropped (queue full)");
    if (after.linesRejected > before.linesRejected &&
        after.lastRejection.find("expected") == std::string::npos)
        fuzz::fail("a rejection does not say what was expected: " + after.lastRejection);
    return 0;
}
