// SPDX-License-Identifier: GPL-3.0-or-later
// Gyroscopes over OSC on loopback: a sender thread sends one message per limb at 100 Hz with
// liblo's lo_send to 127.0.0.1, including malformed packets and gaps; the receiver counts,
// reports and stamps them.
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SensorClock.h"
#include "tests/common/SocatHelpers.h"

#include <gtest/gtest.h>
#include <lo/lo.h>

#include <arpa/inet.h>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <netinet/in.h>
#include <sys/socket.h>
#include <thread>
#include <unistd.h>

namespace {

using namespace underfoot::engine;
using underfoot::test::Transitions;

void sendRawDatagram(int port, const std::string& bytes) {
    const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(s, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    ::close(s);
}

/// Paces `ticks` rounds at 100 Hz; `round(i)` sends that round's messages.
template <typename F>
void at100Hz(std::size_t ticks, F&& round) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < ticks; ++i) {
        std::this_thread::sleep_until(start + std::chrono::milliseconds(10 * i));
        round(i);
    }
}

float valueAt(std::size_t limb, std::size_t i) {
    return static_cast<float>(80 *
                              std::sin(0.05 * static_cast<double>(i) + static_cast<double>(limb)));
}

TEST(OscGyro, SamplesAtOneHundredHertzMalformedPacketsAndGapsAreCountedAndReported) {
    OscGyroConfig config;
    config.port = 0; // any free port
    OscGyroReceiver receiver(config);
    Transitions transitions;
    receiver.setStatusCallback(std::ref(transitions));
    receiver.start();
    ASSERT_GT(receiver.port(), 0);
    const std::string portText = std::to_string(receiver.port());
    lo_address to = lo_address_new("127.0.0.1", portText.c_str());
    std::size_t sent = 0, malformed = 0, skippedSequenced = 0, skippedPlain = 0;
    double firstMalformedS = 0, lastSendS = 0;
    std::thread sender([&] {
        at100Hz(150, [&](std::size_t i) {
            for (std::size_t l = 0; l < kLimbCount; ++l) {
                const auto limb = static_cast<Limb>(l);
                const std::string path = "/underfoot/gyro/" + std::string(limbName(limb));
                if (limb == Limb::LeftShank && i >= 100 && i < 105) {
                    ++skippedSequenced;
                    continue;
                }
                if (limb == Limb::RightThigh && i >= 120 && i < 125) {
                    ++skippedPlain;
                    continue;
                }
                if (limb == Limb::RightThigh) // no sequence numbers on this one
                    lo_send(to, path.c_str(), "f", valueAt(l, i));
                else
                    lo_send(to, path.c_str(), "fi", valueAt(l, i), static_cast<int>(i));
                ++sent;
            }
            if (i >= 50 && i < 55 && firstMalformedS == 0) firstMalformedS = sensorClockSeconds();
            switch (i) {
            case 50:
                lo_send(to, "/underfoot/gyro/left_knee", "f", 1.0f);
                ++malformed;
                break;
            case 51:
                lo_send(to, "/underfoot/gyro/left_thigh", "s", "fast");
                ++malformed;
                break;
            case 52:
                lo_send(to, "/underfoot/gyro/left_thigh", "fi",
                        std::numeric_limits<float>::quiet_NaN(), 3);
                ++malformed;
                break;
            case 53:
                lo_send(to, "/underfoot/gyro/right_shank", "f",
                        std::numeric_limits<float>::infinity());
                ++malformed;
                break;
            case 54:
                sendRawDatagram(receiver.port(), "garbage, not OSC");
                ++malformed;
                break;
            default:
                break;
            }
            lastSendS = sensorClockSeconds();
        });
    });
    std::vector<GyroSample> samples;
    samples.reserve(1000);
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1700);
    SensorState stateAt1s = SensorState::Stopped;
    const auto oneSecond = std::chrono::steady_clock::now() + std::chrono::milliseconds(1000);
    while (std::chrono::steady_clock::now() < until) {
        GyroSample s;
        while (receiver.popSample(s)) samples.push_back(s);
        if (stateAt1s == SensorState::Stopped && std::chrono::steady_clock::now() > oneSecond)
            stateAt1s = receiver.state();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    sender.join();
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    GyroSample s;
    while (receiver.popSample(s)) samples.push_back(s);
    const SensorStatus st = receiver.status();
    receiver.stop();
    lo_address_free(to);

    EXPECT_EQ(sent, 4 * 150 - 10u);
    EXPECT_EQ(samples.size(), sent);
    EXPECT_EQ(st.framesAccepted, sent);
    EXPECT_EQ(st.linesRejected, malformed) << st.lastRejection;
    // Sequence gaps are exact; the unsequenced limb's loss is estimated from the arrival gap.
    EXPECT_EQ(receiver.limbCounters(Limb::LeftShank).lost, skippedSequenced);
    EXPECT_NEAR(static_cast<double>(receiver.limbCounters(Limb::RightThigh).lost),
                static_cast<double>(skippedPlain), 1.0);
    EXPECT_TRUE(receiver.limbCounters(Limb::LeftThigh).sequenced);
    EXPECT_FALSE(receiver.limbCounters(Limb::RightThigh).sequenced);
    // Values and timestamps.
    std::array<double, kLimbCount> lastTime{};
    std::array<std::size_t, kLimbCount> count{};
    for (const GyroSample& g : samples) {
        const auto l = static_cast<std::size_t>(g.limb);
        EXPECT_GE(g.timeS, lastTime[l]);
        lastTime[l] = g.timeS;
        if (g.limb != Limb::RightThigh) {
            EXPECT_FLOAT_EQ(static_cast<float>(g.angularVelocityDps), valueAt(l, g.sequence));
        }
        ++count[l];
    }
    EXPECT_EQ(count[0], 150u);
    EXPECT_EQ(count[1], 145u);
    EXPECT_EQ(count[2], 145u);
    EXPECT_EQ(count[3], 150u);
    // Faults: garbage within a second of the first malformed packet, silence after the end.
    const double garbageAt = transitions.first(SensorState::Garbage);
    ASSERT_GT(garbageAt, 0) << "5 malformed of ~200 packets in 0.5 s is above 2 %";
    EXPECT_LT(garbageAt - firstMalformedS, 1.0);
    EXPECT_NE(transitions.messageOf(SensorState::Garbage).find("expected"), std::string::npos);
    const double silentAt = transitions.first(SensorState::Silent, lastSendS - 0.1);
    ASSERT_GT(silentAt, 0);
    std::printf("[ measured ] OSC: %zu samples, %zu malformed counted, garbage fault after %.0f "
                "ms, silence reported %.0f ms after the last packet\n",
                samples.size(), static_cast<std::size_t>(st.linesRejected),
                (garbageAt - firstMalformedS) * 1000, (silentAt - lastSendS) * 1000);
    EXPECT_LT(silentAt - lastSendS, 1.0);
}

TEST(OscGyro, OneLimbGoingSilentIsAFaultThatNamesIt) {
    OscGyroConfig config;
    config.port = 0;
    OscGyroReceiver receiver(config);
    receiver.start();
    const std::string portText = std::to_string(receiver.port());
    lo_address to = lo_address_new("127.0.0.1", portText.c_str());
    double shankStoppedS = 0;
    double faultS = 0;
    at100Hz(120, [&](std::size_t i) {
        for (std::size_t l = 0; l < kLimbCount; ++l) {
            const auto limb = static_cast<Limb>(l);
            if (limb == Limb::RightShank && i >= 40) {
                if (shankStoppedS == 0) shankStoppedS = sensorClockSeconds();
                continue;
            }
            const std::string path = "/underfoot/gyro/" + std::string(limbName(limb));
            lo_send(to, path.c_str(), "fi", 10.0f, static_cast<int>(i));
        }
        if (faultS == 0 && receiver.state() == SensorState::Silent) faultS = sensorClockSeconds();
    });
    const SensorStatus st = receiver.status();
    receiver.stop();
    lo_address_free(to);
    EXPECT_EQ(st.state, SensorState::Silent);
    EXPECT_NE(st.message.find("right_shank"), std::string::npos) << st.message;
    ASSERT_GT(faultS, 0);
    EXPECT_LT(faultS - shankStoppedS, 1.0);
}

TEST(OscGyro, DoublesAndSequencesAreReadFromUnalignedArguments) {
    OscGyroConfig config;
    config.port = 0;
    OscGyroReceiver receiver(config);
    receiver.start();
    const std::string portText = std::to_string(receiver.port());
    lo_address to = lo_address_new("127.0.0.1", portText.c_str());
    lo_send(to, "/underfoot/gyro/left_shank", "di", -123.456789, 41);
    lo_send(to, "/underfoot/gyro/right_thigh", "d", 99.5);
    std::vector<GyroSample> got;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (got.size() < 2 && std::chrono::steady_clock::now() < until) {
        GyroSample g;
        while (receiver.popSample(g)) got.push_back(g);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    receiver.stop();
    lo_address_free(to);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0].limb, Limb::LeftShank);
    EXPECT_DOUBLE_EQ(got[0].angularVelocityDps, -123.456789);
    EXPECT_EQ(got[0].sequence, 41u);
    EXPECT_EQ(got[1].limb, Limb::RightThigh);
    EXPECT_DOUBLE_EQ(got[1].angularVelocityDps, 99.5);
}

TEST(OscGyro, ABusyPortIsAClearError) {
    OscGyroConfig config;
    config.port = 0;
    OscGyroReceiver first(config);
    first.start();
    OscGyroConfig same;
    same.port = first.port();
    OscGyroReceiver second(same);
    try {
        second.start();
        FAIL() << "bound the same port twice";
    } catch (const SensorError& e) {
        EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos);
    }
}

} // namespace
