// SPDX-License-Identifier: GPL-3.0-or-later
// The per-surface, per-seed figures of `underfoot compare --figures` (realism/SurfaceFigures.h):
// the nested listener's counts, and distances and descriptors equal to those `compare --all` and
// `compare --surface` compute.
#include "realism/Compare.h"
#include "realism/SurfaceFigures.h"
#include "tests/realism/RecordingsCache.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

using namespace underfoot::realism;

TEST(SurfaceFigures, NestedCountsOnlyTheSourcesThatRecordedTheMaterial) {
    const std::vector<SurfaceUnderTest> surfaces{
        {"wood", "wood", "solid"}, {"gravel", "gravel", "aggregate"}, {"leaves", "", "aggregate"}};
    // Source a recorded wood and gravel, b wood only, c neither.
    const std::map<std::string, std::set<std::string>> recorded{
        {"a", {"wood", "gravel"}}, {"b", {"wood"}}, {"c", {"water"}}};
    const std::map<std::string, std::vector<std::string>> heard{{"a", {"hard", "water", "gravel"}},
                                                                {"b", {"wood", "sand", "hard"}},
                                                                {"c", {"metal", "water", "water"}}};
    std::vector<SurfaceFigures> f(3);
    scoreNested(surfaces, heard, recorded, f);
    // wood: a (hard: solid, not wood) and b (wood) count; c did not record wood.
    EXPECT_EQ(f[0].surface, "wood");
    EXPECT_EQ(f[0].sources, 2);
    EXPECT_EQ(f[0].categoryRight, 2);
    EXPECT_EQ(f[0].materialRight, 1);
    // gravel: only a, which heard water (another category).
    EXPECT_EQ(f[1].sources, 1);
    EXPECT_EQ(f[1].categoryRight, 0);
    EXPECT_EQ(f[1].materialRight, 0);
    // No recorded material: nothing scored, every verdict still listed in source order.
    EXPECT_EQ(f[2].sources, 0);
    ASSERT_EQ(f[2].heardWithout.size(), 3u);
    EXPECT_EQ(f[2].heardWithout[0].source, "a");
    EXPECT_EQ(f[2].heardWithout[2].heard, "water");
    EXPECT_FALSE(f[2].heardWithout[0].scored);
    // wood: a and b scored, c not.
    EXPECT_TRUE(f[0].heardWithout[0].scored);
    EXPECT_TRUE(f[0].heardWithout[1].scored);
    EXPECT_FALSE(f[0].heardWithout[2].scored);
    std::vector<SurfaceFigures> tooFew(2);
    EXPECT_THROW(scoreNested(surfaces, heard, recorded, tooFew), std::out_of_range);
}

TEST(SurfaceFigures, OverSeedsSetsEachSourceAgainstItsOwnRecordings) {
    // wood over two seeds: source a heard it in its category once (a's own wood: 1 of 2 files),
    // source b never (b's own wood: 0 of 3); gravel: a heard it right twice, a's gravel 4/4.
    auto fig = [](const std::string& surface, const std::string& material,
                  const std::string& category, std::vector<HeldOutVerdict> v) {
        SurfaceFigures f;
        f.surface = surface;
        f.material = material;
        f.category = category;
        f.heardWithout = std::move(v);
        return f;
    };
    std::vector<SurfaceFigures> figs{
        fig("wood", "wood", "solid", {{"a", "hard", true, {}}, {"b", "sand", true, {}}}),
        fig("gravel", "gravel", "aggregate",
            {{"a", "gravel", true, {}}, {"b", "metal", false, {}}}),
        fig("wood", "wood", "solid", {{"a", "water", true, {}}, {"b", "snow", true, {}}}),
        fig("gravel", "gravel", "aggregate", {{"a", "sand", true, {}}, {"b", "wood", false, {}}}),
        fig("leaves", "", "aggregate", {{"a", "wood", false, {}}})};
    const std::map<std::string, std::map<std::string, JudgedCounts>> own{
        {"a", {{"wood", {2, 1, 1}}, {"gravel", {4, 4, 3}}}}, {"b", {{"wood", {3, 0, 0}}}}};
    addHeldOutRecordings(own, figs);
    EXPECT_EQ(figs[0].heardWithout[0].recordings.files, 2);
    EXPECT_EQ(figs[1].heardWithout[1].recordings.files, 0) << "b did not record gravel";
    const auto s = overSeeds(figs);
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s[0].surface, "wood");
    ASSERT_EQ(s[0].sources.size(), 2u);
    EXPECT_EQ(s[0].sources[0].seeds, 2);
    EXPECT_EQ(s[0].sources[0].seedsInCategory, 1);
    EXPECT_TRUE(s[0].sources[0].atLeastAsOftenAsRecordings()) << "1/2 against 1/2";
    EXPECT_EQ(s[0].sources[1].seedsInCategory, 0);
    EXPECT_TRUE(s[0].sources[1].atLeastAsOftenAsRecordings()) << "0/2 against 0/3";
    EXPECT_FALSE(s[0].alwaysInCategory());
    EXPECT_TRUE(s[0].atLeastAsOftenAsRecordings());
    // gravel: only a counts; 2 of 2 seeds against 4 of 4 recordings.
    ASSERT_EQ(s[1].sources.size(), 1u);
    EXPECT_TRUE(s[1].alwaysInCategory());
    EXPECT_TRUE(s[1].atLeastAsOftenAsRecordings());
    // A seed heard wrong where every recording was heard right falls below them.
    figs[3].heardWithout[0].heard = "water";
    const auto below = overSeeds(figs);
    EXPECT_FALSE(below[1].atLeastAsOftenAsRecordings()) << "1/2 seeds against 4/4";
    EXPECT_TRUE(below[2].sources.empty()) << "leaves: no recorded material";
}

class SurfaceFiguresOnRecordings : public underfoot::realism::test::RecordingsCacheTest {};

TEST_F(SurfaceFiguresOnRecordings, DistancesAndDescriptorsAreThoseOfCompare) {
    const std::vector<SurfaceUnderTest> surfaces{{"wood", "wood", "solid"},
                                                 {"wood_reverb", "wood", "solid"},
                                                 {"gravel", "gravel", "aggregate"}};
    SurfaceFiguresOptions o;
    o.spec.seconds = 4.0;
    o.seeds = {7};
    const auto figs = surfaceFigures(surfaces, recs_, o);
    ASSERT_EQ(figs.size(), 3u);
    std::set<std::string> materials;
    std::map<std::string, std::set<std::string>> sourcesOf;
    for (const auto& r : recs_) {
        materials.insert(r.material);
        sourcesOf[r.material].insert(r.source);
    }
    RenderSpec spec = o.spec;
    spec.seed = 7;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        const auto& f = figs[i];
        const auto& s = surfaces[i];
        SCOPED_TRACE(s.surface);
        EXPECT_EQ(f.seed, 7u);
        ASSERT_TRUE(f.hasRecordings);
        // As `compare --surface`: the own material's recordings, through the surface's room.
        const auto audio = renderForComparison(s.surface, spec);
        const auto room = roomOfSurface(s.surface);
        EXPECT_EQ(room.has_value(), s.surface == "wood_reverb");
        std::vector<Recording> own;
        for (const auto& r : recs_)
            if (r.material == s.material) own.push_back(r);
        const auto c = compareAudio(s.surface, audio, own, room);
        EXPECT_DOUBLE_EQ(f.ownDistance, c.comparison.distance);
        EXPECT_DOUBLE_EQ(f.flatness.synthetic, c.comparison.d[kFlatness].synthetic);
        EXPECT_DOUBLE_EQ(f.flatness.realQ1, c.comparison.d[kFlatness].realQ1);
        EXPECT_DOUBLE_EQ(f.centroid.realQ3, c.comparison.d[kCentroid].realQ3);
        // As `compare --all`: the nearest of every other material's recordings (dry surfaces:
        // a room's convolution of every recording would make this test slow).
        if (!room) {
            std::string other;
            double otherD = 1e300;
            for (const auto& m : materials) {
                if (m == s.material) continue;
                std::vector<Recording> of;
                for (const auto& r : recs_)
                    if (r.material == m) of.push_back(r);
                const double d = compareAudio(s.surface, audio, of).comparison.distance;
                if (d < otherD) {
                    otherD = d;
                    other = m;
                }
            }
            EXPECT_EQ(f.nearestOther, other);
            EXPECT_DOUBLE_EQ(f.nearestOtherDistance, otherD);
        }
        // Every source that recorded the material is a held-out verdict on it.
        EXPECT_EQ(f.sources, int(sourcesOf[s.material].size()));
        EXPECT_LE(f.categoryRight, f.sources);
        EXPECT_LE(f.materialRight, f.categoryRight);
        // Each scored verdict carries how that listener heard the source's own recordings.
        for (const auto& v : f.heardWithout) {
            if (!v.scored) continue;
            int files = 0;
            for (const auto& r : recs_) files += r.source == v.source && r.material == s.material;
            EXPECT_EQ(v.recordings.files, files) << v.source;
            EXPECT_LE(v.recordings.categoryRight, v.recordings.files) << v.source;
        }
        EXPECT_GT(f.nanosecondsPerFrame, 0.0);
        EXPECT_TRUE(std::isfinite(f.nanosecondsPerFrame));
    }
    // The room changes the comparison: wood with reverb is not wood's figure again.
    EXPECT_NE(figs[0].ownDistance, figs[1].ownDistance);
}

TEST_F(SurfaceFiguresOnRecordings, RefusesWhatItCannotJudge) {
    SurfaceFiguresOptions o;
    o.spec.seconds = 2.0;
    EXPECT_THROW(surfaceFigures({}, recs_, o), std::invalid_argument);
    o.seeds.clear();
    EXPECT_THROW(surfaceFigures({{"wood", "wood", "solid"}}, recs_, o), std::invalid_argument);
    o.seeds = {7};
    std::vector<Recording> oneSource;
    for (const auto& r : recs_)
        if (r.source == recs_.front().source) oneSource.push_back(r);
    try {
        surfaceFigures({{"wood", "wood", "solid"}}, oneSource, o);
        ADD_FAILURE() << "one source was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("two sources"), std::string::npos) << e.what();
    }
}

// The realism result of `underfoot compare --figures` (docs/explanation/realism.md, "Per surface
// and seed"): over its default seeds, every bundled surface is heard in its category by every
// held-out source that recorded its material, at every seed, and in any case at least as often
// as that source's own recordings of the material. The known misses are named with the reason
// each is allowed; any other miss fails, whichever cache (four or seven sources) is used.
TEST_F(SurfaceFiguresOnRecordings, EverySurfaceIsPlacedAsOftenAsTheHeldOutRecordings) {
    // (surface, held-out source): the listener without that source misses the surface at some
    // seeds. Gravel without minetest: the same listener hears minetest's own gravel as metal
    // (0 of 4 on four sources, 1 of 4 on seven), so on seven sources the render can fall below
    // them too (docs/decisions/frozen-snow-and-gravel-trade-off.md, "What a third recordist
    // does"). Frozen snow without UFO:AI, seven sources: a render near the renders' median is
    // heard as openclonk's hard floors (docs/decisions/listener-origin-and-snow.md); at par.
    const std::set<std::pair<std::string, std::string>> mayMiss{{"gravel", "minetest"},
                                                                {"frozen_snow", "ufoai"}};
    const std::set<std::pair<std::string, std::string>> mayFallBelowRecordings{
        {"gravel", "minetest"}};
    SurfaceFiguresOptions o; // the command's defaults: cadence 100, 10 s, seeds 3, 7 and 11
    const auto figs = surfaceFigures(bundledSurfaces(), recs_, o);
    int always = 0, atPar = 0, judged = 0;
    for (const auto& s : overSeeds(figs)) {
        if (s.sources.empty()) continue;
        ++judged;
        always += s.alwaysInCategory();
        atPar += s.atLeastAsOftenAsRecordings();
        for (const auto& h : s.sources) {
            SCOPED_TRACE(s.surface + " without " + h.source);
            const std::pair<std::string, std::string> key{s.surface, h.source};
            if (!mayMiss.contains(key)) {
                EXPECT_EQ(h.seedsInCategory, h.seeds) << "heard in another category at some seed";
            }
            if (!mayFallBelowRecordings.contains(key)) {
                EXPECT_TRUE(h.atLeastAsOftenAsRecordings())
                    << h.seedsInCategory << " of " << h.seeds << " seeds against "
                    << h.recordings.categoryRight << " of " << h.recordings.files
                    << " of the source's own recordings";
            }
        }
    }
    RecordProperty("surfaces_in_category_everywhere", always);
    RecordProperty("surfaces_at_par", atPar);
    EXPECT_EQ(judged, 16) << "bundled surfaces with a recorded material";
}
