// SPDX-License-Identifier: GPL-3.0-or-later
// engine/scene/TestTone: the Setup view's test tone. A tone scene run by the offline engine
// puts a sine of the asked frequency and level on the chosen output channel only (the
// engine's crossfade at the start), allocation-free; bad settings are refused with the reason.
#include "engine/scene/LiveEngine.h"
#include "engine/scene/TestTone.h"
#include "tests/common/AllocationTrap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace eng = underfoot::engine;
using underfoot::test::AllocationTrap;

namespace {

struct Run {
    std::vector<std::vector<float>> out; ///< per device output
    long allocations = 0;
};

/// Runs the offline engine (6 outputs: headphones 0/1, actuators 2-5) with a tone scene.
Run runTone(int channel, const eng::TestToneSettings& tone, int blocks) {
    eng::AudioSettings s;
    s.sampleRateHz = 48000;
    s.blockSize = 64;
    s.channels.haptic[0] = {2, 3};
    s.channels.haptic[1] = {4, 5};
    eng::LiveEngine engine;
    engine.openOffline(s);
    EXPECT_TRUE(engine.submit(eng::makeTestToneScene(channel, tone, engine.processSpec())));
    const auto outputs = static_cast<std::size_t>(engine.outputChannels());
    std::vector<std::vector<float>> block(outputs, std::vector<float>(64));
    std::vector<float*> op;
    for (auto& c : block) op.push_back(c.data());
    Run run;
    run.out.resize(outputs);
    for (auto& c : run.out) c.reserve(static_cast<std::size_t>(blocks) * 64);
    {
        AllocationTrap trap;
        for (int b = 0; b < blocks; ++b) {
            engine.processBlock(nullptr, op.data(), 64);
            for (std::size_t c = 0; c < outputs; ++c)
                run.out[c].insert(run.out[c].end(), block[c].begin(), block[c].end());
        }
        run.allocations = trap.count();
    }
    return run;
}

} // namespace

TEST(TestTone, HeadphoneToneIsA1kHzSineAtMinus20dBFSOnItsChannelOnly) {
    const int blocks = 750; // 1 s
    const auto run = runTone(1, eng::kHeadphoneTestTone, blocks);
    EXPECT_EQ(run.allocations, 0) << "the callback with a tone scene must not allocate";
    const auto& x = run.out[1];
    // After the 10 ms crossfade: the exact sine, phase 0 at the scene's first sample.
    const double amplitude = 0.1; // -20 dBFS peak
    double maxError = 0, sumSquares = 0;
    std::size_t n = 0;
    for (std::size_t i = 960; i < x.size(); ++i, ++n) {
        const double expected = amplitude * std::sin(2.0 * std::numbers::pi * 1000.0 *
                                                     static_cast<double>(i) / 48000.0);
        maxError = std::max(maxError, std::abs(x[i] - expected));
        sumSquares += static_cast<double>(x[i]) * x[i];
    }
    EXPECT_LT(maxError, 1e-5);
    const double rmsDb = 10.0 * std::log10(sumSquares / static_cast<double>(n));
    EXPECT_NEAR(rmsDb, -20.0 - 3.0103, 0.01); // a sine's RMS is its peak - 3.01 dB
    // Positive-going zero crossings over the steady part: 1000 per second.
    int crossings = 0;
    for (std::size_t i = 961; i < x.size(); ++i) crossings += (x[i - 1] < 0 && x[i] >= 0) ? 1 : 0;
    EXPECT_NEAR(crossings, 980, 1); // 0.98 s of 1 kHz
    for (std::size_t c = 0; c < run.out.size(); ++c) {
        if (c == 1) continue;
        for (float v : run.out[c]) ASSERT_EQ(v, 0.0f) << "output " << c << " must stay silent";
    }
}

TEST(TestTone, ActuatorToneIs200HzInsideTheHapticBand) {
    const auto run = runTone(4, eng::kHapticTestTone, 750);
    const auto& x = run.out[4];
    int crossings = 0;
    float peak = 0;
    for (std::size_t i = 961; i < x.size(); ++i) {
        crossings += (x[i - 1] < 0 && x[i] >= 0) ? 1 : 0;
        peak = std::max(peak, std::abs(x[i]));
    }
    EXPECT_NEAR(crossings, 196, 1);
    EXPECT_NEAR(peak, 0.1, 1e-4);
    for (float v : run.out[0]) ASSERT_EQ(v, 0.0f);
    for (float v : run.out[2]) ASSERT_EQ(v, 0.0f);
}

TEST(TestTone, BadSettingsAreRefusedWithTheReason) {
    const eng::ProcessSpec spec{48000.0, 64};
    EXPECT_THROW(eng::makeTestToneScene(-1, eng::kHeadphoneTestTone, spec), std::invalid_argument);
    EXPECT_THROW(eng::TestTone(0.0, -20.0), std::invalid_argument);
    EXPECT_THROW(eng::TestTone(std::nan(""), -20.0), std::invalid_argument);
    EXPECT_THROW(eng::TestTone(1000.0, 3.0), std::invalid_argument);
    EXPECT_THROW(eng::TestTone(1000.0, INFINITY), std::invalid_argument);
    try {
        eng::makeTestToneScene(0, {30000.0, -20.0}, spec);
        FAIL() << "30 kHz at 48 kHz must be refused";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("half the sample rate"), std::string::npos)
            << e.what();
    }
}
