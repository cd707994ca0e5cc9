// SPDX-License-Identifier: GPL-3.0-or-later
// The nested estimate with refitted presets (realism/NestedFit.h): which fits it runs and on
// which recordings. The fits themselves are `underfoot fit`'s (test_realism_fit_contrast); the
// full run is `underfoot compare --listener --refit` (minutes: not a test).
#include "realism/Listener.h"
#include "realism/NestedFit.h"

#include <gtest/gtest.h>

#include <set>

using namespace underfoot::realism;

namespace {
Recording rec(const std::string& source, const std::string& material, int i) {
    Recording r;
    r.source = source;
    r.material = material;
    r.file = source + "/" + material + "/" + std::to_string(i) + ".ogg";
    r.path = "/nonexistent/" + r.file;
    return r;
}

// A tiny fake cache: wood from a and b, water from a and b, carpet from c alone, metal from b.
std::vector<Recording> fakeCache() {
    std::vector<Recording> r;
    for (int i = 0; i < 2; ++i) {
        r.push_back(rec("a", "wood", i));
        r.push_back(rec("b", "wood", i));
        r.push_back(rec("a", "water", i));
        r.push_back(rec("b", "water", i));
        r.push_back(rec("c", "carpet", i));
        r.push_back(rec("b", "metal", i));
    }
    return r;
}

const std::vector<std::pair<std::string, std::string>> kFittable = {
    {"wood", "wood"}, {"water", "water"}, {"carpet", "carpet"}, {"metal", "metal"}};
} // namespace

TEST(RealismNestedFit, WithoutSourceDropsExactlyThatSource) {
    const auto all = fakeCache();
    const auto noA = withoutSource(all, "a");
    EXPECT_EQ(noA.size(), all.size() - 4);
    for (const auto& r : noA) EXPECT_NE(r.source, "a");
    EXPECT_EQ(withoutSource(all, "nobody").size(), all.size());
}

TEST(RealismNestedFit, OneFitPerSourceThatRecordedTheMaterialAlongsideAnother) {
    const auto jobs = refitJobs(kFittable, fakeCache());
    std::vector<std::string> got;
    for (const auto& j : jobs) got.push_back(j.surface + " without " + j.heldOut);
    // carpet (c alone) and metal (b alone) have no other source: no refit, shipped fit kept;
    // wood and water are refitted once without a and once without b; c changes neither.
    EXPECT_EQ(got, (std::vector<std::string>{"wood without a", "wood without b", "water without a",
                                             "water without b"}));
}

TEST(RealismNestedFit, TheRefitNeverSeesTheHeldOutSource) {
    const auto all = fakeCache();
    for (const auto& j : refitJobs(kFittable, all)) {
        ASSERT_FALSE(j.own.empty()) << j.surface << " without " << j.heldOut;
        std::set<std::string> seen;
        for (const auto& r : j.own) {
            EXPECT_NE(r.source, j.heldOut) << r.file;
            EXPECT_EQ(r.material, j.material) << r.file;
            seen.insert(r.file);
        }
        for (const auto& r : j.others) {
            EXPECT_NE(r.source, j.heldOut) << r.file;
            EXPECT_NE(r.material, j.material) << r.file;
            seen.insert(r.file);
        }
        // Every recording of the other sources is there, once: own or contrast.
        EXPECT_EQ(seen.size(), withoutSource(all, j.heldOut).size());
        EXPECT_EQ(j.own.size() + j.others.size(), seen.size());
    }
}

TEST(RealismNestedFit, JobsAreDeterministic) {
    const auto first = refitJobs(kFittable, fakeCache());
    const auto second = refitJobs(kFittable, fakeCache());
    ASSERT_EQ(first.size(), second.size());
    for (std::size_t i = 0; i < first.size(); ++i) {
        EXPECT_EQ(first[i].surface, second[i].surface);
        EXPECT_EQ(first[i].heldOut, second[i].heldOut);
        ASSERT_EQ(first[i].own.size(), second[i].own.size());
        for (std::size_t k = 0; k < first[i].own.size(); ++k)
            EXPECT_EQ(first[i].own[k].file, second[i].own[k].file);
    }
}

TEST(RealismNestedFit, BundledSurfacesWithABaseInheritTheirBasesFit) {
    std::vector<Recording> recs;
    for (const char* m : {"wood", "metal", "gravel"}) recs.push_back(rec("a", m, 0));
    const auto fittable = fittableSurfaces(recs);
    std::set<std::string> ids;
    for (const auto& [id, m] : fittable) ids.insert(id);
    EXPECT_TRUE(ids.count("wood"));
    EXPECT_TRUE(ids.count("metal"));
    EXPECT_TRUE(ids.count("gravel"));
    EXPECT_FALSE(ids.count("wood_reverb")) << "base = wood: rendered with wood's refit";
    EXPECT_FALSE(ids.count("creaking_wood"));
    EXPECT_FALSE(ids.count("water")) << "no water recording in this cache";
}

TEST(RealismNestedFit, HeardWithoutSourceNeedsThatSource) {
    std::vector<Example> recs = {
        {"a1", "a", "wood", {0, 0}}, {"b1", "b", "wood", {0, 0}}, {"b2", "b", "water", {1, 1}}};
    recs[0].features.assign(kDescriptorCount, 0.0);
    recs[1].features.assign(kDescriptorCount, 0.0);
    recs[2].features.assign(kDescriptorCount, 1.0);
    std::vector<Example> renders = {{"r", "synthetic", "", recs[0].features}};
    EXPECT_THROW(heardWithoutSource(recs, renders, "z"), std::invalid_argument);
    EXPECT_THROW(heardWithoutSource(recs, {}, "a"), std::invalid_argument);
    EXPECT_EQ(heardWithoutSource(recs, renders, "a").size(), 1u);
}
