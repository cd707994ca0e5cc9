// SPDX-License-Identifier: GPL-3.0-or-later
// Sensor-side pieces without devices: the line protocol, the step detector on a scripted walk,
// the calibration and its TOML files, the GRF player (determinism, no allocation), the fault
// monitor's rules.
#include "engine/control/StepCalibration.h"
#include "engine/control/StepDetector.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/io/sensors/SensorStatus.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "tests/common/AllocationTrap.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace {

using namespace underfoot::engine;

std::vector<ShoeFrame> renderScript(const ShoeScript& script, std::uint64_t seed) {
    Random noise(seed);
    std::vector<ShoeFrame> frames;
    const auto n = static_cast<std::size_t>(script.durationMs());
    for (std::size_t i = 0; i < n; ++i) {
        ShoeFrame f;
        f.index = i;
        f.deviceMs = static_cast<std::uint32_t>(i);
        f.timeS = static_cast<double>(i) * 0.001;
        f.raw = script.sample(i, noise);
        frames.push_back(f);
    }
    return frames;
}

std::vector<StepEvent> detect(const std::vector<ShoeFrame>& frames, const StepThresholds& t) {
    StepDetector detector(t);
    std::vector<StepEvent> events;
    StepDetector::Events out;
    for (const ShoeFrame& f : frames) {
        const std::size_t n = detector.process(f, out);
        events.insert(events.end(), out.begin(), out.begin() + static_cast<long>(n));
    }
    return events;
}

TEST(ShoeProtocol, ParsesFramesHeaderAndRejectsGarbageWithTheLineAndWhatWasExpected) {
    ShoeLineParser p;
    ShoeFrame f;
    EXPECT_EQ(p.parse("# underfoot-shoes 1 rate_hz=1000 adc_bits=10 columns=t_ms,lh,lt,rh,rt", f),
              ShoeLineKind::Header);
    EXPECT_TRUE(p.headerSeen());
    EXPECT_EQ(p.parse("123,1,2,1023,0\r", f), ShoeLineKind::Frame);
    EXPECT_EQ(f.deviceMs, 123u);
    EXPECT_EQ(f.raw[2], 1023);
    EXPECT_EQ(p.parse("124,1,2,1024,0", f), ShoeLineKind::Rejected);
    EXPECT_NE(p.error().find("line 3: expected rh (field 4) as an integer 0..1023"),
              std::string::npos)
        << p.error();
    EXPECT_EQ(p.parse("12,40,x", f), ShoeLineKind::Rejected);
    EXPECT_NE(p.error().find("line 4: expected 5 comma-separated fields"), std::string::npos);
    EXPECT_EQ(p.parse("", f), ShoeLineKind::Rejected);
    EXPECT_EQ(p.parse("-1,1,2,3,4", f), ShoeLineKind::Rejected);
    EXPECT_EQ(p.parse("1,+1,2,3,4", f), ShoeLineKind::Rejected);
    EXPECT_EQ(p.parse("4294967296,1,2,3,4", f), ShoeLineKind::Rejected);
    EXPECT_EQ(p.parse(std::string("1,2\0,3,4,5", 10), f), ShoeLineKind::Rejected);
    EXPECT_NE(p.error().find("\\x00"), std::string::npos) << p.error();
    EXPECT_EQ(p.parse("# underfoot-shoes 2 rate_hz=1000", f), ShoeLineKind::Rejected);
    EXPECT_NE(p.error().find("expected protocol version 1, got 2"), std::string::npos);
    EXPECT_EQ(p.parse("# just a comment", f), ShoeLineKind::Comment);
}

TEST(ShoeProtocol, GapsInTheDeviceClockCountLostFrames) {
    ShoeLineParser p;
    std::string why;
    EXPECT_EQ(p.gapBefore(10, why), 0u);
    EXPECT_EQ(p.gapBefore(11, why), 0u);
    EXPECT_EQ(p.gapBefore(18, why), 6u);
    EXPECT_EQ(why, "t_ms 11 -> 18: 6 frames lost");
    EXPECT_EQ(p.gapBefore(3, why), 0u); // device reset
    EXPECT_NE(why.find("restarted"), std::string::npos);
    EXPECT_EQ(p.gapBefore(0xffffffffu, why), 0u); // (restart again)
    EXPECT_EQ(p.gapBefore(0u, why), 0u);          // millis() wraps: 1 ms step
    EXPECT_TRUE(why.empty());
}

TEST(ShoeProtocol, RandomBytesNeverCrashTheParser) {
    ShoeLineParser p;
    Random r(7);
    ShoeFrame f;
    std::size_t frames = 0;
    for (int i = 0; i < 20000; ++i) {
        std::string line(r.below(80), '\0');
        for (char& c : line) c = static_cast<char>(r.below(256));
        if (p.parse(line, f) == ShoeLineKind::Frame) ++frames;
    }
    EXPECT_LT(frames, 5u);
}

TEST(StepDetector, FindsEveryScriptedStrikeAndNothingWhileStanding) {
    const ShoeScript script = defaultWalkScript(3);
    const auto frames = renderScript(script, 11);
    const auto events = detect(frames, StepThresholds{});
    const auto strikes = script.strikes();
    ASSERT_EQ(strikes.size(), 28u); // 14 steps x heel + toe
    ASSERT_EQ(events.size(), strikes.size());
    for (std::size_t i = 0; i < strikes.size(); ++i) {
        // Simultaneous strikes of different sensors may come in either order: match by sensor.
        const ShoeContact& s = strikes[i];
        const auto it = std::find_if(events.begin(), events.end(), [&](const StepEvent& e) {
            return shoeSensorIndex(e.foot, e.part) == s.sensor && e.deviceMs >= s.onMs &&
                   e.deviceMs <= s.onMs + 15;
        });
        ASSERT_NE(it, events.end()) << shoeSensorName(s.sensor) << " strike at " << s.onMs;
        EXPECT_GT(it->strength, 0.f);
        EXPECT_LE(it->strength, 1.f);
    }
}

TEST(StepDetector, WeightShiftsWhileStandingDoNotTriggerButWouldWithoutTheGuard) {
    ShoeScript script(ShoeWalkOptions{}, 1);
    script.stand(500);
    script.bump(0, 100, 200);
    script.bump(3, 600, 200);
    script.stand(1500);
    const auto frames = renderScript(script, 2);
    EXPECT_TRUE(detect(frames, StepThresholds{}).empty());
    // The derivative of the shifts is above the onset threshold: only the re-arm guard stops
    // them (a detector that considers itself released fires).
    StepThresholds noGuard;
    for (auto& s : noGuard.sensors) {
        s.releaseLevel = 1000;
        s.contactLevel = 80;
    }
    EXPECT_EQ(detect(frames, noGuard).size(), 2u);
}

TEST(StepDetector, LiftOffNeverTriggers) {
    ShoeScript script(ShoeWalkOptions{}, 1);
    script.stand(300);
    script.lift(1000); // all sensors released: negative derivatives only
    EXPECT_TRUE(detect(renderScript(script, 5), StepThresholds{}).empty());
}

TEST(StepDetector, RejectsInvalidThresholds) {
    StepThresholds t;
    t.sensors[1].onsetDerivativePerS = std::nan("");
    EXPECT_THROW(StepDetector{t}, std::invalid_argument);
    t = {};
    t.sensors[2].releaseLevel = 10;
    EXPECT_THROW(StepDetector{t}, std::invalid_argument);
}

TEST(StepCalibration, ProposesThresholdsThatDetectTheParticipantsSteps) {
    // A light participant: lower pressures and softer strikes than the defaults expect.
    ShoeWalkOptions light;
    light.heelPeak = 260;
    light.toePeak = 220;
    light.standHeel = 170;
    light.standToe = 140;
    light.riseMs = 45;
    ShoeScript record(light, 21);
    record.stand(1000);
    record.walk(20);
    record.stand(2000);
    const auto recording = renderScript(record, 4);
    StepCalibrationOptions options;
    options.participant = "P07";
    const StepCalibrationResult result = calibrateSteps(recording, options);
    for (std::size_t s = 0; s < kShoeSensorCount; ++s) {
        EXPECT_EQ(result.stats[s].strikes, 10u) << shoeSensorName(s);
        EXPECT_NEAR(result.stats[s].restLevel, 14, 3);
    }
    EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
    // Default thresholds miss or misplace this participant's steps somewhere...
    ShoeScript trial(light, 99);
    trial.stand(800);
    trial.walk(10);
    trial.bump(0, 500, 80);
    trial.stand(1500);
    trial.walk(6);
    const auto frames = renderScript(trial, 8);
    const auto strikes = trial.strikes();
    // (the weight shift of 80 units on a heel standing at 170, below the default release
    // level of 200, counts as a step)
    EXPECT_NE(detect(frames, StepThresholds{}).size(), strikes.size());
    // ...the calibrated ones find every strike, once, within 15 ms.
    const auto events = detect(frames, result.thresholds);
    ASSERT_EQ(events.size(), strikes.size());
    for (const ShoeContact& s : strikes)
        EXPECT_TRUE(std::any_of(events.begin(), events.end(),
                                [&](const StepEvent& e) {
                                    return shoeSensorIndex(e.foot, e.part) == s.sensor &&
                                           e.deviceMs >= s.onMs && e.deviceMs <= s.onMs + 15;
                                }))
            << shoeSensorName(s.sensor) << " at " << s.onMs;

    // Saved and loaded per participant.
    const auto path = (underfoot::test::scratchDir("sensors") / "p07.toml").string();
    saveStepThresholds(path, result.thresholds, &result);
    const StepThresholds loaded = loadStepThresholds(path);
    EXPECT_EQ(loaded.participant, "P07");
    for (std::size_t s = 0; s < kShoeSensorCount; ++s) {
        EXPECT_DOUBLE_EQ(loaded.sensors[s].onsetDerivativePerS,
                         result.thresholds.sensors[s].onsetDerivativePerS);
        EXPECT_DOUBLE_EQ(loaded.sensors[s].releaseLevel, result.thresholds.sensors[s].releaseLevel);
    }
}

TEST(StepCalibration, ExplainsWhyARecordingCannotBeCalibrated) {
    ShoeScript standing(ShoeWalkOptions{}, 1);
    standing.stand(5000);
    try {
        calibrateSteps(renderScript(standing, 1));
        FAIL() << "standing only";
    } catch (const CalibrationError& e) {
        EXPECT_NE(std::string(e.what()).find("left_heel"), std::string::npos) << e.what();
    }
    ShoeScript twoSteps(ShoeWalkOptions{}, 1);
    twoSteps.stand(1000);
    twoSteps.walk(4);
    twoSteps.stand(2000);
    try {
        calibrateSteps(renderScript(twoSteps, 1));
        FAIL() << "two steps per foot";
    } catch (const CalibrationError& e) {
        EXPECT_NE(std::string(e.what()).find("expected at least 4"), std::string::npos) << e.what();
    }
    EXPECT_THROW(calibrateSteps({}), CalibrationError);
}

TEST(StepCalibration, BadThresholdFilesNameTheFileThePlaceAndWhatWasExpected) {
    const auto dir = underfoot::test::scratchDir("sensors");
    auto write = [&](const std::string& name, const std::string& text) {
        const auto path = (dir / name).string();
        std::ofstream(path) << text;
        return path;
    };
    auto message = [](const std::string& path) {
        try {
            loadStepThresholds(path);
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const auto broken =
        write("broken.toml", "format = \"underfoot-step-thresholds\"\nversion = \n");
    EXPECT_NE(message(broken).find(broken + ":2:"), std::string::npos) << message(broken);
    StepThresholds t;
    const auto good = (dir / "good.toml").string();
    saveStepThresholds(good, t);
    std::ifstream in(good);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto pos = text.find("onset_derivative_per_s = ");
    ASSERT_NE(pos, std::string::npos);
    std::string nan = text;
    nan.replace(pos, std::string("onset_derivative_per_s = ").size(),
                "onset_derivative_per_s = nan #");
    const auto nanPath = write("nan.toml", nan);
    EXPECT_NE(message(nanPath).find("onset_derivative_per_s: expected a finite number"),
              std::string::npos)
        << message(nanPath);
    EXPECT_NE(message(nanPath).find(nanPath + ":"), std::string::npos);
    const auto missing = write("missing.toml", "format = \"underfoot-step-thresholds\"\nversion = "
                                               "1\nframe_rate_hz = 1000\n");
    EXPECT_NE(message(missing).find("derivative_span_ms: expected a finite number (missing)"),
              std::string::npos)
        << message(missing);
    EXPECT_NE(message((dir / "absent.toml").string()).find("absent.toml"), std::string::npos);
    // A typo is refused with its place and the nearest key, not read as the default.
    std::string typo = text;
    typo.replace(pos, std::string("onset_derivative_per_s").size(), "onset_derivative_per_sec");
    const auto typoPath = write("typo.toml", typo);
    EXPECT_NE(message(typoPath).find("unknown key 'onset_derivative_per_sec' in ["),
              std::string::npos)
        << message(typoPath);
    EXPECT_NE(message(typoPath).find("(did you mean 'onset_derivative_per_s'?)"), std::string::npos)
        << message(typoPath);
    EXPECT_NE(message(typoPath).find(typoPath + ":"), std::string::npos) << message(typoPath);
}

TEST(StepGrfPlayer, SameSeedSameGrfsAndNoAllocationOnTheAudioThread) {
    const GrfBank bank = StepGrfPlayer::loadDefaultBank(48000);
    ASSERT_EQ(bank.heel.size(), 5u);
    ASSERT_EQ(bank.toe.size(), 5u);
    auto run = [&](std::uint64_t seed, std::vector<StepPlayback>& played) {
        StepGrfPlayerConfig c;
        c.seed = seed;
        StepGrfPlayer player(bank, c);
        std::vector<float> left(64), right(64);
        float* out[] = {left.data(), right.data()};
        std::vector<float> rendered;
        rendered.reserve(48000 * 6 * 2);
        const auto strikes = defaultWalkScript(3).strikes();
        std::size_t next = 0;
        long allocations = 0;
        for (std::size_t block = 0; block < 48000 * 12 / 64; ++block) {
            const double nowMs = static_cast<double>(block * 64) / 48.0;
            while (next < strikes.size() && strikes[next].onMs <= nowMs) {
                StepEvent e;
                e.foot = shoeSensorFoot(strikes[next].sensor);
                e.part = shoeSensorPart(strikes[next].sensor);
                e.strength = 0.5f + 0.05f * static_cast<float>(next % 10);
                player.pushStep(e);
                ++next;
            }
            {
                underfoot::test::AllocationTrap trap;
                player.process(out, 64);
                allocations += trap.count();
            }
            rendered.insert(rendered.end(), left.begin(), left.end());
            rendered.insert(rendered.end(), right.begin(), right.end());
        }
        EXPECT_EQ(allocations, 0);
        StepPlayback p;
        while (player.popPlayback(p)) played.push_back(p);
        return rendered;
    };
    std::vector<StepPlayback> a, b, c;
    const auto ra = run(42, a), rb = run(42, b), rc = run(43, c);
    EXPECT_EQ(ra, rb);
    EXPECT_NE(ra, rc);
    ASSERT_EQ(a.size(), 28u);
    ASSERT_EQ(b.size(), a.size());
    std::array<int, 5> used{};
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].bankIndex, b[i].bankIndex);
        ASSERT_LT(a[i].bankIndex, 5u);
        ++used[a[i].bankIndex];
    }
    // 28 draws from 5 entries: every entry is used (probability of missing one < 5 * 0.8^28).
    for (int u : used) EXPECT_GT(u, 0);
    // The output is the bank: peak of a heel GRF x gain, on the struck foot's channel.
    const float peak = *std::max_element(ra.begin(), ra.end());
    EXPECT_GT(peak, 0.5f * 700);
    EXPECT_LT(peak, 2.0f * 820);
}

TEST(StepGrfPlayer, ResetOnTheAudioThreadReseedsWithoutAllocating) {
    const GrfBank bank = StepGrfPlayer::loadDefaultBank(48000);
    auto render = [&](StepGrfPlayer& player) {
        std::vector<float> l(64), r(64), all;
        float* out[] = {l.data(), r.data()};
        for (int b = 0; b < 200; ++b) {
            if (b % 20 == 0) {
                StepEvent e;
                e.foot = b % 40 == 0 ? Foot::Left : Foot::Right;
                e.strength = 0.8f;
                player.pushStep(e);
            }
            player.process(out, 64);
            all.insert(all.end(), l.begin(), l.end());
        }
        return all;
    };
    StepGrfPlayerConfig c;
    c.seed = 5;
    StepGrfPlayer fresh(bank, c);
    const auto expected = render(fresh);
    c.seed = 6;
    StepGrfPlayer reused(bank, c);
    render(reused);
    StepEvent pending;
    reused.pushStep(pending); // dropped by reset
    {
        underfoot::test::AllocationTrap trap;
        reused.reset(5);
        EXPECT_EQ(trap.count(), 0);
    }
    EXPECT_EQ(reused.seed(), 5u);
    EXPECT_EQ(reused.activeVoices(), 0u);
    EXPECT_EQ(render(reused), expected);
}

TEST(StepGrfPlayer, PerFootPartLayoutPutsEachSensorOnItsChannel) {
    StepGrfPlayerConfig c;
    c.layout = GrfChannelLayout::PerFootPart;
    StepGrfPlayer player(StepGrfPlayer::loadDefaultBank(48000), c);
    ASSERT_EQ(player.channels(), 4u);
    std::array<std::vector<float>, 4> ch;
    for (auto& v : ch) v.assign(256, 0.f);
    float* out[] = {ch[0].data(), ch[1].data(), ch[2].data(), ch[3].data()};
    StepEvent e;
    e.foot = Foot::Right;
    e.part = FootPart::Toe;
    e.strength = 1;
    player.pushStep(e);
    player.process(out, 256);
    EXPECT_GT(*std::max_element(ch[3].begin(), ch[3].end()), 0.f);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(*std::max_element(ch[i].begin(), ch[i].end()), 0.f);
    StepPlayback p;
    ASSERT_TRUE(player.popPlayback(p));
    EXPECT_FLOAT_EQ(p.gain, 1.f);
    EXPECT_THROW(StepGrfPlayer(GrfBank{}, StepGrfPlayerConfig{}), std::invalid_argument);
    StepGrfPlayerConfig wrongRate;
    wrongRate.sampleRateHz = 44100;
    EXPECT_THROW(StepGrfPlayer(StepGrfPlayer::loadDefaultBank(48000), wrongRate),
                 std::invalid_argument);
}

TEST(FaultMonitor, SilenceGarbageLossAndRecoveryFollowTheWindow) {
    FaultThresholds t;
    FaultMonitor m(t);
    double now = 100;
    m.opened(now);
    EXPECT_EQ(m.state(), SensorState::Waiting);
    m.update(now + 2.0);
    EXPECT_EQ(m.state(), SensorState::Waiting);
    m.update(now + 2.6);
    EXPECT_EQ(m.state(), SensorState::Silent);
    for (int i = 0; i < 600; ++i) {
        now = 103 + i * 0.001;
        m.frameAccepted(now);
        m.update(now);
    }
    EXPECT_EQ(m.state(), SensorState::Running);
    for (int i = 0; i < 20; ++i) m.lineRejected(now, "line x: expected y"); // > 2 % of 500
    m.update(now);
    EXPECT_EQ(m.state(), SensorState::Garbage);
    EXPECT_NE(m.status().message.find("line x: expected y"), std::string::npos);
    for (int i = 1; i <= 600; ++i) {
        now += 0.001;
        m.frameAccepted(now);
        m.update(now);
    }
    EXPECT_EQ(m.state(), SensorState::Running); // window clean again
    m.framesLost(now, 6, "t_ms 1 -> 8: 6 frames lost");
    m.update(now);
    EXPECT_EQ(m.state(), SensorState::Lossy);
    m.update(now + 0.5);
    EXPECT_EQ(m.state(), SensorState::Silent);
    m.disconnected(now + 0.5, "gone");
    EXPECT_EQ(m.state(), SensorState::Disconnected);
    EXPECT_FALSE(m.recordable());
    EXPECT_EQ(m.status().faults, 3u); // silent, garbage, lossy (lossy -> silent -> disconnected:
                                      // one fault episode)
}

} // namespace
