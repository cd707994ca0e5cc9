// SPDX-License-Identifier: GPL-3.0-or-later
// The FSR shoes over a real serial path: socat makes a pseudo-terminal pair, a writer thread
// emulates the sketch at 1 kHz on one end (scripted steps, garbage, gaps, silence), a
// SerialSource reads the other end. Skipped only when socat is not installed.
#include "engine/control/StepCalibration.h"
#include "engine/control/StepDetector.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "tests/common/SocatHelpers.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace {

using namespace underfoot::engine;
using namespace underfoot::test;

#define REQUIRE_SOCAT(pair)                                                                        \
    if (!socatInstalled()) GTEST_SKIP() << "socat is not installed (apt-get install socat)";       \
    ASSERT_TRUE(pair.ready()) << "socat did not create its pty links"

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

TEST(SerialSocat, DetectsEveryScriptedStepWithFootPartAndTimingAndNoneWhileStanding) {
    if (!socatInstalled()) GTEST_SKIP() << "socat is not installed (apt-get install socat)";
    SocatPair pair("walk");
    ASSERT_TRUE(pair.ready());
    ShoeScript script(ShoeWalkOptions{}, 5);
    script.stand(500);
    script.walk(6);
    script.bump(shoeSensorIndex(Foot::Left, FootPart::Heel), 500);
    script.bump(shoeSensorIndex(Foot::Right, FootPart::Toe), 1000);
    script.stand(1500);
    script.walk(4, Foot::Right);
    script.stand(300);
    const auto strikes = script.strikes();
    ASSERT_EQ(strikes.size(), 20u);

    SerialConfig config;
    config.path = pair.app;
    // A healthy stream is the premise: the writer thread of this test may be descheduled longer
    // than the default 400 ms limit on a loaded machine (SilenceIsDetected* tests the limit).
    config.faults.silenceMs = 1000;
    SerialSource source(config);
    StepDetector detector{StepThresholds{}};
    std::vector<StepEvent> events; // reader thread only until stop()
    events.reserve(256);
    source.setFrameCallback([&](const ShoeFrame& f) {
        StepDetector::Events out;
        const std::size_t n = detector.process(f, out);
        for (std::size_t i = 0; i < n; ++i) events.push_back(out[i]);
    });
    Transitions transitions;
    source.setStatusCallback(std::ref(transitions));
    source.start();
    EXPECT_EQ(source.backendName(), "termios"); // libserialport cannot open a pty

    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    Random noise(9);
    const auto ticks = static_cast<std::size_t>(script.durationMs());
    std::vector<double> writeTimes;
    std::thread writer([&] {
        writeAll(fd, shoeHeaderLine());
        paced(
            fd, ticks,
            [&](std::size_t i) {
                return formatShoeLine(static_cast<std::uint32_t>(1000 + i),
                                      script.sample(i, noise));
            },
            &writeTimes);
    });
    // Drain the consumer queue meanwhile, as the GUI/log would.
    std::size_t popped = 0;
    SensorState stateMidWalk = SensorState::Stopped;
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ticks + 300);
    while (std::chrono::steady_clock::now() < until) {
        ShoeFrame f;
        while (source.popFrame(f)) ++popped;
        if (popped > 2000 && stateMidWalk == SensorState::Stopped) stateMidWalk = source.state();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    writer.join();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    source.stop();
    ::close(fd);
    ShoeFrame f;
    while (source.popFrame(f)) ++popped;

    const SensorStatus st = source.status();
    EXPECT_EQ(stateMidWalk, SensorState::Running);
    EXPECT_FALSE(source.recordable()); // stopped
    EXPECT_EQ(st.framesAccepted, ticks);
    EXPECT_EQ(popped, ticks);
    EXPECT_EQ(st.linesRejected, 0u) << st.lastRejection;
    EXPECT_EQ(st.framesLost, 0u) << st.lastLoss;
    EXPECT_EQ(source.protocolVersionSeen(), 1);

    ASSERT_EQ(events.size(), strikes.size()) << "every strike once, no step while standing";
    std::vector<double> latencyMs, detectMs, transportMs;
    for (const ShoeContact& s : strikes) {
        const auto it = std::find_if(events.begin(), events.end(), [&](const StepEvent& e) {
            const double frame = e.deviceMs - 1000.0;
            return shoeSensorIndex(e.foot, e.part) == s.sensor && frame >= s.onMs &&
                   frame <= s.onMs + 15;
        });
        ASSERT_NE(it, events.end()) << shoeSensorName(s.sensor) << " strike at " << s.onMs;
        const auto onsetFrame = static_cast<std::size_t>(s.onMs);
        const std::size_t eventFrame = it->deviceMs - 1000;
        latencyMs.push_back((it->timeS - writeTimes[onsetFrame]) * 1000);
        detectMs.push_back(static_cast<double>(eventFrame) - s.onMs);
        transportMs.push_back((it->timeS - writeTimes[eventFrame]) * 1000);
    }
    const double worst = *std::max_element(latencyMs.begin(), latencyMs.end());
    std::printf("[ measured ] %zu strikes, %zu events; onset-to-event latency median %.2f ms, "
                "max %.2f ms (detector %.1f ms median after onset, transport median %.2f ms)\n",
                strikes.size(), events.size(), median(latencyMs), worst, median(detectMs),
                median(transportMs));
    // The wall-clock latencies are printed, not asserted: they include the scheduling delays of
    // a loaded machine (617 ms worst seen beside two listener runs). What the detector decides
    // is judged in device time, which no scheduler moves: each strike's event comes within
    // 15 frames of its onset (above), about 6 frames after it in the median.
    EXPECT_LE(median(detectMs), 10.0);
}

TEST(SerialSocat, GarbageLinesAreCountedReportedAndRaiseAFaultWithinASecond) {
    SocatPair pair("garbage");
    REQUIRE_SOCAT(pair);
    SerialConfig config;
    config.path = pair.app;
    SerialSource source(config);
    Transitions transitions;
    source.setStatusCallback(std::ref(transitions));
    source.start();
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    const std::vector<std::string> garbage = {
        "abc\n", "1,2,3\n",      "12,1024,0,0,0\n", std::string("\0\xff\xfe\n", 4), "1,2,3,4,5,6\n",
        "\n",    "-5,1,1,1,1\n", "1.5,1,1,1,1\n",   std::string(300, 'x') + "\n"};
    std::size_t garbageLines = 0;
    double firstGarbageS = 0;
    std::thread writer([&] {
        paced(fd, 1500, [&](std::size_t i) {
            std::string s = formatShoeLine(static_cast<std::uint32_t>(i), {10, 10, 10, 10});
            if (i >= 500 && i < 800 && i % 5 == 0) {
                if (firstGarbageS == 0) firstGarbageS = sensorClockSeconds();
                s += garbage[garbageLines++ % garbage.size()];
            }
            return s;
        });
    });
    writer.join();
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    source.stop();
    ::close(fd);
    const SensorStatus st = source.status();
    EXPECT_EQ(garbageLines, 60u);
    EXPECT_EQ(st.linesRejected, garbageLines);
    EXPECT_EQ(st.framesAccepted, 1500u);
    EXPECT_EQ(st.framesLost, 0u);
    EXPECT_NE(st.lastRejection.find("line "), std::string::npos) << st.lastRejection;
    EXPECT_NE(st.lastRejection.find("expected"), std::string::npos) << st.lastRejection;
    const double garbageAt = transitions.first(SensorState::Garbage);
    ASSERT_GT(garbageAt, 0) << "no Garbage state";
    std::printf("[ measured ] garbage fault %.0f ms after the first garbage line\n",
                (garbageAt - firstGarbageS) * 1000);
    EXPECT_LT(garbageAt - firstGarbageS, 1.0);
    EXPECT_GT(transitions.first(SensorState::Running, garbageAt), 0) << "recovers when clean";
}

TEST(SerialSocat, GapsInTheDeviceClockAreCountedAsLostFrames) {
    SocatPair pair("gaps");
    REQUIRE_SOCAT(pair);
    SerialConfig config;
    config.path = pair.app;
    SerialSource source(config);
    Transitions transitions;
    source.setStatusCallback(std::ref(transitions));
    source.start();
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    std::size_t skipped = 0;
    std::thread writer([&] {
        paced(fd, 1500, [&](std::size_t i) {
            // 5 of every 50 frames lost between 500 and 1000.
            if (i >= 500 && i < 1000 && i % 50 < 5) {
                ++skipped;
                return std::string{};
            }
            return formatShoeLine(static_cast<std::uint32_t>(i), {10, 10, 10, 10});
        });
    });
    writer.join();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    source.stop();
    ::close(fd);
    const SensorStatus st = source.status();
    EXPECT_EQ(skipped, 50u);
    EXPECT_EQ(st.framesLost, skipped) << st.lastLoss;
    EXPECT_EQ(st.framesAccepted, 1500u - skipped);
    EXPECT_GT(transitions.first(SensorState::Lossy), 0) << "no Lossy state";
}

TEST(SerialSocat, SilenceIsDetectedWithinASecondAndRecovers) {
    SocatPair pair("silence");
    REQUIRE_SOCAT(pair);
    SerialConfig config;
    config.path = pair.app;
    SerialSource source(config);
    Transitions transitions;
    source.setStatusCallback(std::ref(transitions));
    source.start();
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    std::vector<double> times;
    paced(
        fd, 500,
        [](std::size_t i) {
            return formatShoeLine(static_cast<std::uint32_t>(i), {10, 10, 10, 10});
        },
        &times);
    const double lastWrite = times.back();
    std::this_thread::sleep_for(std::chrono::milliseconds(1200)); // the shoes stall
    EXPECT_EQ(source.state(), SensorState::Silent);
    EXPECT_FALSE(source.status().message.empty());
    // The sketch resumes where it stalled (its clock continues at 500: nothing was lost).
    paced(fd, 300, [](std::size_t i) {
        return formatShoeLine(static_cast<std::uint32_t>(500 + i), {10, 10, 10, 10});
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_EQ(source.state(), SensorState::Running);
    source.stop();
    ::close(fd);
    const double silentAt = transitions.first(SensorState::Silent, lastWrite);
    ASSERT_GT(silentAt, 0);
    std::printf("[ measured ] silence reported %.0f ms after the last frame (limit %.0f ms)\n",
                (silentAt - lastWrite) * 1000, config.faults.silenceMs);
    EXPECT_LT(silentAt - lastWrite, 1.0);
}

TEST(SerialSocat, UnplugIsDetectedWithinASecond) {
    SocatPair pair("unplug");
    REQUIRE_SOCAT(pair);
    SerialConfig config;
    config.path = pair.app;
    config.faults.silenceMs = 1000; // a healthy stream until the unplug, as above
    SerialSource source(config);
    Transitions transitions;
    source.setStatusCallback(std::ref(transitions));
    source.start();
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    std::atomic<bool> stop{false};
    std::thread writer([&] {
        paced(
            fd, 5000,
            [](std::size_t i) {
                return formatShoeLine(static_cast<std::uint32_t>(i), {10, 10, 10, 10});
            },
            nullptr, &stop);
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_EQ(source.state(), SensorState::Running);
    const double killedAt = pair.kill();
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    stop = true;
    writer.join();
    ::close(fd);
    EXPECT_EQ(source.state(), SensorState::Disconnected) << source.status().message;
    const double goneAt = transitions.first(SensorState::Disconnected);
    ASSERT_GT(goneAt, 0);
    std::printf("[ measured ] unplug (socat killed) reported after %.1f ms: %s\n",
                (goneAt - killedAt) * 1000, source.status().message.c_str());
    EXPECT_LT(goneAt - killedAt, 1.0);
    EXPECT_FALSE(source.status().message.empty());

    // Plugged in again (a new pty pair behind the same link names): reopened within ~0.5 s.
    SocatPair again("unplug");
    ASSERT_TRUE(again.ready());
    const int fd2 = openWriter(again.shoes);
    ASSERT_GE(fd2, 0);
    const double replugS = sensorClockSeconds();
    paced(fd2, 1500, [](std::size_t i) {
        return formatShoeLine(static_cast<std::uint32_t>(i), {10, 10, 10, 10});
    });
    EXPECT_EQ(source.state(), SensorState::Running) << source.status().message;
    EXPECT_EQ(source.status().reconnects, 1u);
    const double backAt = transitions.first(SensorState::Running, replugS);
    ASSERT_GT(backAt, 0);
    std::printf("[ measured ] replugged: running again %.0f ms after the port reappeared\n",
                (backAt - replugS) * 1000);
    source.stop();
    ::close(fd2);
}

TEST(SerialSocat, CalibratesFromAWalkRecordedThroughThePort) {
    SocatPair pair("calibrate");
    REQUIRE_SOCAT(pair);
    ShoeWalkOptions light; // a light participant (the defaults would count a weight shift)
    light.heelPeak = 260;
    light.toePeak = 220;
    light.standHeel = 170;
    light.standToe = 140;
    light.riseMs = 45;
    ShoeScript walk(light, 12);
    walk.stand(1000);
    walk.walk(12);
    walk.stand(800);
    const auto ticks = static_cast<std::size_t>(walk.durationMs());
    SerialConfig config;
    config.path = pair.app;
    SerialSource source(config);
    source.start();
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    // A partial line first, as when the port is opened in the middle of the device's stream:
    // skipped, not counted as garbage.
    writeAll(fd, "23,1\n");
    Random noise(12);
    std::thread writer([&] {
        paced(fd, ticks, [&](std::size_t i) {
            return formatShoeLine(static_cast<std::uint32_t>(i), walk.sample(i, noise));
        });
    });
    std::vector<ShoeFrame> frames;
    frames.reserve(ticks);
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ticks + 300);
    while (std::chrono::steady_clock::now() < until) {
        ShoeFrame f;
        while (source.popFrame(f)) frames.push_back(f);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    writer.join();
    source.stop();
    ::close(fd);
    ShoeFrame f;
    while (source.popFrame(f)) frames.push_back(f);
    ASSERT_EQ(frames.size(), ticks);
    EXPECT_EQ(source.status().linesRejected, 0u) << source.status().lastRejection;
    StepCalibrationOptions options;
    options.participant = "P12";
    const StepCalibrationResult result = calibrateSteps(frames, options);
    for (std::size_t s = 0; s < kShoeSensorCount; ++s)
        EXPECT_EQ(result.stats[s].strikes, 6u) << shoeSensorName(s);
    // The recording itself, replayed through a detector with the proposed thresholds: every
    // strike once.
    StepDetector detector(result.thresholds);
    std::size_t events = 0;
    for (const ShoeFrame& frame : frames) {
        StepDetector::Events out;
        events += detector.process(frame, out);
    }
    EXPECT_EQ(events, walk.strikes().size());
}

TEST(SerialSocat, OpeningErrorsNameThePortAndTheReason) {
    SerialConfig missing;
    missing.path = "/dev/underfoot-no-such-port";
    SerialSource a(missing);
    try {
        a.start();
        FAIL() << "opened a missing port";
    } catch (const SensorError& e) {
        EXPECT_NE(std::string(e.what()).find("/dev/underfoot-no-such-port"), std::string::npos);
    }
    SocatPair pair("errors");
    REQUIRE_SOCAT(pair);
    SerialConfig onlySp;
    onlySp.path = pair.app;
    onlySp.backend = SerialBackend::LibSerialPort;
    SerialSource b(onlySp);
    EXPECT_THROW(b.start(), SensorError); // libserialport looks ports up in /sys: no ptys
    SerialConfig badBaud;
    badBaud.path = pair.app;
    badBaud.baud = 12345;
    SerialSource c(badBaud);
    EXPECT_THROW(c.start(), SensorError);
    EXPECT_NO_THROW(SerialSource::listPorts());
}

} // namespace
