// SPDX-License-Identifier: GPL-3.0-or-later
// Every bundled surface: present, well described, deterministic, stable over randomized sweeps of
// its documented parameter ranges, silent and asleep when nobody walks, allocation-free.
#include "engine/render/AudioFeatures.h"
#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "tests/common/AllocationTrap.h"

using namespace underfoot::engine;

namespace {
// Every surface of the studies' answer lists (docs/explanation/studies.md) plus the reverb
// variants.
const std::vector<std::string> kAnswerListSurfaces = {"beach_sand",
                                                      "gravel",
                                                      "dirt_pebbles",
                                                      "deep_snow",
                                                      "frozen_snow",
                                                      "high_grass",
                                                      "forest_underbrush",
                                                      "dry_leaves",
                                                      "wood",
                                                      "creaking_wood",
                                                      "metal",
                                                      "concrete",
                                                      "carpet",
                                                      "puddles",
                                                      "water",
                                                      "wood_reverb",
                                                      "creaking_wood_reverb",
                                                      "metal_reverb"};

GrfSignal shortWalk(double seconds, std::uint64_t seed = 3) {
    WalkerParameters w;
    w.cadenceStepsPerMin = 110;
    return walkerGrf(w, seconds, 48000.0, seed);
}

// Sets the value at a path such as "layer[1].modes[2].freq_hz" (1-based indices, as ParamInfo
// names them) in a parsed preset.
void setAtPath(toml::table& root, const std::string& path, double value) {
    toml::node* node = &root;
    std::stringstream ss(path);
    std::string part;
    std::vector<std::string> parts;
    while (std::getline(ss, part, '.')) parts.push_back(part);
    for (std::size_t i = 0; i < parts.size(); ++i) {
        std::string key = parts[i];
        int index = -1;
        if (auto b = key.find('['); b != std::string::npos) {
            index = std::stoi(key.substr(b + 1)) - 1;
            key = key.substr(0, b);
        }
        if (i + 1 == parts.size()) { // the parameter itself (absent when it has its default)
            ASSERT_LT(index, 0) << "a parameter path cannot end in an array element: " << path;
            node->as_table()->insert_or_assign(key, value);
            return;
        }
        toml::node* child = node->as_table()->get(key);
        ASSERT_NE(child, nullptr) << path;
        if (index >= 0) child = child->as_array()->get(static_cast<std::size_t>(index));
        ASSERT_NE(child, nullptr) << path;
        node = child;
    }
}
} // namespace

TEST(SurfacePresets, EverySurfaceOfTheAnswerListsIsBundled) {
    std::set<std::string> ids;
    for (const auto& s : listSurfaces()) ids.insert(s.id);
    for (const auto& id : kAnswerListSurfaces) EXPECT_TRUE(ids.count(id)) << id;
}

TEST(SurfacePresets, EveryPresetNamesItselfDescribesItselfAndEachLayer) {
    for (const auto& s : listSurfaces()) {
        EXPECT_EQ(std::filesystem::path(s.file).stem().string(), s.id);
        EXPECT_GE(s.description.size(), 20u) << s.id;
        EXPECT_FALSE(s.layerPurposes.empty()) << s.id;
        for (const auto& p : s.layerPurposes) EXPECT_GT(p.size(), 15u) << s.id << ": " << p;
        const auto surface = Surface::load(s.file);
        for (const auto& p : surface->parameters()) {
            EXPECT_LE(p.minValue, p.value) << s.id << " " << p.path;
            EXPECT_LE(p.value, p.maxValue) << s.id << " " << p.path;
            EXPECT_FALSE(p.help.empty()) << s.id << " " << p.path;
        }
    }
}

TEST(SurfacePresets, ReverbVariantsCarryAnImpulseResponseAndTheirBaseLayers) {
    for (const std::string id : {"wood_reverb", "creaking_wood_reverb", "metal_reverb"}) {
        const auto s = Surface::loadById(id);
        ASSERT_TRUE(s->info().reverb.has_value()) << id;
        const auto base = Surface::loadById(id.substr(0, id.size() - 7));
        EXPECT_EQ(s->layerCount(), base->layerCount()) << id;
    }
}

TEST(SurfacePresets, SameSeedSameSamplesOtherSeedOtherSamples) {
    const auto grf = shortWalk(1.5);
    RenderOptions options;
    options.scene.reverb = ReverbMode::Off;
    for (const auto& s : listSurfaces()) {
        options.seed = 11;
        const auto a = renderSurface(s.id, grf, options).audio.samples;
        const auto b = renderSurface(s.id, grf, options).audio.samples;
        ASSERT_EQ(a, b) << s.id;
        options.seed = 12;
        const auto c = renderSurface(s.id, grf, options).audio.samples;
        EXPECT_NE(a, c) << s.id << " ignores its seed";
    }
}

TEST(SurfacePresets, RandomizedSweepsWithinDocumentedRangesStayFiniteAndBounded) {
    // For each preset, several variants with every parameter drawn within its documented range
    // (log-uniform where the range spans decades). Variants that break a documented constraint
    // between two parameters (e.g. dynamic > static friction) are refused by the loader with a
    // message; they are counted, and most variants must load.
    // Each preset draws from its own stream (seeded by its id), so a parameter added to one
    // layer type re-draws only the presets that have that layer, not every preset after it.
    const auto grf = shortWalk(1.0, 5);
    RenderOptions options;
    options.scene.reverb = ReverbMode::Off;
    int rendered = 0, refused = 0;
    for (const auto& s : listSurfaces()) {
        if (s.reverb) continue;                        // same layers as their base
        std::uint64_t idHash = 1469598103934665603ull; // FNV-1a: stable across platforms
        for (unsigned char ch : s.id) idHash = (idHash ^ ch) * 1099511628211ull;
        Random rng(Random::deriveSeed(20261121, idHash));
        const auto params = Surface::load(s.file)->parameters();
        for (int variant = 0; variant < 3; ++variant) {
            toml::table root = toml::parse_file(s.file);
            for (const auto& p : params) {
                // Sweep this file's layers (not the header, not a base preset's layers: those are
                // swept with the base preset itself).
                if (p.path.find("layer[") != 0) continue;
                // Output gains scale the result linearly and cannot make a model unstable.
                if (p.path.size() >= 7 && p.path.substr(p.path.size() - 7) == "gain_db") continue;
                double v;
                if (p.logScale && p.minValue > 0)
                    v = std::exp(rng.uniform(std::log(p.minValue), std::log(p.maxValue)));
                else
                    v = rng.uniform(p.minValue, p.maxValue);
                setAtPath(root, p.path, v);
            }
            std::ostringstream text;
            text << root;
            const std::string file =
                (std::filesystem::temp_directory_path() / ("sweep_" + s.id + ".toml")).string();
            std::unique_ptr<Surface> surface;
            try {
                surface = loadSurfaceFromString(text.str(), file);
            } catch (const PresetError& e) {
                ++refused;
                EXPECT_NE(std::string(e.what()).find("expected"), std::string::npos) << e.what();
                continue;
            }
            surface->prepare({48000.0, 256});
            surface->reset(static_cast<std::uint64_t>(variant));
            std::vector<float> out(256);
            double peak = 0;
            for (std::size_t i = 0; i + 256 <= grf.frames(); i += 256) {
                surface->process(grf.channels[0].data() + i, out.data(), 256);
                for (float x : out) {
                    ASSERT_TRUE(std::isfinite(x)) << s.id << " variant " << variant << "\n"
                                                  << text.str();
                    peak = std::max(peak, double(std::fabs(x)));
                }
            }
            // Bounded: a blow-up grows without limit; a passive model cannot exceed what its
            // strikes put in. At the corners of the documented ranges (a 5 kg sole at 9 m/s on a
            // 0.1 g mode) that energy bound is ~7e4 m/s at the pickup, i.e. below 1e5 here.
            EXPECT_LT(peak, 1e5) << s.id << " variant " << variant << "\n" << text.str();
            ++rendered;
        }
    }
    EXPECT_GT(rendered, 2 * refused) << rendered << " rendered, " << refused << " refused";
}

TEST(SurfacePresets, NobodyWalkingMeansSilenceAndSleep) {
    for (const auto& s : listSurfaces()) {
        auto surface = Surface::load(s.file);
        surface->prepare({48000.0, 512});
        surface->reset(1);
        std::vector<float> grf(512, 0.0f), out(512, 1.0f);
        surface->process(grf.data(), out.data(), 512);
        for (float v : out) ASSERT_EQ(v, 0.0f) << s.id;
        EXPECT_TRUE(surface->isSleeping()) << s.id;
    }
}

TEST(SurfacePresets, AfterTheLastStepEverySurfaceFallsSilentAndSleeps) {
    auto grf = shortWalk(1.2);
    for (auto& c : grf.channels) c.resize(c.size() + 48000 * 4, 0.0f); // 4 s of standing aside
    for (const auto& s : listSurfaces()) {
        auto surface = Surface::load(s.file);
        surface->prepare({48000.0, 480});
        surface->reset(2);
        std::vector<float> out(480);
        bool slept = false;
        for (std::size_t i = 0; i + 480 <= grf.frames(); i += 480) {
            surface->process(grf.channels[0].data() + i, out.data(), 480);
            if (i > grf.frames() - 48000) { // the last second: silent, asleep
                for (float v : out)
                    ASSERT_EQ(v, 0.0f)
                        << s.id << " still sounds at " << double(i) / 48000.0 << " s";
                slept = surface->isSleeping();
            }
        }
        EXPECT_TRUE(slept) << s.id;
    }
}

// Standing still: a load held with a quiet stance's sway (+-15 N at 0.4 Hz, 0.04 kN/s at most)
// after a 0.3 s rise to 700 N. Granular beds settle (GrainsControl::settleAfterS: 2 s, then a
// 0.5 s fade), creaking boards stop shearing and their roughness stops with the shear: every
// surface is silent well before 10 s of standing (they sounded for ever: gravel at -44 dBFS RMS,
// deep snow at -32, creaking wood at -90). A shift of the weight (700 -> 350 N in 0.25 s) wakes
// the beds and the boards again. Gravel, sand, dirt and grass are not in that set: their grains
// come from the heel's impact alone (docs/decisions/revoice-grass-gravel-metal.md), so a shift of
// a standing weight is silent on them.
TEST(SurfacePresets, StandingStillFallsSilentAndAWeightShiftWakesTheBed) {
    const double fs = 48000.0;
    auto load = [&](std::size_t i) {
        const double t = static_cast<double>(i) / fs;
        if (t < 0.3) return 700.0 * t / 0.3;
        if (t < 12.0) return 700.0 + 15.0 * std::sin(2.0 * std::numbers::pi * 0.4 * (t - 0.3));
        const double base = 700.0 + 15.0 * std::sin(2.0 * std::numbers::pi * 0.4 * (12.0 - 0.3));
        return t < 12.25 ? base - (base - 350.0) * (t - 12.0) / 0.25 : 350.0;
    };
    const std::size_t frames = static_cast<std::size_t>(13.0 * fs);
    std::vector<float> grf(frames);
    for (std::size_t i = 0; i < frames; ++i) grf[i] = static_cast<float>(load(i));
    const std::set<std::string> wake = {"dry_leaves", "deep_snow", "creaking_wood"};
    for (const auto& s : listSurfaces()) {
        FootstepScene scene;
        scene.build(s.id, {});
        scene.prepare({fs, 480});
        scene.reset(5);
        std::vector<float> l(480), r(480), silent(480, 0.0f);
        double standingPeak = 0.0, shiftPeak = 0.0;
        for (std::size_t i = 0; i + 480 <= frames; i += 480) {
            const float* in[2] = {grf.data() + i, silent.data()};
            scene.process(in, l.data(), r.data(), 480);
            const double t = static_cast<double>(i) / fs;
            for (std::size_t k = 0; k < 480; ++k) {
                const double v = std::max(std::fabs(l[k]), std::fabs(r[k]));
                if (t >= 10.0 && t < 12.0) standingPeak = std::max(standingPeak, v);
                if (t >= 12.0) shiftPeak = std::max(shiftPeak, v);
            }
        }
        EXPECT_LT(standingPeak, 1e-6) << s.id << " still sounds after 10 s of standing still: peak "
                                      << 20 * std::log10(standingPeak) << " dBFS";
        if (wake.count(s.id)) {
            EXPECT_GT(shiftPeak, 1e-3) << s.id << ": the weight shift is silent";
        }
    }
}

TEST(SurfacePresets, ProcessDoesNotAllocate) {
    const auto grf = shortWalk(1.0);
    for (const auto& s : listSurfaces()) {
        FootstepScene scene;
        scene.build(s.id, {});
        scene.prepare({48000.0, 256});
        scene.reset(4);
        std::vector<float> l(256), r(256);
        underfoot::test::allocationCount = 0;
        for (std::size_t i = 0; i + 256 <= grf.frames(); i += 256) {
            const float* in[2] = {grf.channels[0].data() + i, grf.channels[1].data() + i};
            underfoot::test::countAllocations = true;
            scene.process(in, l.data(), r.data(), 256);
            underfoot::test::countAllocations = false;
        }
        EXPECT_EQ(underfoot::test::allocationCount.load(), 0) << s.id;
    }
}

TEST(SurfacePresets, BrokenPresetsFailWithFileLineColumnAndWhatWasExpected) {
    const std::string head =
        "id = \"x\"\nname = \"X\"\ncategory = \"solid\"\ndescription = \"a test preset\"\n";
    auto expectError = [&](const std::string& body, const std::string& fragment) {
        try {
            loadSurfaceFromString(head + body, "broken.toml");
            ADD_FAILURE() << "no error for:\n" << body;
        } catch (const PresetError& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("broken.toml:"), std::string::npos) << e.what();
        }
    };
    const std::string modes = "modes = [{ freq_hz = 100, t60_s = 0.1 }]\n";
    expectError(
        "[[layer]]\ntype = \"impact\"\npurpose = \"strikes of the sole\"\nstiffness = -5\n" + modes,
        "expected a number in [10000, 1e+11]");
    expectError(
        "[[layer]]\ntype = \"impact\"\npurpose = \"strikes of the sole\"\nstifness = 1e7\n" + modes,
        ":8:1: unknown key 'stifness' in layer[1]; expected one of: ");
    expectError(
        "[[layer]]\ntype = \"impact\"\npurpose = \"strikes of the sole\"\nstifness = 1e7\n" + modes,
        "(did you mean 'stiffness'?)");
    expectError("[[layer]]\ntype = \"impactt\"\npurpose = \"x\"\n", "expected a layer type");
    expectError("[[layer]]\ntype = \"impact\"\npurpose = \"strikes of the sole\"\nalpha = nan\n" +
                    modes,
                "finite");
    expectError("[[layer]]\ntype = \"impact\"\npurpose = \"strikes\"\nstiffness = \"hard\"\n" +
                    modes,
                "expected a number");
    expectError("[[layer]]\ntype = \"impact\"\npurpose = \"strikes\"\n", "expected `modes");
    expectError("", "expected at least one [[layer]]");
    expectError("[[layer]\n", "broken.toml:5");
}

TEST(SurfacePresets, EverySurfaceIsCalibratedToARealisticFootstepLevel) {
    // A 70 kg walker at 100 steps/min: every dry surface's render peaks near -12 dBFS (median
    // over three seeds within 3 dB), so switching surfaces in an experiment does not jump in level.
    const auto grf = walkerGrf({}, 6.0, 48000.0, 7);
    RenderOptions options;
    options.scene.reverb = ReverbMode::Off;
    for (const auto& s : listSurfaces()) {
        if (s.reverb) continue;
        std::vector<double> peaks;
        for (std::uint64_t seed : {7u, 8u, 9u}) {
            options.seed = seed;
            peaks.push_back(computeFeatures(renderSurface(s.id, grf, options).audio).peakDb);
        }
        std::sort(peaks.begin(), peaks.end());
        EXPECT_NEAR(peaks[1], -12.0, 3.0) << s.id;
        EXPECT_LT(peaks[2], -3.0) << s.id;
    }
}

TEST(SurfacePresets, TheAllocationTrapSeesAnAllocation) {
    // So that the zero counts of the no-allocation tests mean something.
    underfoot::test::AllocationTrap trap;
    int* volatile p = new int(3); // volatile: the allocation cannot be elided
    delete p;
    EXPECT_EQ(trap.count(), 1);
}

// heel_graze > 0: the heel's rear edge touches first, lightly, and the heel strikes
// heel_graze_lead_s later (+-25 % jitter); without it the step peaks at once after the landing.
TEST(SurfacePresets, HeelEdgeTouchesBeforeTheHeelStrikes) {
    const std::string preset =
        "id = \"x\"\nname = \"X\"\ncategory = \"solid\"\ndescription = \"a test preset\"\n"
        "[[layer]]\ntype = \"impact\"\npurpose = \"strikes of the sole\"\nstiffness = 1e9\n"
        "press_fraction = 0.0\n"
        "modes = [{ freq_hz = 300, t60_s = 0.05 }, { freq_hz = 900, t60_s = 0.03 }]\n";
    struct Step {
        double onsetMs, peakMs, firstTouchShare;
    };
    auto step = [&](const std::string& extra, std::uint64_t seed) {
        auto surface = loadSurfaceFromString(preset + extra, "graze.toml");
        surface->prepare({48000.0, 256});
        surface->reset(seed);
        // 100 ms off the floor, then the load rises to 700 N in 20 ms and is held.
        std::vector<float> grf(48000 * 3 / 10), out(grf.size(), 0.0f);
        for (std::size_t i = 0; i < grf.size(); ++i) {
            const double t = double(i) / 48000.0;
            grf[i] = t < 0.1 ? 0.0f : static_cast<float>(std::min(700.0, 35000.0 * (t - 0.1)));
        }
        for (std::size_t i = 0; i + 256 <= grf.size(); i += 256)
            surface->process(grf.data() + i, out.data() + i, 256);
        // Up to 150 ms: before the forefoot's strike (70 ms after the landing, +-15 %).
        const std::size_t end = 48000 * 15 / 100;
        std::size_t peak = 0;
        for (std::size_t i = 0; i < end; ++i)
            if (std::fabs(out[i]) > std::fabs(out[peak])) peak = i;
        const double top = std::fabs(out[peak]);
        std::size_t onset = 0;
        while (std::fabs(out[onset]) < 1e-3 * top) ++onset;
        double first = 0.0; // the loudest sample of the first 2 ms after the onset
        for (std::size_t i = onset; i < onset + 96; ++i)
            first = std::max(first, double(std::fabs(out[i])));
        return Step{double(onset) / 48.0, double(peak) / 48.0, first / top};
    };
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        const Step flat = step("", seed);
        EXPECT_NEAR(flat.onsetMs, 100.0, 2.0);
        EXPECT_LT(flat.peakMs - flat.onsetMs, 2.0) << seed;
        const Step graze = step("heel_graze = 0.2\nheel_graze_lead_s = 0.006\n", seed);
        EXPECT_NEAR(graze.onsetMs, flat.onsetMs, 0.1) << seed;
        EXPECT_GE(graze.peakMs - graze.onsetMs, 0.75 * 6.0 - 0.5) << seed;
        EXPECT_LE(graze.peakMs - graze.onsetMs, 1.25 * 6.0 + 2.0) << seed;
        EXPECT_LT(graze.firstTouchShare, 0.5) << seed; // the edge's touch is the quieter one
        EXPECT_GT(graze.firstTouchShare, 0.02) << seed;
    }
}
