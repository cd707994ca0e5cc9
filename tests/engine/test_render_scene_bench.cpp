// SPDX-License-Identifier: GPL-3.0-or-later
// The scene benchmark's timing (engine/render/SceneBench) and the scene reset it relies on.
#include "engine/render/Renderer.h"
#include "engine/render/SceneBench.h"

#include "tests/common/CliRun.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <vector>

using namespace underfoot::engine;

namespace {
using underfoot::test::CommandResult;
CommandResult runUnderfoot(const std::string& args) {
    return underfoot::test::runUnderfootCli(args);
}

std::vector<float> renderBlocks(FootstepScene& scene, const GrfSignal& grf, int block) {
    std::vector<float> out, l(static_cast<std::size_t>(block)), r(l.size());
    for (std::size_t s = 0; s + static_cast<std::size_t>(block) <= grf.frames();
         s += static_cast<std::size_t>(block)) {
        const float* g = grf.channels[0].data() + s;
        scene.process(&g, l.data(), r.data(), block);
        out.insert(out.end(), l.begin(), l.end());
        out.insert(out.end(), r.begin(), r.end());
    }
    return out;
}
} // namespace

// A reset scene must do what a fresh one does, reverb included: the benchmark's repeats rely on
// it (block b does the same work in every repeat) and so does "same seed, same samples".
TEST(FootstepScene, AResetSceneWithReverbRendersWhatAFreshOneRenders) {
    const GrfSignal grf = walkerGrf({}, 1.5, 48000.0, 4);
    SceneOptions options;
    options.voices = 1;
    FootstepScene fresh, reused;
    fresh.build("wood_reverb", options);
    reused.build("wood_reverb", options);
    ASSERT_TRUE(fresh.hasReverb());
    for (auto* s : {&fresh, &reused}) s->prepare({48000.0, 64});
    fresh.reset(9);
    reused.reset(3);
    (void)renderBlocks(reused, grf, 64); // leaves a reverb tail and a voice state behind
    reused.reset(9);
    const auto a = renderBlocks(fresh, grf, 64);
    const auto b = renderBlocks(reused, grf, 64);
    ASSERT_EQ(a.size(), b.size());
    float peak = 0;
    for (float v : a) peak = std::max(peak, std::fabs(v));
    EXPECT_GT(peak, 0.0f);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "sample " << i;
}

TEST(SceneBench, TimeBlocksRunsEveryBlockOfEveryRepeatAfterAReset) {
    int resets = 0;
    std::vector<int> calls(7, 0);
    const auto s = timeBlocks(
        7, 3, 64, 48000.0, [&] { ++resets; }, [&](std::size_t b) { ++calls.at(b); });
    EXPECT_EQ(resets, 3);
    for (int c : calls) EXPECT_EQ(c, 3);
    EXPECT_EQ(s.blocks, 7u);
    EXPECT_EQ(s.repeats, 3);
    EXPECT_LE(s.medianUs, s.p99Us);
    EXPECT_LE(s.p99Us, s.worstUs);
    EXPECT_THROW(timeBlocks(
                     0, 1, 64, 48000.0, [] {}, [](std::size_t) {}),
                 std::invalid_argument);
    EXPECT_THROW(timeBlocks(
                     1, 0, 64, 48000.0, [] {}, [](std::size_t) {}),
                 std::invalid_argument);
}

TEST(SceneBench, MeasuresAReverbSurfaceAndReportsConsistentFigures) {
    SceneBenchSpec spec;
    spec.surface = "wood_reverb";
    spec.seconds = 1.0;
    spec.repeats = 2;
    const auto r = measureScene(spec);
    EXPECT_TRUE(r.hasReverb);
    EXPECT_GT(r.irLength, 10000u);
    EXPECT_GT(r.checksum, 0.0);
    const auto& s = r.stats;
    EXPECT_GE(s.blocks, 48000u / 64u);
    EXPECT_GT(s.realTimeFactor, 0.0);
    // ns/sample and x real time are the same measurement.
    EXPECT_NEAR(s.nsPerSample * s.realTimeFactor, 1e9 / 48000.0, 1e-3 * 1e9 / 48000.0);
    EXPECT_GT(s.medianUs, 0.0);
    EXPECT_LE(s.medianUs, s.p99Us);
    EXPECT_LE(s.p99Us, s.worstUs);
    EXPECT_NEAR(s.budgetShare(), s.worstUs / (1e6 * 64 / 48000.0), 1e-12);

    spec.reverb = ReverbMode::Off;
    const auto dry = measureScene(spec);
    EXPECT_FALSE(dry.hasReverb);
    EXPECT_EQ(dry.irLength, 0u);
    spec.surface = "no_such_surface";
    EXPECT_ANY_THROW(measureScene(spec));
}

// `underfoot bench --only scene-instructions` runs SceneBlocks block by block under callgrind:
// it must do the work measureScene times (the same blocks and samples; a reset starts over).
TEST(SceneBench, SceneBlocksDoesTheWorkMeasureSceneTimes) {
    SceneBenchSpec spec;
    spec.surface = "wood_reverb";
    spec.voices = 2;
    spec.seconds = 1.0;
    spec.repeats = 1;
    const auto timed = measureScene(spec);
    SceneBlocks scene(spec);
    EXPECT_EQ(scene.blocks(), timed.stats.blocks);
    EXPECT_TRUE(scene.hasReverb());
    EXPECT_EQ(scene.reverbLength(), timed.irLength);
    for (int run = 0; run < 2; ++run) {
        scene.reset();
        for (std::size_t b = 0; b < scene.blocks(); ++b) scene.process(b);
        EXPECT_EQ(scene.checksum(), timed.checksum) << "run " << run;
    }
    spec.voices = 3;
    EXPECT_THROW(SceneBlocks{spec}, std::invalid_argument);
}

// `underfoot bench --only surfaces` prints one row per surface from SceneBench, reverb presets
// with their IR length.
TEST(SceneBench, BenchCommandPrintsEverySurfaceWithItsBlockFigures) {
    const auto r = runUnderfoot("bench --only surfaces --seconds 0.5 --repeats 1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("| wood | - |"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("| wood_reverb | 42240 |"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("worst / median"), std::string::npos);
    const auto bad = runUnderfoot("bench --only no_such_part");
    EXPECT_NE(bad.exitCode, 0);
    EXPECT_NE(bad.output.find("--only"), std::string::npos) << bad.output;
}
