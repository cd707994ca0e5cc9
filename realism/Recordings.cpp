// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Recordings.h"

#include "base/DataDir.h"
#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace underfoot::realism {
namespace fs = std::filesystem;

std::string defaultRecordingsDir() {
    return base::recordingsDirectory();
}

const std::vector<std::string>& unseenSources() {
    static const std::vector<std::string> s = {"0ad", "berusky2"};
    return s;
}

bool isUnseenSource(const std::string& source) {
    const auto& u = unseenSources();
    return std::find(u.begin(), u.end(), source) != u.end();
}

std::vector<Recording> withoutUnseenSources(std::vector<Recording> recordings) {
    std::erase_if(recordings, [](const Recording& r) { return isUnseenSource(r.source); });
    return recordings;
}

const std::vector<std::string>& fetchedSources() {
    static const std::vector<std::string> s = {"minetest",   "openarena", "ufoai",
                                               "lugaru",     "nexuiz",    "openclonk",
                                               "redeclipse", "berusky2",  "0ad"};
    return s;
}

namespace {
// The rows of one manifest file; `labOnly`: refuse a source the fetch script writes.
void readManifestFile(const std::string& dir, const fs::path& path, bool labOnly,
                      std::vector<Recording>& out) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot be read", path.string()));
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (lineNo == 1) {
            if (line != kManifestHeader)
                throw std::runtime_error(fmt::format("{}:1: expected the header \"{}\", got \"{}\"",
                                                     path.string(), kManifestHeader, line));
            continue;
        }
        if (line.empty()) continue;
        std::vector<std::string> f;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) f.push_back(cell);
        if (line.back() == ',') f.emplace_back(); // an empty last column (recordist) is a column
        if (f.size() != 7)
            throw std::runtime_error(
                fmt::format("{}:{}: expected 7 comma-separated columns ({}), got {}", path.string(),
                            lineNo, kManifestHeader, f.size()));
        for (std::size_t c = 0; c < 6; ++c)
            if (f[c].empty())
                throw std::runtime_error(
                    fmt::format("{}:{}: column {} is empty", path.string(), lineNo, c + 1));
        const auto& fetched = fetchedSources();
        if (labOnly && std::find(fetched.begin(), fetched.end(), f[1]) != fetched.end())
            throw std::runtime_error(fmt::format(
                "{}:{}: source \"{}\" is one that scripts/fetch-recordings.sh fetches; a lab's "
                "recordings need a name of their own",
                path.string(), lineNo, f[1]));
        Recording r;
        r.file = f[0];
        r.path = (fs::path(dir) / f[0]).string();
        r.source = f[1];
        r.package = f[2];
        r.version = f[3];
        r.licence = f[4];
        r.material = f[5];
        r.recordist = f[6];
        out.push_back(std::move(r));
    }
}
} // namespace

std::vector<Recording> loadManifest(const std::string& dir) {
    const auto fetched = fs::path(dir) / "manifest.csv";
    const auto lab = fs::path(dir) / "lab-manifest.csv";
    const bool hasFetched = fs::exists(fetched), hasLab = fs::exists(lab);
    if (!hasFetched && !hasLab)
        throw std::runtime_error(
            fmt::format("{}: no recordings manifest (run `bash scripts/fetch-recordings.sh {}`)",
                        fetched.string(), dir));
    std::vector<Recording> out;
    if (hasFetched) readManifestFile(dir, fetched, false, out);
    if (hasLab) readManifestFile(dir, lab, true, out);
    return out;
}

namespace {
bool isAudio(const fs::path& p) {
    auto e = p.extension().string();
    std::transform(e.begin(), e.end(), e.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return e == ".wav" || e == ".ogg" || e == ".flac" || e == ".aiff" || e == ".aif";
}
} // namespace

std::vector<Recording> collectRecordings(const std::vector<std::string>& paths) {
    std::vector<Recording> out;
    for (const auto& p : paths) {
        if (!fs::exists(p)) throw std::runtime_error(fmt::format("{}: no such file or folder", p));
        std::vector<std::string> files;
        if (fs::is_directory(p)) {
            for (const auto& e : fs::recursive_directory_iterator(p))
                if (e.is_regular_file() && isAudio(e.path())) files.push_back(e.path().string());
            std::sort(files.begin(), files.end());
            if (files.empty())
                throw std::runtime_error(
                    fmt::format("{}: no audio files (.wav .ogg .flac .aiff) below this folder", p));
        } else {
            files.push_back(p);
        }
        for (auto& f : files) {
            Recording r;
            r.path = f;
            r.file = f;
            r.source = "user";
            r.package = "user";
            r.licence = "unknown";
            out.push_back(std::move(r));
        }
    }
    return out;
}

std::string materialOfSurface(const std::string& surfaceId) {
    static const std::map<std::string, std::string> m = {
        {"beach_sand", "sand"},   {"gravel", "gravel"},
        {"dirt_pebbles", "dirt"}, {"deep_snow", "snow"},
        {"frozen_snow", "snow"},  {"high_grass", "grass"},
        {"wood", "wood"},         {"creaking_wood", "wood"},
        {"wood_reverb", "wood"},  {"creaking_wood_reverb", "wood"},
        {"metal", "metal"},       {"metal_reverb", "metal"},
        {"concrete", "hard"},     {"puddles", "water"},
        {"water", "water"},       {"carpet", "carpet"},
    };
    auto it = m.find(fs::path(surfaceId).stem().string());
    return it == m.end() ? std::string() : it->second;
}

const std::vector<std::string>& knownMaterials() {
    static const std::vector<std::string> m = {"wood", "metal", "hard",  "ice",   "gravel", "sand",
                                               "snow", "dirt",  "grass", "water", "carpet"};
    return m;
}

std::string categoryOfMaterial(const std::string& material) {
    if (material == "wood" || material == "metal" || material == "hard" || material == "ice" ||
        material == "carpet")
        return "solid";
    if (material == "gravel" || material == "sand" || material == "snow" || material == "dirt" ||
        material == "grass")
        return "aggregate";
    if (material == "water") return "liquid";
    throw std::invalid_argument(fmt::format("unknown material \"{}\"", material));
}

} // namespace underfoot::realism
