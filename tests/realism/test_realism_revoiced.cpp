// SPDX-License-Identifier: GPL-3.0-or-later
// High grass, gravel, metal, beach sand and deep snow keep their re-voicing against the
// recordings of their material (docs/decisions/revoice-grass-gravel-metal.md and the records
// cited below): the descriptors on which the listener misplaced them lie within the bounds
// below. Each check is a robust z of realism/Distance.h against the recordings of
// scripts/fetch-recordings.sh (either cache: the four-source one CI has, or the seven-source one
// of `--large`), not a listener verdict, which moves with every other preset
// (the renders are centred as one source); high grass, the snows and puddles also keep their
// held-out verdicts, which their descriptors cannot express. The presets before the re-voicing
// fail every descriptor bound below on both caches (their figures, `underfoot compare -s ID
// --seed 7`, are in the comments: seven-source / four-source cache where they differ); skipped
// without the cache.
#include "realism/Compare.h"
#include "realism/Listener.h"
#include "realism/Recordings.h"
#include "realism/SurfaceFigures.h"
#include "tests/realism/RecordingsCache.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

using namespace underfoot::realism;

namespace {

class Revoiced : public underfoot::realism::test::RecordingsCacheTest {
  protected:
    // Renders the surface as `underfoot compare` does (walker cadence=100, 10 s, seed 7) against
    // the recordings of its material and prints every descriptor's synthetic median and z.
    SurfaceComparison compare(const std::string& surface, const std::string& material) const {
        std::vector<Recording> real;
        for (const auto& r : recs_)
            if (r.material == material) real.push_back(r);
        EXPECT_GE(real.size(), 5u) << surface;
        auto c = compareSurface(surface, real, RenderSpec{});
        std::string line = fmt::format("{:<11} distance {:.2f}:", surface, c.comparison.distance);
        for (int d = 0; d < kDescriptorCount; ++d) {
            const auto& x = c.comparison.d[static_cast<std::size_t>(d)];
            line += fmt::format(" {} {:.4g} (z {:.2f})", descriptorInfo(d).key, x.synthetic, x.z);
        }
        std::printf("%s\n", line.c_str());
        EXPECT_GE(c.comparison.syntheticSteps, 8) << surface;
        return c;
    }
    static const DescriptorComparison& at(const SurfaceComparison& c, Descriptor d) {
        return c.comparison.d[static_cast<std::size_t>(d)];
    }
    // The figures of `surface` at `seed`, as `underfoot compare --figures` computes them: every
    // bundled surface is rendered (the listener centres the renders as one source). The
    // recordings are not played through the rooms of the surfaces with a room: the distances of
    // those (not asserted here) are to the dry recordings.
    SurfaceFigures figuresOf(const std::string& surface, std::uint64_t seed) const {
        SurfaceFiguresOptions o;
        o.seeds = {seed};
        o.dryRecordings = true;
        for (auto& f : surfaceFigures(bundledSurfaces(), recs_, o))
            if (f.surface == surface) {
                std::printf("%s seed %llu: own %.2f, nearest other %s %.2f\n", surface.c_str(),
                            static_cast<unsigned long long>(seed), f.ownDistance,
                            f.nearestOther.c_str(), f.nearestOtherDistance);
                return f;
            }
        ADD_FAILURE() << surface << " is not a bundled surface";
        return {};
    }
    // Expects the listener trained without each source that recorded the surface's material to
    // hear it in its category; returns how many such sources there are.
    static int placedWithoutEachSource(const SurfaceFigures& f) {
        for (const auto& v : f.heardWithout) {
            if (!v.scored) continue;
            EXPECT_EQ(categoryOfMaterial(v.heard), f.category)
                << f.surface << " without " << v.source << ": " << v.heard;
        }
        return f.sources;
    }
};

} // namespace

// High grass: the soil's thud under the swish and the snaps of thicker stems. Before: 20-250 Hz
// share -15.8 dB against a recorded median of -7.0 (z 1.72), peakiness 9.1 against 15.1 dB
// (z 1.03). With the low swish (docs/decisions/high-grass-low-swish.md), today on both caches:
// -4.3 dB (z 0.52), 13.6 dB (z 0.27). The bright swish as friction noise (same record, "The
// bright swish as friction noise") took its micro-events from 148 per second (z 1.30;
// recordings 60) to 44 (z 0.44): ringing grains thinned out into ticks in the heel burst's
// tail. The distance to the pooled recordings pays for both (0.41 -> 0.55 -> 0.64: the walk is
// darker than their median, centroid 771 Hz against 1908), which the held-out listeners below
// gain.
TEST_F(Revoiced, HighGrassHasTheSoilsLowEnd) {
    const auto c = compare("high_grass", "grass");
    EXPECT_LE(at(c, kBandLow).z, 0.8);
    EXPECT_LE(at(c, kPeakiness).z, 0.6);
    EXPECT_LE(at(c, kGrainRate).z, 0.8);
    EXPECT_LE(c.comparison.distance, 0.7);
}

// High grass is heard as an aggregate by the listener trained without each source that recorded
// grass (`underfoot compare --listener`, seed 7; `--figures` counts the same verdicts), on either
// cache: it holds at every seed from 1 to 30 on four and on seven sources (`compare --figures
// --seeds 1,2,...,30`; chosen on 1-20, docs/decisions/high-grass-low-swish.md, "The bright swish
// as friction noise"). With ringing grains for its bright swish, the listener without UFO:AI
// heard it out of its category (mostly as metal) at seed 7 and at 21 of the 30 seeds on seven
// sources; without the low swish, as water at seed 7 on four. A verdict, not a descriptor bound:
// it moves with every other preset (the renders are centred as one source), so a change
// elsewhere that fails this must say what it costs high grass.
TEST_F(Revoiced, HighGrassIsHeardAsAnAggregateWithoutEachSource) {
    EXPECT_GE(placedWithoutEachSource(figuresOf("high_grass", 7)), 3)
        << "minetest, UFO:AI and lugaru recorded grass";
}

// Frozen snow is heard as an aggregate by the listener trained without each source that
// recorded snow, at render seeds 3 and 11, on either cache. Chosen by a seeded search on seeds
// 1-10 of both caches and confirmed on 11-20 (docs/decisions/aggregate-flatness-every-seed.md),
// it was placed at every seed from 1 to 20 on four sources and at 18 of 20 on seven; the preset
// before it at 18 and 15 of 20, and at neither of these seeds on either cache (without UFO:AI: a
// hard floor; at seed 11 without minetest too). Searched again on seeds 11-20 of seven sources
// when deep snow's crunch became noise (docs/decisions/deep-snow-crunch-as-noise.md), it is
// placed at every seed from 1 to 30 on four sources and at 23 of 30 on seven (25 before either
// snow changed, 16 with deep snow's noise crunch and frozen snow as it was). `underfoot compare
// --figures --seeds 1,...,30` gives the rate. A verdict, like high grass's above: it moves with
// every other preset.
TEST_F(Revoiced, FrozenSnowIsHeardAsAnAggregateWithoutEachSnowSource) {
    for (const std::uint64_t seed : {3, 11})
        EXPECT_EQ(placedWithoutEachSource(figuresOf("frozen_snow", seed)), 3)
            << "seed " << seed << ": lugaru, minetest and UFO:AI recorded snow";
}

// Deep snow: its crunch is short overlapping bursts of friction noise, not ringing crystals
// (docs/decisions/deep-snow-crunch-as-noise.md). Before, the ringing grains thinned out into
// separate ticks: 134.6 micro-events per second against the recordings' 52.4 (z 1.92), and the
// listener trained without UFO:AI heard a hard floor at seed 7 on either cache (at 4 and 10 of
// render seeds 1-10 on four and seven sources). Now 70.7 per second (z 0.61), placed by every
// held-out snow source at every seed from 1 to 30 on four and seven sources, chosen on 1-10 of
// both. The distance pays (0.39 -> 0.54: brighter, centroid 724 Hz against 558). A verdict too,
// like high grass's above: it moves with every other preset.
TEST_F(Revoiced, DeepSnowCrunchesAsNoise) {
    const auto c = compare("deep_snow", "snow");
    EXPECT_LE(at(c, kGrainRate).z, 0.8);
    EXPECT_LE(c.comparison.distance, 0.6);
    EXPECT_EQ(placedWithoutEachSource(figuresOf("deep_snow", 7)), 3)
        << "lugaru, minetest and UFO:AI recorded snow";
}

// Puddles are heard as a liquid by the listener trained without each source that recorded water,
// and lie nearer the water recordings than any other material's, at render seed 2 on either
// cache. Chosen by a seeded search on seeds 1-10 of both caches and confirmed on 11-20
// (docs/decisions/puddles-slosh-and-stirred-bubbles.md), they are, at every seed from 1 to 20.
// The preset before it was heard as sand without UFO:AI at seeds 2 and 17 (four sources) and was
// nearer gravel's recordings than water's at 2 (four) and 4 (seven) seeds of 20; at seed 2,
// 0.54 and 0.65 against gravel's 0.49. A verdict, like high grass's above: it moves with every
// other preset.
TEST_F(Revoiced, PuddlesAreHeardAsALiquidAndNearestWater) {
    const auto f = figuresOf("puddles", 2);
    EXPECT_GE(placedWithoutEachSource(f), 3)
        << "minetest, openarena and UFO:AI (and on seven sources a fourth) recorded water";
    EXPECT_LT(f.ownDistance, f.nearestOtherDistance)
        << "nearer " << f.nearestOther << " than water (" << f.ownDistance << ")";
    EXPECT_LE(f.ownDistance, 0.5);
}

// Metal: one or two clangs, not a stream of small events. Before: 121 micro-events per second
// of step against a recorded median of 36 / 28 (z 1.76 / 2.32), crest 20.5 dB against 17.9 /
// 17.1 (z 0.85 / 1.14). Now: 22 / s (z 0.70 / 0.46), crest z 0.35 / 0.65.
TEST_F(Revoiced, MetalIsAFewClangsNotAStreamOfGrains) {
    const auto c = compare("metal", "metal");
    EXPECT_LE(at(c, kGrainRate).synthetic, 60.0) << "micro-events per second of step";
    EXPECT_LE(at(c, kGrainRate).z, 1.0);
    EXPECT_LE(at(c, kCrest).z, 0.8);
    EXPECT_LE(c.comparison.distance, 0.6);
}

// Metal: the heel lands on the plate at once (docs/decisions/metal-quick-heel.md). With the heel
// edge 6 ms ahead of the heel, as on wood, the step rose in 0.010 s, slower than the recorded
// median (0.0095 s on four sources); now 0.005 s: inside the recorded IQR on four sources
// (0.0038-0.021 s, z 0.93), just below it on seven (0.0055-0.021 s, z 1.26). The distance pays
// for it (0.41 / 0.44 -> 0.52 / 0.53); the nested listener gains (`underfoot compare
// --figures`: metal without openarena in its category).
TEST_F(Revoiced, MetalRisesQuicklyWithinTheRecordedRange) {
    const auto c = compare("metal", "metal");
    EXPECT_LE(at(c, kAttack).synthetic, 0.007) << "s from -30 dB to the peak";
    EXPECT_LE(at(c, kAttack).z, 1.5);
}

// Gravel: the heel's impact crushes the bed at once. Before: attack 0.119 s against a recorded
// median of 0.044 (z 1.44), temporal centroid 0.123 s against 0.061 (z 1.17): the crunch built
// up with the load. Now (both caches): 0.021 s (z 1.07), 0.039 s (z 0.79); the step decays
// more slowly than the recorded ones (decay to -20 dB 0.043 s against 0.018, z 1.26), which the
// distance (0.54, was 0.48) carries.
TEST_F(Revoiced, GravelCrunchesAtOnce) {
    const auto c = compare("gravel", "gravel");
    EXPECT_LE(at(c, kAttack).synthetic, 0.06) << "s from the step's onset to its peak";
    EXPECT_LE(at(c, kTemporalCentroid).synthetic, at(c, kTemporalCentroid).realMedian);
    EXPECT_LE(at(c, kTemporalCentroid).z, 1.0);
    EXPECT_LE(c.comparison.distance, 0.6);
}

// Beach sand: a short, sparse, dark shower of grains, heard as an aggregate without each source
// that recorded sand. Chosen by a seeded search on seeds 1-10 of both caches and confirmed on
// 11-20 (docs/decisions/beach-sand-short-shower.md): on seven sources the listener trained
// without minetest heard the preset before as a hard floor at every seed (micro-events 36 per
// second, 1-4 kHz share -10.5 dB at seed 7); now 19 per second, -14.4 dB, placed at every seed
// from 1 to 20 on either cache. The descriptors pin the change on the four-source cache, where
// both presets are placed; the verdict, like high grass's above, moves with every other preset.
TEST_F(Revoiced, BeachSandIsAShortSparseDarkShower) {
    const auto c = compare("beach_sand", "sand");
    EXPECT_LE(at(c, kGrainRate).synthetic, 25.0) << "micro-events per second of step";
    EXPECT_GE(at(c, kGrainRate).synthetic, at(c, kGrainRate).realQ1);
    EXPECT_LE(at(c, kBandMid).synthetic, at(c, kBandMid).realMedian) << "1-4 kHz share, dB";
    EXPECT_LE(c.comparison.distance, 0.5);
    EXPECT_EQ(placedWithoutEachSource(figuresOf("beach_sand", 7)), 2) << "minetest and UFO:AI";
}
