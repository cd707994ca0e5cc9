// SPDX-License-Identifier: GPL-3.0-or-later
// The listener, the manifest and, when the recordings cache is there, the real recordings.
#include "engine/io/AudioFile.h"
#include "realism/Compare.h"
#include "realism/Listener.h"
#include "realism/Recordings.h"
#include "tests/realism/RecordingsCache.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {
Example example(const std::string& source, const std::string& material, double centre,
                std::mt19937& g) {
    std::normal_distribution<double> n(0.0, 0.3);
    Example e;
    e.name = source + "/" + material;
    e.source = source;
    e.material = material;
    for (int k = 0; k < kDescriptorCount + 4; ++k) e.features.push_back(centre + n(g));
    return e;
}

// Sources a, b and c recorded metal (at 0) and water (at 8), three files each; c alone also
// recorded gravel, at 1, next to metal.
std::vector<Example> metalWaterAndALoneGravel(std::mt19937& g) {
    std::vector<Example> rec;
    for (const char* src : {"a", "b", "c"})
        for (int i = 0; i < 3; ++i) {
            rec.push_back(example(src, "metal", 0.0, g));
            rec.push_back(example(src, "water", 8.0, g));
        }
    for (int i = 0; i < 3; ++i) rec.push_back(example("c", "gravel", 1.0, g));
    return rec;
}

fs::path scratch(const std::string& name) {
    auto p = fs::temp_directory_path() / ("underfoot_realism_" + name);
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
}
} // namespace

TEST(RealismListener, CentringBySourceRemovesASourceWideOffset) {
    // Source "b" recorded everything 4 units higher (another microphone and processing): its
    // metal sits where the others' gravel is. Centred on each source's median, it is heard right.
    std::mt19937 g(9);
    std::vector<Example> ex;
    for (const char* src : {"a", "b", "c"})
        for (int i = 0; i < 3; ++i) {
            const double off = std::string(src) == "b" ? 4.0 : 0.0;
            ex.push_back(example(src, "metal", 0.0 + off, g));
            ex.push_back(example(src, "gravel", 4.0 + off, g));
            ex.push_back(example(src, "water", 8.0 + off, g));
        }
    const auto plain = leaveOneSourceOut(ex, {false, false, false});
    const auto centred = leaveOneSourceOut(ex);
    EXPECT_EQ(centred.files, 27);
    EXPECT_EQ(centred.materialCorrect, 27);
    // Without centring only b's water (beyond everything) is heard right; metal and gravel not.
    EXPECT_EQ(plain.perSource.at("b").first, 3) << "b's files without centring";
    EXPECT_LT(plain.materialCorrect, 27);
    // centreBySource subtracts each source's own median, unlabelled sources too.
    std::vector<Example> s = {
        {"x", "s", "", {1, 10}}, {"y", "s", "", {3, 30}}, {"z", "t", "", {7, 7}}};
    centreBySource(s);
    EXPECT_DOUBLE_EQ(s[0].features[0], -1);
    EXPECT_DOUBLE_EQ(s[1].features[1], 10);
    EXPECT_DOUBLE_EQ(s[2].features[0], 0);
    // One centroid per (source, material): the material's nearest centroid counts.
    Listener l;
    l.train({{"1", "a", "metal", std::vector<double>(kDescriptorCount, 0.0)},
             {"2", "b", "metal", std::vector<double>(kDescriptorCount, 10.0)},
             {"3", "a", "water", std::vector<double>(kDescriptorCount, 4.0)}});
    EXPECT_EQ(l.classify(std::vector<double>(kDescriptorCount, 9.0)), "metal");
    EXPECT_EQ(l.distances(std::vector<double>(kDescriptorCount, 9.0)).size(), 2u);
}

TEST(RealismListener, NearestCentroidAndLeaveOneSourceOut) {
    std::mt19937 g(4);
    std::vector<Example> ex;
    for (const char* src : {"a", "b", "c"})
        for (int i = 0; i < 3; ++i) {
            ex.push_back(example(src, "metal", 0.0, g));
            ex.push_back(example(src, "gravel", 3.0, g));
            ex.push_back(example(src, "water", 6.0, g));
        }
    Listener l;
    l.train(ex);
    EXPECT_EQ(l.materials().size(), 3u);
    EXPECT_EQ(l.classify(std::vector<double>(kDescriptorCount + 4, 5.8)), "water");
    EXPECT_EQ(l.classify(std::vector<double>(kDescriptorCount + 4, 0.3)), "metal");
    const auto r = leaveOneSourceOut(ex);
    EXPECT_EQ(r.files, 27);
    EXPECT_EQ(r.materialCorrect, 27);
    EXPECT_EQ(r.categoryCorrect, 27);
    EXPECT_EQ(r.confusion.at("gravel").at("gravel"), 9);
    // A material only one source has cannot be scored when that source is held out.
    ex.push_back(example("c", "sand", 9.0, g));
    EXPECT_EQ(leaveOneSourceOut(ex).unseenMaterialFiles, 1);
    EXPECT_THROW(l.classify({1.0}), std::invalid_argument);
    std::vector<Example> one = {example("a", "metal", 0, g)};
    EXPECT_THROW(leaveOneSourceOut(one), std::invalid_argument);
}

TEST(RealismListener, RendersAreJudgedByListenersThatNeverHeardASource) {
    // Sources a and b hear gravel at 4; source c alone recorded gravel at 1, next to metal (0).
    // A render at 1.2 (with a metal render at 0 and a water render at 8 beside it, so the renders'
    // own median is 1.2 and centring leaves them in place relative to the recordings' median)
    // is heard as gravel by the listener that knows c, as metal by the one trained without c.
    std::mt19937 g(5);
    const auto rec = metalWaterAndALoneGravel(g);
    const auto n = static_cast<std::size_t>(kDescriptorCount + 4);
    const std::vector<Example> renders = {{"m", "synthetic", "", std::vector<double>(n, 0.0)},
                                          {"g", "synthetic", "", std::vector<double>(n, 1.2)},
                                          {"w", "synthetic", "", std::vector<double>(n, 8.0)}};
    const ListenerOptions plain{false, true, true};
    const auto heard = heardWithoutEachSource(rec, renders, plain);
    ASSERT_EQ(heard.size(), 3u);
    EXPECT_EQ(heard.at("a")[1], "gravel");
    EXPECT_EQ(heard.at("b")[1], "gravel");
    EXPECT_EQ(heard.at("c")[1], "metal") << "without c no source has gravel";
    for (const auto& [src, h] : heard) {
        EXPECT_EQ(h[0], "metal") << src;
        EXPECT_EQ(h[2], "water") << src;
    }
    EXPECT_EQ(heardWithoutEachSource(rec, renders), heardWithoutEachSource(rec, renders));
    EXPECT_THROW(heardWithoutEachSource(rec, {}), std::invalid_argument);
    std::vector<Example> one = {example("a", "metal", 0, g)};
    EXPECT_THROW(heardWithoutEachSource(one, renders), std::invalid_argument);
}

TEST(RealismListener, HeldOutRecordingsAreJudgedByTheRendersListener) {
    // Source c alone recorded gravel, next to everyone's metal: the listener without c, which
    // hears a gravel-like render as metal, hears c's own gravel as metal too.
    std::mt19937 g(5);
    const auto rec = metalWaterAndALoneGravel(g);
    const ListenerOptions plain{false, true, true};
    const auto own = heldOutRecordings(rec, plain);
    ASSERT_EQ(own.size(), 3u);
    const auto& cg = own.at("c").at("gravel");
    EXPECT_EQ(cg.files, 3);
    EXPECT_EQ(cg.categoryRight, 0) << "heard as metal, a solid";
    EXPECT_EQ(cg.materialRight, 0) << "no other source recorded gravel";
    EXPECT_EQ(own.at("a").at("metal").categoryRight, 3);
    EXPECT_EQ(own.at("b").at("water").materialRight, 3);
    EXPECT_EQ(own.at("a").count("gravel"), 0u);
    std::vector<Example> one = {example("a", "metal", 0, g)};
    EXPECT_THROW(heldOutRecordings(one), std::invalid_argument);
}

TEST(RealismListener, EachSourceAloneJudgesTheOthersRecordingsAndTheRenders) {
    // Sources a, b and c recorded metal (0) and water (8); c also gravel, at 4, and d metal
    // alone. Trained on one source, the listener judges the other sources' recordings of the
    // materials that source recorded, and the renders of them; d, with one material, has no
    // listener to speak of.
    std::mt19937 g(5);
    std::vector<Example> rec;
    for (const char* src : {"a", "b", "c"})
        for (int i = 0; i < 3; ++i) {
            rec.push_back(example(src, "metal", 0.0, g));
            rec.push_back(example(src, "water", 8.0, g));
        }
    for (int i = 0; i < 3; ++i) rec.push_back(example("c", "gravel", 4.0, g));
    for (int i = 0; i < 3; ++i) rec.push_back(example("d", "metal", 0.0, g));
    const auto n = static_cast<std::size_t>(kDescriptorCount + 4);
    const std::vector<Example> renders = {{"m", "synthetic", "", std::vector<double>(n, 0.2)},
                                          {"g", "synthetic", "", std::vector<double>(n, 4.2)},
                                          {"w", "synthetic", "", std::vector<double>(n, 7.9)},
                                          {"l", "synthetic", "", std::vector<double>(n, 4.0)}};
    const std::vector<std::string> mats = {"metal", "gravel", "water", ""};
    const ListenerOptions plain{false, true, true};
    const auto f = trainedOnEachSource(rec, renders, mats, plain);
    ASSERT_EQ(f.size(), 3u) << "d recorded one material";
    EXPECT_EQ(f.count("d"), 0u);
    const auto& a = f.at("a");
    EXPECT_EQ(a.recordings.at("metal").files, 9) << "b's, c's and d's metal";
    EXPECT_EQ(a.recordings.at("metal").materialRight, 9);
    EXPECT_EQ(a.recordings.at("water").files, 6);
    EXPECT_EQ(a.recordings.count("gravel"), 0u) << "a did not record gravel";
    ASSERT_EQ(a.heard.size(), 4u);
    EXPECT_EQ(a.heard[0], "metal");
    EXPECT_EQ(a.heard[1], "") << "a render of a material a did not record is not judged by it";
    EXPECT_EQ(a.heard[3], "") << "nor a render of no recorded material";
    EXPECT_EQ(a.renders.at("water").materialRight, 1);
    const auto& c = f.at("c");
    EXPECT_EQ(c.recordings.count("gravel"), 0u) << "no other source recorded gravel";
    EXPECT_EQ(c.heard[1], "gravel");
    EXPECT_EQ(c.renders.at("gravel").files, 1);
    EXPECT_EQ(c.renders.at("gravel").categoryRight, 1);
    EXPECT_EQ(trainedOnEachSource(rec, renders, mats), trainedOnEachSource(rec, renders, mats));
    EXPECT_THROW(trainedOnEachSource(rec, renders, {"metal"}), std::invalid_argument);
    std::vector<Example> one = {example("a", "metal", 0, g), example("a", "water", 8, g)};
    EXPECT_THROW(trainedOnEachSource(one, renders, mats), std::invalid_argument);
}

TEST(RealismListener, HeldOutRecordingsAddUpToLeaveOneSourceOut) {
    // Overlapping materials, so that some files are misheard, and one material a single source
    // has: the counts per source and material add up to leaveOneSourceOut's totals, and the
    // files of the single source's material are its unseen files.
    std::mt19937 g(11);
    std::vector<Example> ex;
    for (const char* src : {"a", "b", "c", "d"})
        for (int i = 0; i < 4; ++i) {
            ex.push_back(example(src, "metal", 0.0, g));
            ex.push_back(example(src, "wood", 0.4, g));
            ex.push_back(example(src, "gravel", 0.8, g));
            ex.push_back(example(src, "water", 1.2, g));
        }
    for (int i = 0; i < 2; ++i) ex.push_back(example("d", "sand", 0.6, g));
    for (const ListenerOptions o : {ListenerOptions{}, ListenerOptions{false, true, false}}) {
        const auto r = leaveOneSourceOut(ex, o);
        ASSERT_LT(r.categoryCorrect, r.files) << "the test needs misheard files";
        ASSERT_GT(r.categoryCorrect, r.materialCorrect);
        int files = 0, cat = 0, mat = 0, unseen = 0;
        for (const auto& [src, mats] : heldOutRecordings(ex, o))
            for (const auto& [m, c] : mats) {
                EXPECT_LE(c.materialRight, c.categoryRight) << src << " " << m;
                if (m == "sand") {
                    unseen += c.files;
                    EXPECT_EQ(c.materialRight, 0);
                    continue;
                }
                files += c.files;
                cat += c.categoryRight;
                mat += c.materialRight;
                EXPECT_EQ(c.files, 4) << src << " " << m;
            }
        EXPECT_EQ(files, r.files);
        EXPECT_EQ(cat, r.categoryCorrect);
        EXPECT_EQ(mat, r.materialCorrect);
        EXPECT_EQ(unseen, r.unseenMaterialFiles);
    }
}

// The listener's examples from recordings, as `compare --listener` and `--figures` build them:
// one per file with a step, the file's features; a silent file is left out and named.
TEST(RealismListener, RecordingExamplesLeaveOutSilentFilesAndNameThem) {
    const auto dir = fs::temp_directory_path() / fmt::format("uf_examples_{}", ::getpid());
    fs::create_directories(dir);
    Recording step;
    step.file = "lab/wood/step.wav";
    step.path = (dir / "step.wav").string();
    step.source = step.package = "lab";
    step.material = "wood";
    underfoot::engine::writeAudioFile(step.path,
                                      renderForComparison("wood", {"cadence=100", 2.0, 7, 48000}),
                                      underfoot::engine::SampleFormat::Float32);
    Recording quiet = step;
    quiet.file = "lab/wood/silent.wav";
    quiet.path = (dir / "silent.wav").string();
    underfoot::engine::AudioBuffer zeros;
    zeros.channels = 1;
    zeros.sampleRateHz = 48000;
    zeros.samples.assign(48000, 0.0f);
    underfoot::engine::writeAudioFile(quiet.path, zeros, underfoot::engine::SampleFormat::Float32);

    AnalysisOptions o;
    std::vector<std::string> silent;
    const auto ex = recordingExamples({quiet, step}, o, &silent);
    ASSERT_EQ(ex.size(), 1u);
    EXPECT_EQ(ex[0].name, "lab/wood/step.wav");
    EXPECT_EQ(ex[0].source, "lab");
    EXPECT_EQ(ex[0].material, "wood");
    EXPECT_EQ(ex[0].features, fileFeatures(describeFile(step.path, o)));
    EXPECT_EQ(silent, std::vector<std::string>{"lab/wood/silent.wav"});
    EXPECT_EQ(recordingExamples({quiet}, o).size(), 0u)
        << "no list asked for: left out all the same";
    fs::remove_all(dir);
}

TEST(RealismRecordings, ManifestErrorsNameTheFileAndLine) {
    const auto dir = scratch("manifest");
    EXPECT_THROW(loadManifest(dir.string()), std::runtime_error); // missing
    { std::ofstream(dir / "manifest.csv") << "file,source\n"; }
    try {
        loadManifest(dir.string());
        FAIL() << "a bad header was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("manifest.csv:1"), std::string::npos) << e.what();
    }
    {
        std::ofstream(dir / "manifest.csv")
            << "file,source,package,version,licence,material,recordist\n"
            << "a/b.wav,src,pkg,1,CC0-1.0,metal,someone\n"
            << "a/c.wav,src,pkg,1,CC0-1.0\n";
    }
    try {
        loadManifest(dir.string());
        FAIL() << "a short line was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("manifest.csv:3"), std::string::npos) << e.what();
    }
    EXPECT_EQ(materialOfSurface("gravel"), "gravel");
    EXPECT_EQ(materialOfSurface("carpet"), "carpet");
    EXPECT_EQ(materialOfSurface("dry_leaves"), "");
    EXPECT_EQ(categoryOfMaterial("water"), "liquid");
    EXPECT_THROW(categoryOfMaterial("lava"), std::invalid_argument);
    EXPECT_THROW(collectRecordings({(dir / "nope").string()}), std::runtime_error);
    fs::remove_all(dir);
}

// Found while seeding fuzz_recordings_manifest: a row whose last column (recordist,
// the one column that may be empty) was empty counted 6 columns and the whole manifest was
// refused.
TEST(RealismRecordings, ManifestAcceptsAnEmptyRecordist) {
    const auto dir = scratch("manifest_recordist");
    {
        std::ofstream(dir / "manifest.csv")
            << "file,source,package,version,licence,material,recordist\r\n"
            << "lab/snow/take 1.wav,lab,lab,2026-11,CC-BY-4.0,snow,\r\n"
            << "a/b.wav,src,pkg,1,CC0-1.0,metal,someone\n";
    }
    const auto rows = loadManifest(dir.string());
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].file, "lab/snow/take 1.wav");
    EXPECT_EQ(rows[0].material, "snow");
    EXPECT_EQ(rows[0].recordist, "");
    EXPECT_EQ(rows[1].recordist, "someone");
    // An empty required column is still refused with the file and line.
    {
        std::ofstream(dir / "manifest.csv")
            << "file,source,package,version,licence,material,recordist\n"
            << "a/b.wav,src,pkg,1,CC0-1.0,,\n";
    }
    try {
        loadManifest(dir.string());
        FAIL() << "an empty material was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("manifest.csv:2: column 6 is empty"),
                  std::string::npos)
            << e.what();
    }
    fs::remove_all(dir);
}

// The unseen sources (fetch-recordings.sh --unseen) are never fitted on: withoutUnseenSources,
// which `underfoot fit` and the tests' fixture read the cache through, drops their rows alone.
TEST(RealismRecordings, TheUnseenSourceIsLeftOutOfTheCacheForFitting) {
    const auto dir = scratch("manifest_unseen");
    {
        std::ofstream(dir / "manifest.csv")
            << "file,source,package,version,licence,material,recordist\n"
            << "ufoai/gravel/gravel1.ogg,ufoai,ufoai-sound,2.5,CC-BY-SA-3.0,gravel,UFO:AI team\n"
            << "0ad/gravel/fs_gravel1.ogg,0ad,0ad-data,0.0.26,CC-BY-SA-3.0,gravel,Wildfire\n"
            << "minetest/snow/s.ogg,minetest,minetest-data,5.6,CC0-1.0,snow,Ryding\n"
            << "0ad/snow/fs_snow_11.ogg,0ad,0ad-data,0.0.26,CC-BY-SA-3.0,snow,Wildfire\n"
            << "berusky2/snow/stepsnow2.wav,berusky2,berusky2-data,0.12-2,GPL-2+,snow,AnakreoN\n";
    }
    const auto all = loadManifest(dir.string());
    ASSERT_EQ(all.size(), 5u);
    const auto kept = withoutUnseenSources(all);
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_EQ(kept[0].source, "ufoai");
    EXPECT_EQ(kept[1].source, "minetest");
    EXPECT_EQ(unseenSources(), (std::vector<std::string>{"0ad", "berusky2"}));
    EXPECT_TRUE(isUnseenSource("berusky2"));
    EXPECT_FALSE(isUnseenSource("ufoai"));
    EXPECT_EQ(withoutUnseenSources(kept).size(), 2u);
    fs::remove_all(dir);
}

// The real recordings (scripts/fetch-recordings.sh). Skipped, saying so, without the cache.
class RealRecordings : public underfoot::realism::test::RecordingsCacheTest {};

TEST_F(RealRecordings, EveryRecordingHasStepsAndTheListenerBeatsChance) {
    ASSERT_GE(recs_.size(), 20u);
    std::set<std::string> sources;
    for (const auto& r : recs_) sources.insert(r.source);
    if (sources.size() < 4)
        GTEST_SKIP()
            << "the recordings cache at " << dir_ << " has " << sources.size()
            << " sources, this test is for the 4 of scripts/fetch-recordings.sh: re-run it";
    AnalysisOptions o;
    o.maxHz = sharedMaxHz(recs_, 48000);
    for (const auto& r : recs_) ASSERT_TRUE(fs::exists(r.path)) << r.path;
    std::vector<std::string> silent;
    const auto ex = recordingExamples(recs_, o, &silent);
    ASSERT_TRUE(silent.empty()) << silent.front() << ": no step found";
    ASSERT_EQ(ex.size(), recs_.size());
    const auto loso = leaveOneSourceOut(ex);
    ASSERT_GT(loso.files, 0);
    // Better than always answering the commonest material (or category) of the held-out files.
    int commonestMaterial = 0;
    std::map<std::string, int> perCategory;
    for (const auto& [truth, row] : loso.confusion) {
        int n = 0;
        for (const auto& [heard, k] : row) n += k;
        commonestMaterial = std::max(commonestMaterial, n);
        perCategory[categoryOfMaterial(truth)] += n;
    }
    int commonestCategory = 0;
    for (const auto& [c, n] : perCategory) commonestCategory = std::max(commonestCategory, n);
    EXPECT_GT(loso.materialCorrect, commonestMaterial) << loso.materialCorrect << "/" << loso.files;
    EXPECT_GT(loso.categoryCorrect, commonestCategory) << loso.categoryCorrect << "/" << loso.files;
}

TEST_F(RealRecordings, RecordedMetalDecaysFasterThanTheOldRingingMetal) {
    std::vector<Recording> metal;
    for (const auto& r : recs_)
        if (r.material == "metal") metal.push_back(r);
    ASSERT_FALSE(metal.empty());
    RenderSpec spec;
    spec.seconds = 4;
    const auto c = compareSurface("metal", metal, spec);
    EXPECT_GT(c.comparison.realSteps, 3);
    EXPECT_GT(c.comparison.syntheticSteps, 4);
    EXPECT_GT(c.comparison.distance, 0.0);
    EXPECT_TRUE(std::isfinite(c.comparison.distance));
}
