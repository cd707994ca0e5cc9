// SPDX-License-Identifier: GPL-3.0-or-later
// A live FSR trial end to end with real components: emulated shoes (ShoeScript at 1 kHz) on a
// socat pseudo-terminal pair -> SerialSource -> StepInput -> StepGrfPlayer as the scene's GRF
// source in a LiveEngine driven offline -> LivePlayer -> Session -> StudyStore. The writer dies
// mid-trial: the session pauses within a second and nothing broken is committed; the shoes come
// back, the trial is presented again and answered; its sensor log and audio figures are stored.
#include "app/wiring/Adapters.h"
#include "app/wiring/Players.h"
#include "engine/dsp/Random.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "experiment/Export.h"
#include "experiment/Session.h"
#include "tests/common/PacedOfflineEngine.h"
#include "tests/common/SocatHelpers.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace eng = underfoot::engine;
namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;
using underfoot::test::SocatPair;

namespace {

/// The shoes' silence limit in these tests (the product's default is 400 ms).
constexpr double kSilenceMs = 1000;

const char* kProtocol = R"(
[protocol]
id = "fsr_live"
version = 1
title = "FSR live"
[design]
type = "within"
[input]
type = "sensor"
sensor = "fsr"
[[stimuli]]
id = "WD"
surface = "wood"
[ordering]
repetitions = 2
[questions.surface]
options = ["wood", "gravel"]
)";

/// Writes the script's lines at 1 kHz from its own thread, continuing the device clock where
/// the previous writer stopped (a writer that "dies" just stops writing).
class ShoeWriter {
  public:
    ShoeWriter(int fd, const eng::ShoeScript& script, std::size_t firstTick, bool header)
        : thread_([this, fd, &script, firstTick, header] {
              if (header) underfoot::test::writeAll(fd, eng::shoeHeaderLine());
              eng::Random noise(3 + firstTick);
              const auto start = std::chrono::steady_clock::now();
              for (std::size_t i = 0; !stop_.load(); ++i) {
                  std::this_thread::sleep_until(start + std::chrono::milliseconds(i));
                  const std::size_t tick = firstTick + i;
                  if (!underfoot::test::writeAll(
                          fd, eng::formatShoeLine(static_cast<std::uint32_t>(tick),
                                                  script.sample(tick, noise))))
                      break;
                  next_ = tick + 1;
                  lastWriteS_ = eng::sensorClockSeconds();
              }
          }) {}
    ~ShoeWriter() { kill(); }
    /// Stops writing; returns the sensor-clock time of the last line written.
    double kill() {
        stop_ = true;
        if (thread_.joinable()) thread_.join();
        return lastWriteS_.load();
    }
    std::size_t nextTick() const { return next_.load(); }

  private:
    std::atomic<bool> stop_{false};
    std::atomic<std::size_t> next_{0};
    std::atomic<double> lastWriteS_{0};
    std::thread thread_;
};

/// Polls the session like the GUI's timer (every 10 ms) until `done` or `timeoutS`.
template <class Done>
bool pollUntil(xp::Session& session, double timeoutS, Done done) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutS);
    while (std::chrono::steady_clock::now() < until) {
        session.checkSensors();
        if (done()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return done();
}

bool waitRunning(const eng::SerialSource& source, double timeoutS) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutS);
    while (std::chrono::steady_clock::now() < until) {
        if (source.recordable()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

std::map<std::string, int> countKinds(const std::string& csvPath) {
    std::ifstream in(csvPath);
    std::map<std::string, int> kinds;
    std::string line;
    std::getline(in, line); // header
    while (std::getline(in, line)) {
        const auto a = line.find(',');
        const auto b = line.find(',', a + 1);
        ++kinds[line.substr(a + 1, b - a - 1)];
    }
    return kinds;
}

} // namespace

TEST(SessionSensors, AWriterDyingMidTrialPausesTheSessionAndTheTrialIsPresentedAgain) {
    if (!underfoot::test::socatInstalled()) GTEST_SKIP() << "socat is not installed";
    auto pair = std::make_unique<SocatPair>("session");
    ASSERT_TRUE(pair->ready());
    eng::ShoeScript script(eng::ShoeWalkOptions{}, 8);
    script.stand(500);
    script.walk(80); // ~45 s of walking: more than the test writes

    // The shoes as the app wires them.
    eng::SerialConfig config;
    config.path = pair->app;
    // The emulated shoes are a thread of this process. On a loaded machine (sanitizers, a build
    // beside the tests) it was descheduled for 402 ms, longer than the default 400 ms limit, and
    // the session rightly paused while the test expected a healthy stream. The pause logic is
    // the same for any limit: 1 s here, and the pause must follow it within 0.6 s.
    config.faults.silenceMs = kSilenceMs;
    auto shoes = std::make_shared<eng::SerialSource>(config);
    eng::StepGrfPlayerConfig playerConfig;
    playerConfig.seed = 77;
    auto stepPlayer = std::make_shared<eng::StepGrfPlayer>(
        eng::StepGrfPlayer::loadDefaultBank(48000), playerConfig);
    auto steps = std::make_shared<eng::StepInput>(eng::StepThresholds{});
    steps->attach(*shoes, stepPlayer.get());
    shoes->start();

    // The engine without a device: a thread runs the callback body block by block.
    underfoot::test::PacedOfflineEngine offline;
    eng::LiveEngine& engine = offline.engine;

    const fs::path study = underfoot::test::scratchDir("session_sensors") / "study";
    fs::create_directories(study);
    xp::StudyStore store =
        xp::StudyStore::create((study / "study.db").string(),
                               xp::parseProtocol(kProtocol, "fsr.toml"), {"F", "lab", 1, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    wir::LivePlayerOptions o;
    o.studyFolder = study.string();
    o.recordingFolder = (study / "recordings").string();
    o.scene.fsrSource = std::make_shared<wir::StepGrfSource>(stepPlayer);
    o.shoes = shoes;
    o.shoeSteps = steps;
    wir::LivePlayer player(engine, o);
    xp::Session session(store, "P1", player, {"E", "offline 48000/64", "fsr pty", "t"});
    session.finishBriefing();

    int fd = underfoot::test::openWriter(pair->shoes);
    ASSERT_GE(fd, 0);
    auto writer = std::make_unique<ShoeWriter>(fd, script, 0, true);
    ASSERT_TRUE(waitRunning(*shoes, 5.0)) << shoes->status().message;

    // First presentation: 1.2 s of walking, then the writer dies.
    const int index = session.current().index;
    session.play();
    EXPECT_FALSE(pollUntil(session, 1.2, [&] { return session.paused(); }))
        << "paused while the shoes were fine: " << session.pauseReason();
    const double lastLineS = writer->kill();
    ASSERT_TRUE(pollUntil(session, 3.0, [&] { return session.paused(); }));
    const double pauseDelayS = eng::sensorClockSeconds() - lastLineS;
    std::printf("[ measured ] last shoe line -> session paused: %.0f ms (%s)\n", pauseDelayS * 1e3,
                session.pauseReason().c_str());
    EXPECT_GE(pauseDelayS, kSilenceMs / 1e3 - 0.05);
    EXPECT_LT(pauseDelayS, kSilenceMs / 1e3 + 0.6);
    EXPECT_NE(session.pauseReason().find("FSR shoes silent"), std::string::npos)
        << session.pauseReason();
    EXPECT_FALSE(player.playing());
    EXPECT_THROW(session.play(), std::logic_error);
    EXPECT_THROW(session.resumeAfterFault(), std::logic_error); // the shoes are still silent
    {
        const xp::TrialRecord t = store.trial("P1", index);
        EXPECT_FALSE(t.answered) << "a broken trial was committed";
        EXPECT_EQ(t.interruptions, 1);
        EXPECT_EQ(t.interruptionReason, session.pauseReason());
        EXPECT_EQ(store.firstUnanswered("P1"), index);
    }

    // The shoes come back: the participant resumes at the same trial.
    writer = std::make_unique<ShoeWriter>(fd, script, writer->nextTick(), false);
    ASSERT_TRUE(waitRunning(*shoes, 5.0)) << shoes->status().message;
    session.resumeAfterFault();
    ASSERT_EQ(session.current().index, index);
    session.play();
    EXPECT_FALSE(pollUntil(session, 2.0, [&] { return session.paused(); }))
        << session.pauseReason();
    xp::TrialAnswer answer;
    answer.answer = "wood";
    session.answer(answer);

    // The second trial: the port goes away (socat dies: an unplugged cable), then comes back at
    // the same path and the source reopens it.
    const int second = session.current().index;
    ASSERT_NE(second, index);
    session.play();
    EXPECT_FALSE(pollUntil(session, 0.8, [&] { return session.paused(); }))
        << session.pauseReason();
    const double unplugS = pair->kill();
    ASSERT_TRUE(pollUntil(session, 3.0, [&] { return session.paused(); }));
    const double unplugDelayS = eng::sensorClockSeconds() - unplugS;
    std::printf("[ measured ] port gone -> session paused: %.0f ms (%s)\n", unplugDelayS * 1e3,
                session.pauseReason().c_str());
    EXPECT_LT(unplugDelayS, 1.0);
    writer->kill();
    ::close(fd);
    EXPECT_FALSE(store.trial("P1", second).answered);
    EXPECT_EQ(store.trial("P1", second).interruptions, 1);
    pair = std::make_unique<SocatPair>("session"); // same link paths
    ASSERT_TRUE(pair->ready());
    fd = underfoot::test::openWriter(pair->shoes);
    ASSERT_GE(fd, 0);
    writer = std::make_unique<ShoeWriter>(fd, script, writer->nextTick(), true);
    ASSERT_TRUE(waitRunning(*shoes, 6.0)) << shoes->status().message;
    session.resumeAfterFault();
    ASSERT_EQ(session.current().index, second);
    session.play();
    EXPECT_FALSE(pollUntil(session, 1.0, [&] { return session.paused(); }))
        << session.pauseReason();
    session.answer(answer);
    EXPECT_EQ(session.phase(), xp::SessionPhase::Finished);
    EXPECT_TRUE(store.trial("P1", second).answered);
    EXPECT_TRUE(store.trial("P1", second).sensorLog.has_value());
    writer->kill();
    ::close(fd);
    offline.stop();
    shoes->stop();

    const xp::TrialRecord t = store.trial("P1", index);
    ASSERT_TRUE(t.answered);
    EXPECT_EQ(t.interruptions, 1);
    ASSERT_TRUE(t.sensorLog.has_value());
    ASSERT_TRUE(t.grfRecording.has_value());
    EXPECT_EQ(fs::path(*t.sensorLog).parent_path(), "recordings") << *t.sensorLog;
    const fs::path log = study / *t.sensorLog;
    ASSERT_TRUE(fs::exists(log)) << log;
    EXPECT_TRUE(fs::exists(study / *t.grfRecording));
    const auto kinds = countKinds(log.string());
    std::printf("[ measured ] sensor log of the valid presentation: %d frames, %d steps, %d grfs\n",
                kinds.count("frame") ? kinds.at("frame") : 0,
                kinds.count("step") ? kinds.at("step") : 0,
                kinds.count("grf") ? kinds.at("grf") : 0);
    EXPECT_GT(kinds.count("frame") ? kinds.at("frame") : 0, 1500); // ~2 s at 1 kHz
    EXPECT_GT(kinds.count("step") ? kinds.at("step") : 0, 0);
    EXPECT_EQ(kinds.count("step") ? kinds.at("step") : 0,
              kinds.count("grf") ? kinds.at("grf") : 0); // every step played a bank GRF
    ASSERT_TRUE(t.audio.has_value());
    EXPECT_EQ(t.audio->blockSize, 64);
    EXPECT_DOUBLE_EQ(t.audio->sampleRateHz, 48000.0);
    EXPECT_GT(t.audio->frames, 48000u * 3 / 2);
    EXPECT_EQ(t.audio->droppedGrfFrames, 0u);
    std::printf("[ measured ] trial audio: %llu frames, %llu xruns, avg load %.3f %%, max block "
                "%.4f ms\n",
                static_cast<unsigned long long>(t.audio->frames),
                static_cast<unsigned long long>(t.audio->xruns), t.audio->averageLoadPercent,
                t.audio->maxBlockMs);

    std::ostringstream csv;
    EXPECT_EQ(xp::writeAudioCsv(store, csv), 2);
    EXPECT_NE(csv.str().find(*t.sensorLog), std::string::npos);
}

TEST(SessionSensors, GyroTrialsReportTheReceiversFaults) {
    // A water stimulus wading with the gyroscopes, a real OSC receiver on a free port and no
    // sender: the trial's sensor is not recordable, so the session would pause.
    eng::LiveEngine engine;
    eng::AudioSettings audioSettings;
    audioSettings.sampleRateHz = 48000;
    audioSettings.blockSize = 64;
    engine.openOffline(audioSettings);
    eng::OscGyroConfig gyroConfig;
    gyroConfig.port = 0;
    auto receiver = std::make_shared<eng::OscGyroReceiver>(gyroConfig);
    receiver->start();
    wir::LivePlayerOptions o;
    o.scene.gyroReceiver = receiver;
    wir::LivePlayer player(engine, o);
    xp::Stimulus water;
    water.id = "wade_gyro";
    water.surface = "water";
    water.input.kind = xp::InputKind::Sensor;
    water.input.sensor = xp::SensorKind::Gyro;
    water.wading["depth"] = std::string("deep");
    EXPECT_FALSE(player.sensorFault()); // nothing played yet
    player.start(water, 9);
    const auto fault = player.sensorFault();
    ASSERT_TRUE(fault.has_value());
    EXPECT_EQ(fault->rfind("gyroscopes ", 0), 0u) << *fault;
    player.stop();
    EXPECT_TRUE(player.sensorFault()); // still the last trial's sensor: not back yet

    xp::Stimulus walked = water; // the virtual gait needs no sensor
    walked.input.kind = xp::InputKind::Walker;
    walked.input.sensor = xp::SensorKind::None;
    player.start(walked, 9);
    EXPECT_FALSE(player.sensorFault());
    player.stop();
    receiver->stop();
}
