// SPDX-License-Identifier: GPL-3.0-or-later
// Water, deep snow, frozen snow, dry leaves and forest underbrush stay where their re-voicing put
// them (docs/decisions/realism-revoicing.md, "Heard in their category: liquids, snows, leaves and
// underbrush"): the descriptors that made the listener hear them as solids lie within about one
// recorded spread of their material's recordings (leaves and underbrush, which have none, of all
// recorded aggregates). Each check is a robust z of realism/Distance.h against the recordings of
// scripts/fetch-recordings.sh, not a listener verdict (which moves with every other preset,
// the renders being centred as one source). The presets of main before the re-voicing fail
// every bound below (their figures are in the comments); skipped without the cache.
#include "realism/Compare.h"
#include "realism/Descriptors.h"
#include "realism/Distance.h"
#include "realism/Recordings.h"
#include "tests/realism/RecordingsCache.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {

struct Bound {
    Descriptor d;
    double maxZ; ///< largest robust z allowed
};

class HeardInTheirCategory : public underfoot::realism::test::RecordingsCacheTest {
  protected:
    std::vector<Recording> of(const std::set<std::string>& materials) const {
        std::vector<Recording> out;
        for (const auto& r : recs_)
            if (materials.count(r.material)) out.push_back(r);
        return out;
    }

    // Renders the surface as `underfoot compare` does (walker cadence=100, 10 s, seed 7),
    // prints its z on every descriptor and checks the bounds and the distance.
    SurfaceComparison check(const std::string& surface, const std::set<std::string>& materials,
                            const std::vector<Bound>& bounds, double maxDistance) const {
        const auto real = of(materials);
        EXPECT_GE(real.size(), 5u) << surface;
        auto c = compareSurface(surface, real, RenderSpec{});
        std::string line = fmt::format("{:<18} distance {:.2f}:", surface, c.comparison.distance);
        for (int d = 0; d < kDescriptorCount; ++d)
            line += fmt::format(" {} {:.2f}", descriptorInfo(d).key,
                                c.comparison.d[static_cast<std::size_t>(d)].z);
        std::printf("%s\n", line.c_str());
        for (const auto& b : bounds)
            EXPECT_LE(c.comparison.d[static_cast<std::size_t>(b.d)].z, b.maxZ)
                << surface << ": " << descriptorInfo(b.d).key;
        EXPECT_LE(c.comparison.distance, maxDistance) << surface;
        EXPECT_GE(c.comparison.syntheticSteps, 8) << surface;
        return c;
    }
};

} // namespace

// Water (wading): the fitted preset was a short tonal ping of landing bubbles at 1.4-3 kHz;
// recorded water steps are long splash noise spread over the band. main before: 250 Hz-1 kHz
// z 1.51 (-14 dB of the whole band vs a recorded median of -5), flatness z 0.80, decay to
// -20 dB 31 ms (recorded median 63 ms), distance 0.60.
TEST_F(HeardInTheirCategory, WaterIsASplashSpreadOverTheBandAndLong) {
    const auto c =
        check("water", {"water"}, {{kBandLowMid, 0.75}, {kFlatness, 0.75}, {kBandLow, 0.75}}, 0.58);
    const auto& decay = c.comparison.d[kDecay20];
    EXPECT_GE(decay.synthetic, decay.realMedian) << "a water step decays at least as slowly as "
                                                    "the median recorded one";
}

// Deep snow: main's was muffled and narrow (flatness z 4.27, 4-16 kHz z 4.28: -41 dB) with too
// little low energy (20-250 Hz z 2.51), distance 1.40 to the snow recordings.
TEST_F(HeardInTheirCategory, DeepSnowIsBroadAndLowLikeRecordedSnow) {
    check("deep_snow", {"snow"}, {{kFlatness, 1.5}, {kBandHigh, 2.0}, {kBandLow, 1.0}}, 0.8);
}

// Dry leaves and underbrush (no recordings of their own) against every recorded aggregate:
// main's were brighter and flatter than any (leaves: centroid z 1.39, flatness 1.40, 4-16 kHz
// 1.36, distance 1.11; underbrush: 1.47, 1.17, 1.26, 1.11).
TEST_F(HeardInTheirCategory, LeavesAndUnderbrushLieAmongTheRecordedAggregates) {
    const std::set<std::string> aggregates = {"gravel", "sand", "snow", "dirt", "grass"};
    for (const char* s : {"dry_leaves", "forest_underbrush"})
        check(s, aggregates, {{kCentroid, 1.0}, {kFlatness, 1.0}, {kBandHigh, 1.0}}, 0.85);
}

// Frozen snow (docs/decisions/realism-revoicing.md, "Frozen snow: a crust that breaks"): main's was
// a bright crunch over 1-5 kHz with glassy 5-12 kHz grains and almost nothing low, heard as ice
// (the listener's pulls: 4-16 kHz, flatness, 250 Hz-1 kHz, decay) and nearer gravel (0.67) and
// water than snow (1.77). Against the snow recordings: 20-250 Hz z 5.95 (-20 dB of the whole band
// vs a recorded median of -2.2), centroid 2.66 (1997 vs 558 Hz), flatness 2.29, 1-4 kHz 2.01, 4-16
// kHz 1.69. Now: the low band within one recorded spread and the step closer to the snow recordings
// than to those of gravel, water and ice (the materials it was nearest or heard as).
TEST_F(HeardInTheirCategory, FrozenSnowIsACrustBreakingOverSnowNotIce) {
    const auto c = check(
        "frozen_snow", {"snow"},
        {{kBandLow, 1.0}, {kCentroid, 1.0}, {kFlatness, 1.0}, {kBandMid, 1.5}, {kBandHigh, 1.0}},
        0.8);
    for (const char* other : {"gravel", "water", "ice"}) {
        const auto real = of({other});
        ASSERT_GE(real.size(), 3u) << other;
        const auto o = compareSurface("frozen_snow", real, RenderSpec{});
        std::printf("frozen_snow vs %-6s distance %.2f\n", other, o.comparison.distance);
        EXPECT_LT(c.comparison.distance + 0.1, o.comparison.distance)
            << "frozen snow is not clearly closer to snow than to " << other;
    }
}

// Beach sand and dirt with pebbles are as noise-like as their recordings: the friction hiss
// layer (docs/decisions/aggregate-friction-hiss.md) puts their spectral flatness inside the
// recorded steps' IQR. Before it (ringing grains only, `underfoot compare -s ID`, seed 7):
// sand -22.3 dB against -14.6..-10.0 (z 2.33, distance 0.64), dirt -16.5 against -15.6..-11.4;
// after: sand -13.6 (distance 0.41), dirt -15.1 (0.48).
TEST_F(HeardInTheirCategory, SandAndDirtAreAsNoiseLikeAsTheirRecordings) {
    for (const auto& [surface, material, maxDistance] :
         {std::tuple{"beach_sand", "sand", 0.5}, std::tuple{"dirt_pebbles", "dirt", 0.55}}) {
        const auto c = check(surface, {material}, {{kFlatness, 0.75}}, maxDistance);
        const auto& f = c.comparison.d[kFlatness];
        std::printf("%s flatness %.2f dB, recordings' IQR %.2f..%.2f dB\n", surface, f.synthetic,
                    f.realQ1, f.realQ3);
        EXPECT_GE(f.synthetic, f.realQ1) << surface << ": more tonal than the recordings' IQR";
        EXPECT_LE(f.synthetic, f.realQ3) << surface << ": flatter than the recordings' IQR";
    }
}

// The same at every render seed from 1 to 20, not at seed 7 only, for the aggregates whose
// ringing grains once made them too tonal, and for both snows: the walker's steps and the grains
// differ from seed to seed, and so does the flatness. Before their re-voicing
// (docs/decisions/aggregate-flatness-every-seed.md), beach sand was outside the IQR at seed 1
// (-15.1 dB), dirt at seeds 2, 5, 15 and 17 (down to -16.1), frozen snow at seeds 4, 9, 12 and
// 13 (up to -11.3: its crust's cracks ran on in longer cascades).
TEST_F(HeardInTheirCategory, AggregatesAreAsNoiseLikeAsTheirRecordingsAtEverySeed) {
    for (const auto& [surface, material] :
         {std::pair{"beach_sand", "sand"}, std::pair{"dirt_pebbles", "dirt"},
          std::pair{"deep_snow", "snow"}, std::pair{"frozen_snow", "snow"}}) {
        const auto real = of({material});
        ASSERT_GE(real.size(), 5u) << surface;
        // The recordings are read and described once (by the first seed's comparison); every
        // seed's render is described with the same options and compared with their steps.
        const auto first = compareSurface(surface, real, RenderSpec{});
        std::string line = fmt::format("{:<13} flatness dB by seed:", surface);
        for (std::uint64_t seed = 1; seed <= 20; ++seed) {
            RenderSpec spec;
            spec.seed = seed;
            const auto steps = describeSteps(renderForComparison(surface, spec), first.options);
            ASSERT_GE(steps.size(), 8u) << surface << " seed " << seed;
            const auto c = compareSteps(steps, first.realSteps);
            const auto& f = c.d[kFlatness];
            line += fmt::format(" {:.1f}", f.synthetic);
            EXPECT_GE(f.synthetic, f.realQ1)
                << surface << " seed " << seed << ": more tonal than the recordings' IQR ("
                << f.realQ1 << ".." << f.realQ3 << " dB)";
            EXPECT_LE(f.synthetic, f.realQ3)
                << surface << " seed " << seed << ": flatter than the recordings' IQR (" << f.realQ1
                << ".." << f.realQ3 << " dB)";
        }
        std::printf("%s\n", line.c_str());
    }
}
