// SPDX-License-Identifier: GPL-3.0-or-later
// A lab's own recordings added to the recordings cache as a source (realism/LabRecordings.h):
// what is copied and listed, every refusal leaving the cache as it was, removal, and the lab
// manifest as loadManifest reads it.
#include "engine/io/AudioFile.h"
#include "realism/Compare.h"
#include "realism/LabRecordings.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {
fs::path labScratch(const std::string& name) {
    auto p =
        fs::temp_directory_path() / ("underfoot_lab_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
}

std::string labSlurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A short render of `surface` written as a WAV: footsteps the step detector finds.
void writeLabSteps(const fs::path& p, const std::string& surface, std::uint64_t seed) {
    fs::create_directories(p.parent_path());
    underfoot::engine::writeAudioFile(
        p.string(), renderForComparison(surface, {"cadence=100", 2.0, seed, 48000}),
        underfoot::engine::SampleFormat::Float32);
}

// A cache as fetch-recordings.sh leaves it: a manifest.csv of two fetched rows.
fs::path fetchedLabCache(const std::string& name) {
    const auto dir = labScratch(name);
    std::ofstream(dir / "manifest.csv")
        << kManifestHeader << "\n"
        << "minetest/wood/a.ogg,minetest,minetest-data,5.6.1,CC0-1.0,wood,someone\n"
        << "ufoai/gravel/b.ogg,ufoai,ufoai-sound,2.5,CC-BY-SA-3.0,gravel,\n";
    return dir;
}

LabSource labGravel(const std::string& name) {
    return {name, "gravel", "CC-BY-4.0", "A. Recordist", "2026-12-06"};
}

// Every file below the cache, relative to it, with its bytes: the whole state of the cache.
std::map<std::string, std::string> cacheSnapshot(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = labSlurp(e.path());
    return out;
}
} // namespace

TEST(LabRecordings, AddCopiesTheFilesAndListsThemBesideTheFetchedOnes) {
    const auto dir = fetchedLabCache("add");
    const auto in = labScratch("add_in");
    writeLabSteps(in / "take1.wav", "gravel", 3);
    writeLabSteps(in / "more" / "take2.wav", "gravel", 7);
    const auto fetchedBefore = labSlurp(dir / "manifest.csv");

    const auto added = addLabRecordings(dir.string(), labGravel("hall-b"), {in.string()});
    ASSERT_EQ(added.size(), 2u);
    EXPECT_EQ(added[0].file, "hall-b/gravel/take2.wav"); // collectRecordings sorts the paths
    EXPECT_EQ(added[1].file, "hall-b/gravel/take1.wav");
    for (const auto& a : added) {
        EXPECT_GT(a.steps, 0u);
        EXPECT_TRUE(fs::exists(dir / a.file)) << a.file;
    }
    EXPECT_EQ(labSlurp(dir / "hall-b/gravel/take1.wav"), labSlurp(in / "take1.wav"));
    EXPECT_EQ(labSlurp(dir / "manifest.csv"), fetchedBefore)
        << "the fetched manifest is not touched";
    EXPECT_FALSE(fs::exists(dir / "lab-manifest.csv.tmp"));

    const auto rows = loadManifest(dir.string());
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_EQ(rows[0].source, "minetest");
    EXPECT_EQ(rows[0].version, "5.6.1");
    EXPECT_EQ(rows[2].file, "hall-b/gravel/take2.wav");
    EXPECT_EQ(rows[2].path, (dir / "hall-b/gravel/take2.wav").string());
    EXPECT_EQ(rows[2].source, "hall-b");
    EXPECT_EQ(rows[2].package, "lab");
    EXPECT_EQ(rows[2].version, "2026-12-06");
    EXPECT_EQ(rows[2].licence, "CC-BY-4.0");
    EXPECT_EQ(rows[2].material, "gravel");
    EXPECT_EQ(rows[2].recordist, "A. Recordist");

    // A second material of the same source, without a recordist, goes beside the first.
    writeLabSteps(in / "snow" / "s.wav", "deep_snow", 5);
    addLabRecordings(dir.string(), {"hall-b", "snow", "lab-internal", "", "2026-12-07"},
                     {(in / "snow" / "s.wav").string()});
    const auto summary = summariseSources(loadManifest(dir.string()));
    ASSERT_EQ(summary.size(), 3u);
    EXPECT_EQ(summary[2].source, "hall-b");
    EXPECT_TRUE(summary[2].lab);
    EXPECT_FALSE(summary[0].lab);
    EXPECT_FALSE(summary[2].unseen);
    const std::vector<std::pair<std::string, std::size_t>> files = {{"gravel", 2}, {"snow", 1}};
    EXPECT_EQ(summary[2].files, files);
    fs::remove_all(dir);
    fs::remove_all(in);
}

TEST(LabRecordings, EveryRefusalNamesTheCauseAndLeavesTheCacheAsItWas) {
    const auto dir = fetchedLabCache("refuse");
    const auto in = labScratch("refuse_in");
    writeLabSteps(in / "a" / "step.wav", "gravel", 3);
    writeLabSteps(in / "b" / "step.wav", "gravel", 5);
    writeLabSteps(in / "ok.wav", "gravel", 7);
    addLabRecordings(dir.string(), labGravel("lab"), {(in / "ok.wav").string()});
    {
        underfoot::engine::AudioBuffer zeros;
        zeros.channels = 1;
        zeros.sampleRateHz = 48000;
        zeros.samples.assign(48000, 0.0f);
        underfoot::engine::writeAudioFile((in / "silent.wav").string(), zeros,
                                          underfoot::engine::SampleFormat::Float32);
        std::ofstream(in / "notes.wav") << "not audio";
    }
    const auto before = cacheSnapshot(dir);
    const auto ok = (in / "a" / "step.wav").string();

    auto refused = [&](const LabSource& s, const std::vector<std::string>& paths,
                       const std::string& expected) {
        SCOPED_TRACE(expected);
        try {
            addLabRecordings(dir.string(), s, paths);
            ADD_FAILURE() << "accepted";
        } catch (const std::exception& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        }
        EXPECT_EQ(cacheSnapshot(dir), before) << "the cache changed";
    };
    refused(labGravel("minetest"), {ok}, "\"minetest\" is a package scripts/fetch-recordings.sh");
    refused(labGravel("0ad"), {ok}, "\"0ad\" is a package");
    refused(labGravel("synthetic"), {ok}, "reserved (the listener's name for the renders)");
    refused(labGravel("My Lab"), {ok}, "'M' is not allowed");
    refused(labGravel(""), {ok}, "expected 1 to 40 characters");
    refused(labGravel(std::string(41, 'a')), {ok}, "expected 1 to 40 characters");
    refused({"lab2", "gravl", "CC0-1.0", "", "2026-12-06"}, {ok},
            "unknown material \"gravl\"; expected one of: wood");
    refused({"lab2", "gravel", "CC0,1.0", "", "2026-12-06"}, {ok}, "the licence \"CC0,1.0\"");
    refused({"lab2", "gravel", "", "", "2026-12-06"}, {ok}, "the licence must not be empty");
    refused({"lab2", "gravel", "CC0-1.0", "a \"b\"", "2026-12-06"}, {ok}, "the recordist");
    refused({"lab2", "gravel", "CC0-1.0", "x", ""}, {ok}, "the date must not be empty");
    refused(labGravel("lab2"), {}, "no audio file or folder to add");
    refused(labGravel("lab2"), {(in / "nope.wav").string()}, "nope.wav: no such file or folder");
    refused(labGravel("lab2"), {ok, (in / "silent.wav").string()}, "silent.wav: no footstep found");
    refused(labGravel("lab2"), {ok, (in / "notes.wav").string()}, "notes.wav");
    refused(labGravel("lab2"), {(in / "a").string(), (in / "b").string()},
            "would both be lab2/gravel/step.wav");
    refused(labGravel("lab"), {(in / "ok.wav").string()},
            "lab/gravel/ok.wav is already in the cache");
    // A file in the source's folder that no manifest lists is not overwritten.
    fs::create_directories(dir / "lab2" / "gravel");
    std::ofstream(dir / "lab2" / "gravel" / "step.wav") << "kept";
    const auto withStray = cacheSnapshot(dir);
    try {
        addLabRecordings(dir.string(), labGravel("lab2"), {ok});
        ADD_FAILURE() << "overwrote a file no manifest lists";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("exists but no manifest lists it"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(cacheSnapshot(dir), withStray);
    fs::remove_all(dir);
    fs::remove_all(in);
}

TEST(LabRecordings, RemoveTakesOutTheSourcesRowsAndFolderOnly) {
    const auto dir = fetchedLabCache("remove");
    const auto in = labScratch("remove_in");
    writeLabSteps(in / "g.wav", "gravel", 3);
    addLabRecordings(dir.string(), labGravel("lab-a"), {(in / "g.wav").string()});
    addLabRecordings(dir.string(), labGravel("lab-b"), {(in / "g.wav").string()});
    const auto fetchedBefore = labSlurp(dir / "manifest.csv");

    EXPECT_EQ(removeLabSource(dir.string(), "lab-a"), 1u);
    EXPECT_FALSE(fs::exists(dir / "lab-a"));
    EXPECT_TRUE(fs::exists(dir / "lab-b/gravel/g.wav"));
    EXPECT_EQ(labSlurp(dir / "manifest.csv"), fetchedBefore);
    const auto rows = loadManifest(dir.string());
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[2].source, "lab-b");

    try {
        removeLabSource(dir.string(), "lab-a");
        ADD_FAILURE() << "removed twice";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("no lab source \"lab-a\" (it lists: lab-b)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(removeLabSource(dir.string(), "ufoai"), std::invalid_argument);
    EXPECT_EQ(loadManifest(dir.string()).size(), 3u);
    fs::remove_all(dir);
    fs::remove_all(in);
}

TEST(LabRecordings, TheLabManifestAloneIsACacheAndHoldsNoFetchedSource) {
    const auto dir = labScratch("alone");
    const auto in = labScratch("alone_in");
    writeLabSteps(in / "w.wav", "wood", 3);
    addLabRecordings(dir.string(), {"studio", "wood", "CC0-1.0", "", "2026-12-06"},
                     {(in / "w.wav").string()});
    EXPECT_FALSE(fs::exists(dir / "manifest.csv"));
    ASSERT_EQ(loadManifest(dir.string()).size(), 1u);

    // A hand-edited lab manifest naming a fetched source is refused with its file and line:
    // the fetch script rewrites that source's rows and folder.
    std::ofstream(dir / "lab-manifest.csv", std::ios::app)
        << "ufoai/wood/x.wav,ufoai,lab,2026-12-06,CC0-1.0,wood,\n";
    try {
        loadManifest(dir.string());
        ADD_FAILURE() << "a fetched source was accepted in the lab's manifest";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("lab-manifest.csv:3: source \"ufoai\""),
                  std::string::npos)
            << e.what();
    }
    fs::remove_all(dir);
    fs::remove_all(in);
}
