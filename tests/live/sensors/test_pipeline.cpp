// SPDX-License-Identifier: GPL-3.0-or-later
// The FSR control path of a live scene end to end: emulated shoes on a socat pty -> SerialSource
// -> StepInput (detector on the reader thread) -> StepGrfPlayer run by a block-paced "audio"
// thread -> sensor log (CSV) written by the main thread from the queues.
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/SensorLog.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "tests/common/SocatHelpers.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace {

using namespace underfoot::engine;
using namespace underfoot::test;

std::vector<std::vector<std::string>> readCsv(const std::string& path) {
    std::ifstream in(path);
    std::vector<std::vector<std::string>> rows;
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) cells.push_back(cell);
        if (!line.empty() && line.back() == ',') cells.emplace_back();
        rows.push_back(cells);
    }
    return rows;
}

TEST(SensorPipeline, StepsFromTheShoesPlayBankGrfsAndEverythingIsLogged) {
    if (!socatInstalled()) GTEST_SKIP() << "socat is not installed (apt-get install socat)";
    SocatPair pair("pipeline");
    ASSERT_TRUE(pair.ready());
    ShoeScript script(ShoeWalkOptions{}, 8);
    script.stand(400);
    script.walk(6);
    script.stand(300);
    const auto strikes = script.strikes();
    const auto ticks = static_cast<std::size_t>(script.durationMs());

    SerialConfig config;
    config.path = pair.app;
    SerialSource source(config);
    StepGrfPlayerConfig playerConfig;
    playerConfig.seed = 77;
    StepGrfPlayer player(StepGrfPlayer::loadDefaultBank(48000), playerConfig);
    StepInput input{StepThresholds{}};
    input.attach(source, &player);
    source.start();
    const double origin = sensorClockSeconds();
    const std::string logPath = (scratchDir("sensors_log") / "trial_sensors.csv").string();
    SensorLogWriter log(logPath, origin);

    std::atomic<bool> audioRunning{true};
    std::atomic<double> peakN{0};
    std::thread audio([&] { // 64-frame blocks at 48 kHz, paced like a device callback
        std::vector<float> left(64), right(64);
        float* out[] = {left.data(), right.data()};
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t b = 0; audioRunning.load(); ++b) {
            std::this_thread::sleep_until(start + std::chrono::microseconds(b * 4000 / 3));
            player.process(out, 64);
            for (std::size_t i = 0; i < 64; ++i)
                if (left[i] + right[i] > peakN.load()) peakN = left[i] + right[i];
        }
    });
    const int fd = openWriter(pair.shoes);
    ASSERT_GE(fd, 0);
    Random noise(3);
    std::thread writer([&] {
        writeAll(fd, shoeHeaderLine());
        paced(fd, ticks, [&](std::size_t i) {
            return formatShoeLine(static_cast<std::uint32_t>(i), script.sample(i, noise));
        });
    });
    std::size_t frames = 0, steps = 0, playbacks = 0;
    auto drain = [&] {
        ShoeFrame f;
        while (source.popFrame(f)) log.write(f), ++frames;
        StepEvent e;
        while (input.popEvent(e)) log.write(e), ++steps;
        StepPlayback p;
        while (player.popPlayback(p)) log.write(p), ++playbacks;
    };
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ticks + 300);
    while (std::chrono::steady_clock::now() < until) {
        drain();
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    writer.join();
    source.stop();
    audioRunning = false;
    audio.join();
    drain();
    log.flush();
    ::close(fd);

    EXPECT_EQ(frames, ticks);
    EXPECT_EQ(steps, strikes.size());
    EXPECT_EQ(playbacks, strikes.size()); // every step reached the audio thread
    EXPECT_EQ(input.eventsDropped(), 0u);
    EXPECT_EQ(player.stepsDropped(), 0u);
    EXPECT_GT(peakN.load(), 500.0); // a bank GRF (peaks 733-820 N) x gain >= 0.5 sounded

    const auto rows = readCsv(logPath);
    ASSERT_EQ(rows.size(), 1 + frames + steps + playbacks);
    ASSERT_EQ(rows[0].size(), 18u);
    EXPECT_EQ(rows[0][0], "time_s");
    std::size_t frameRows = 0, stepRows = 0, grfRows = 0;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        ASSERT_EQ(rows[r].size(), 18u) << "row " << r;
        if (rows[r][1] == "frame") ++frameRows;
        if (rows[r][1] == "step") ++stepRows;
        if (rows[r][1] == "grf") {
            ++grfRows;
            const int bankIndex = std::stoi(rows[r][12]);
            EXPECT_GE(bankIndex, 0);
            EXPECT_LT(bankIndex, 5);
        }
    }
    EXPECT_EQ(frameRows, frames);
    EXPECT_EQ(stepRows, steps);
    EXPECT_EQ(grfRows, playbacks);
}

TEST(SensorLog, AnUnwritableLogIsAClearError) {
    try {
        SensorLogWriter log("/nonexistent-dir/x.csv", 0);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.csv"), std::string::npos);
    }
}

} // namespace
