// SPDX-License-Identifier: GPL-3.0-or-later
// Offline rendering: the scene, the renderer and the `underfoot render` command end to end.
#include "engine/control/GrfFile.h"
#include "engine/dsp/Denormals.h"
#include "engine/render/AccuracyCost.h"
#include "engine/render/AudioFeatures.h"
#include "engine/render/Renderer.h"

#include "tests/common/ScratchDir.h"

#include "tests/common/CliRun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

using namespace underfoot::engine;
namespace fs = std::filesystem;

namespace {
using underfoot::test::CommandResult;
CommandResult run(const std::string& args) {
    return underfoot::test::runUnderfootCli(args);
}
fs::path tempDir() {
    return underfoot::test::scratchDir("test_render");
}
} // namespace

TEST(FootstepScene, ADryStimulusHasNoReverbNodeAndAReverbStimulusHasOne) {
    FootstepScene dry, wet, forcedDry;
    dry.build("wood");
    wet.build("wood_reverb");
    SceneOptions off;
    off.reverb = ReverbMode::Off;
    forcedDry.build("wood_reverb", off);
    EXPECT_FALSE(dry.hasReverb());
    EXPECT_TRUE(wet.hasReverb());
    EXPECT_FALSE(forcedDry.hasReverb());
}

TEST(FootstepScene, DryScenesSpendNothingOnReverb) {
    const auto grf = walkerGrf({}, 2.0, 48000.0, 1);
    RenderOptions options;
    const auto dry = renderSurface("wood", grf, options);
    const auto wet = renderSurface("wood_reverb", grf, options);
    EXPECT_EQ(dry.cost.reverbSeconds, 0.0);
    EXPECT_FALSE(dry.cost.hasReverb);
    EXPECT_GT(wet.cost.reverbSeconds, 0.0);
    // Same footsteps, plus a tail: the reverberated render holds more energy after each step.
    const auto fd = computeFeatures(dry.audio), fw = computeFeatures(wet.audio);
    EXPECT_GT(fw.activeShare, fd.activeShare);
}

TEST(Renderer, TheWalkerStopsAfterCompletingItsLastSteps) {
    const auto grf = walkerGrf({}, 3.0, 48000.0, 1);
    EXPECT_GE(grf.durationSeconds(), 3.0);
    for (const auto& c : grf.channels) EXPECT_EQ(c.back(), 0.0f);
}

TEST(Renderer, EverySampleRateFrom22To192kHzGivesFiniteSimilarSound) {
    for (const std::string surface : {"wood", "gravel", "creaking_wood"}) {
        double centroid48 = 0;
        for (const double fs : {22050.0, 48000.0, 96000.0, 192000.0}) {
            const auto grf = walkerGrf({}, 2.0, fs, 1);
            RenderOptions options;
            options.sampleRateHz = fs;
            const auto r = renderSurface(surface, grf, options);
            for (float v : r.audio.samples) ASSERT_TRUE(std::isfinite(v)) << surface << " " << fs;
            const auto f = computeFeatures(r.audio);
            EXPECT_GT(f.peakDb, -40.0) << surface << " " << fs;
            EXPECT_LT(f.peakDb, 0.0) << surface << " " << fs;
            if (fs == 48000.0) centroid48 = f.centroidHz;
            if (fs >= 48000.0) { // the same sound, within the band 48 kHz can hold
                EXPECT_NEAR(f.centroidHz / centroid48, 1.0, 0.35) << surface << " " << fs;
            }
        }
    }
}

TEST(Renderer, LongRenderHasNoLevelDriftAndFlushesDenormals) {
    // Ten minutes of walking on wood: the last minute sounds like the first (no drift of state)
    // and the render thread runs with denormals flushed.
    EXPECT_FALSE(ScopedFlushDenormals::active());
    const double minutes = 10.0;
    const auto grf = walkerGrf({}, minutes * 60.0, 48000.0, 9);
    RenderOptions options;
    const auto r = renderSurface("wood", grf, options);
    EXPECT_TRUE(r.flushedDenormals);
    EXPECT_FALSE(ScopedFlushDenormals::active()); // restored afterwards
    AudioBuffer first, last;
    first.sampleRateHz = last.sampleRateHz = 48000.0;
    first.channels = last.channels = 2;
    const std::size_t minute = 48000 * 60 * 2;
    first.samples.assign(r.audio.samples.begin(),
                         r.audio.samples.begin() + static_cast<long>(minute));
    const std::size_t end = static_cast<std::size_t>(minutes * 48000 * 60 * 2);
    last.samples.assign(r.audio.samples.begin() + static_cast<long>(end - minute),
                        r.audio.samples.begin() + static_cast<long>(end));
    const auto a = computeFeatures(first), b = computeFeatures(last);
    EXPECT_NEAR(a.rmsDb, b.rmsDb, 0.5);
    EXPECT_NEAR(a.centroidHz / b.centroidHz, 1.0, 0.05);
}

TEST(RenderCommand, SameSeedSameFileOtherSeedOtherFile) {
    const auto dir = tempDir();
    const std::string a = (dir / "a.wav").string(), b = (dir / "b.wav").string(),
                      c = (dir / "c.wav").string();
    ASSERT_EQ(run("render --surface gravel --walker cadence=100 --seconds 3 --seed 7 -q -o " + a)
                  .exitCode,
              0);
    ASSERT_EQ(run("render --surface gravel --walker cadence=100 --seconds 3 --seed 7 -q -o " + b)
                  .exitCode,
              0);
    ASSERT_EQ(run("render --surface gravel --walker cadence=100 --seconds 3 --seed 8 -q -o " + c)
                  .exitCode,
              0);
    const auto ra = readAudioFile(a), rb = readAudioFile(b), rc = readAudioFile(c);
    EXPECT_EQ(ra.samples, rb.samples);
    EXPECT_NE(ra.samples, rc.samples);
    EXPECT_EQ(ra.channels, 2);
    EXPECT_GE(double(ra.frames()) / ra.sampleRateHz, 3.0);
}

TEST(RenderCommand, RendersFromAGrfFile) {
    const auto dir = tempDir();
    GrfSignal grf = walkerGrf({}, 2.0, 48000.0, 3);
    grf.channels.resize(1);
    grf.names.resize(1);
    writeGrfWav((dir / "step.wav").string(), grf, 1000.0);
    const auto r = run("render --surface wood --grf " + (dir / "step.wav").string() + " -o " +
                       (dir / "from_grf.wav").string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto f = computeFeatures(readAudioFile((dir / "from_grf.wav").string()));
    EXPECT_GT(f.peakDb, -30.0);
}

TEST(RenderCommand, BadInputGetsAClearMessageAndExitCode2) {
    const auto dir = tempDir();
    {
        std::ofstream csv(dir / "nan.csv");
        csv << "time_s,left\n0,0\n0.001,nan\n0.002,10\n";
    }
    auto r = run("render --surface wood --grf " + (dir / "nan.csv").string() + " -o " +
                 (dir / "x.wav").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("nan.csv:3"), std::string::npos) << r.output;
    { std::ofstream empty(dir / "empty.csv"); }
    r = run("render --surface wood --grf " + (dir / "empty.csv").string() + " -o " +
            (dir / "x.wav").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("empty.csv"), std::string::npos) << r.output;
    r = run("render --surface gravell -o " + (dir / "x.wav").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("unknown surface \"gravell\""), std::string::npos) << r.output;
    r = run("render --surface wood --walker cadence=fast -o " + (dir / "x.wav").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("cadence"), std::string::npos) << r.output;
    r = run("render --surface wood --seconds -3 -o " + (dir / "x.wav").string());
    EXPECT_NE(r.exitCode, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.wav"));
}

TEST(RenderCommand, SurfacesListsEveryPresetWithADescription) {
    const auto r = run("surfaces");
    ASSERT_EQ(r.exitCode, 0);
    for (const std::string id :
         {"beach_sand", "gravel", "deep_snow", "wood", "metal_reverb", "water"})
        EXPECT_NE(r.output.find(id), std::string::npos) << id;
}

TEST(AccuracyCost, NewtonIsMoreAccurateThanExplicitAndOversamplingConverges) {
    const auto settings = defaultImpactSettings();
    const auto explicit1 = measureImpact(settings[0], 0.5);
    const auto newton = measureImpact(settings[5], 0.5);
    const auto newton4x = measureImpact(settings[7], 0.5);
    EXPECT_LT(newton.contactTimeErrorPct, explicit1.contactTimeErrorPct);
    EXPECT_LT(newton.spectralDistanceDb, explicit1.spectralDistanceDb);
    EXPECT_LT(newton4x.spectralDistanceDb, newton.spectralDistanceDb);
    EXPECT_LT(newton4x.restitutionError, 0.01);
}
