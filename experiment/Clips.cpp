// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Clips.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace underfoot::experiment {

const char* toString(ClipSource source) {
    switch (source) {
    case ClipSource::Wading:
        return "wading";
    case ClipSource::Footsteps:
        return "footsteps";
    case ClipSource::Lab:
        return "lab";
    }
    return "lab";
}

std::map<std::string, std::string> parameterStrings(const Parameters& parameters) {
    std::map<std::string, std::string> out;
    for (const auto& [name, value] : parameters) {
        if (const auto* b = std::get_if<bool>(&value))
            out[name] = *b ? "true" : "false";
        else if (const auto* d = std::get_if<double>(&value))
            out[name] = fmt::format("{}", *d);
        else
            out[name] = std::get<std::string>(value);
    }
    return out;
}

std::vector<ClipJob> clipJobs(const Protocol& protocol, const std::string& clipDir) {
    if (!protocol.clips.enabled)
        throw std::invalid_argument(fmt::format("protocol {} ({}) is not a listening test: it has "
                                                "no [clips] table and no lab-supplied clip",
                                                protocol.id, protocol.sourceName));
    std::vector<ClipJob> jobs;
    for (const auto& s : protocol.stimuli) {
        ClipJob j;
        j.stimulus = s;
        j.source = s.clip                 ? ClipSource::Lab
                   : s.surface == "water" ? ClipSource::Wading
                                          : ClipSource::Footsteps;
        j.path = clipPath(s, clipDir);
        j.seed = clipSeed(protocol, s);
        j.seconds = protocol.clips.seconds;
        jobs.push_back(std::move(j));
    }
    return jobs;
}

namespace {
std::string manifestPath(const std::string& clipDir) {
    return (std::filesystem::path(clipDir) / kClipManifest).lexically_normal().string();
}
std::vector<std::string> splitComma(const std::string& line) {
    std::vector<std::string> out;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
}
} // namespace

std::string fileSha256(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot read the file", path));
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return sha256Hex(bytes.str());
}

void writeClipManifest(const std::string& clipDir, const std::vector<ClipRecord>& records) {
    const std::string path = manifestPath(clipDir);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot write the clip manifest", path));
    out << "stimulus_id,file,source,seed,seconds,sample_rate_hz,frames,sha256,samples_sha256\n";
    for (const auto& r : records) {
        if (r.file.find(',') != std::string::npos)
            throw std::runtime_error(
                fmt::format("{}: clip file name '{}' contains a comma", path, r.file));
        out << fmt::format("{},{},{},{},{},{},{},{},{}\n", r.stimulusId, r.file, toString(r.source),
                           r.seed, r.seconds, r.sampleRateHz, r.frames, r.sha256, r.samplesSha256);
    }
    if (!out) throw std::runtime_error(fmt::format("{}: writing the clip manifest failed", path));
}

std::vector<ClipRecord> readClipManifest(const std::string& clipDir) {
    const std::string path = manifestPath(clipDir);
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    std::vector<ClipRecord> out;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (lineNo == 1 || line.empty()) continue;
        const auto cells = splitComma(line);
        if (cells.size() != 8 && cells.size() != 9)
            throw std::runtime_error(fmt::format(
                "{}:{}: expected 9 comma-separated fields (8 in older manifests), found {}", path,
                lineNo, cells.size()));
        ClipRecord r;
        r.stimulusId = cells[0];
        r.file = cells[1];
        if (cells[2] == "wading")
            r.source = ClipSource::Wading;
        else if (cells[2] == "footsteps")
            r.source = ClipSource::Footsteps;
        else if (cells[2] == "lab")
            r.source = ClipSource::Lab;
        else
            throw std::runtime_error(fmt::format("{}:{}: source '{}': expected wading, footsteps "
                                                 "or lab",
                                                 path, lineNo, cells[2]));
        // Whole cells only: "7abc" is not 7 and "-1" is not 2^64 - 1 (std::stoull accepted
        // both; found reviewing fuzz_clip_manifest).
        const auto whole = [&](const std::string& cell, const char* name, auto& v) {
            const auto parsed = std::from_chars(cell.data(), cell.data() + cell.size(), v);
            if (parsed.ec != std::errc{} || parsed.ptr != cell.data() + cell.size())
                throw std::runtime_error(fmt::format(
                    "{}:{}: {} '{}': expected a whole number 0 to {}", path, lineNo, name, cell,
                    std::numeric_limits<std::remove_reference_t<decltype(v)>>::max()));
        };
        const auto real = [&](const std::string& cell, const char* name, double& v) {
            const auto parsed = std::from_chars(cell.data(), cell.data() + cell.size(), v);
            if (parsed.ec != std::errc{} || parsed.ptr != cell.data() + cell.size() ||
                !std::isfinite(v) || v < 0)
                throw std::runtime_error(fmt::format("{}:{}: {} '{}': expected a finite number "
                                                     ">= 0",
                                                     path, lineNo, name, cell));
        };
        whole(cells[3], "seed", r.seed);
        real(cells[4], "seconds", r.seconds);
        real(cells[5], "sample_rate_hz", r.sampleRateHz);
        whole(cells[6], "frames", r.frames);
        r.sha256 = cells[7];
        if (cells.size() == 9) r.samplesSha256 = cells[8];
        out.push_back(std::move(r));
    }
    return out;
}

std::vector<std::string> checkClips(const Protocol& protocol, const std::string& clipDir) {
    std::vector<std::string> problems;
    for (const auto& p : checkClipFiles(protocol, clipDir)) problems.push_back(p.toString());
    std::map<std::string, ClipRecord> manifest;
    try {
        for (auto& r : readClipManifest(clipDir)) manifest[r.stimulusId] = std::move(r);
    } catch (const std::runtime_error& e) {
        problems.emplace_back(e.what());
        return problems;
    }
    for (const auto& job : clipJobs(protocol, clipDir)) {
        if (job.source == ClipSource::Lab) continue; // checked above
        if (!std::filesystem::exists(job.path)) {
            problems.push_back(fmt::format("clip of stimulus '{}' ({}) is not rendered yet; run "
                                           "`underfoot clips --protocol {} -o {}`",
                                           job.stimulus.id, job.path, protocol.sourceName,
                                           clipDir));
            continue;
        }
        const auto it = manifest.find(job.stimulus.id);
        if (it == manifest.end()) {
            problems.push_back(fmt::format("clip {} is not in the manifest {}; render the "
                                           "clips again with `underfoot clips`",
                                           job.path, manifestPath(clipDir)));
            continue;
        }
        if (it->second.seed != job.seed)
            problems.push_back(fmt::format("clip {} was rendered with seed {}, the protocol asks "
                                           "for {}; render the clips again",
                                           job.path, it->second.seed, job.seed));
        else if (fileSha256(job.path) != it->second.sha256)
            problems.push_back(fmt::format("clip {} changed since it was rendered (SHA-256 "
                                           "differs from {}); render the clips again",
                                           job.path, manifestPath(clipDir)));
    }
    return problems;
}

ClipPlayer::ClipPlayer(const Protocol& protocol, std::string clipDir, PlayFunction play,
                       std::function<void()> stop)
    : protocol_(protocol), clipDir_(std::move(clipDir)), play_(std::move(play)),
      stop_(std::move(stop)) {
    const auto problems = checkClips(protocol_, clipDir_);
    if (!problems.empty()) {
        std::string all;
        for (const auto& p : problems) all += (all.empty() ? "" : "\n") + p;
        throw StoreError(all);
    }
    for (auto& r : readClipManifest(clipDir_)) manifest_[r.stimulusId] = std::move(r);
}

const ClipRecord* ClipPlayer::record(const std::string& stimulusId) const {
    const auto it = manifest_.find(stimulusId);
    return it == manifest_.end() ? nullptr : &it->second;
}

StimulusStart ClipPlayer::start(const Stimulus& stimulus, std::uint64_t) {
    const std::string path = clipPath(stimulus, clipDir_);
    if (!std::filesystem::exists(path))
        throw StoreError(fmt::format("the clip of this trial is missing: {}", path));
    const ClipRecord* r = record(stimulus.id);
    if (!r && stimulus.clip) {
        // A lab-supplied file that `underfoot clips` has not recorded yet: stored by name only
        // (`underfoot clips` records its length and samples for replay).
        lastPath_ = path;
        ++presentations_;
        if (play_) play_(path);
        StimulusStart started;
        started.renderSeed = clipSeed(protocol_, stimulus);
        started.clip = PlayedClip{*stimulus.clip, 0.0, 0, 0.0, ""};
        return started;
    }
    if (!r)
        throw StoreError(fmt::format("{} is not in the manifest {}; render the clips again "
                                     "with `underfoot clips`",
                                     path, manifestPath(clipDir_)));
    // What is played is what the manifest describes (and what the trial will store).
    if (fileSha256(path) != r->sha256)
        throw StoreError(fmt::format("{} changed since it was rendered (SHA-256 differs from "
                                     "{}); render the clips again",
                                     path, manifestPath(clipDir_)));
    lastPath_ = path;
    ++presentations_;
    if (play_) play_(path);
    StimulusStart started;
    started.renderSeed = r->seed;
    PlayedClip c;
    c.file = r->file;
    c.seconds = r->sampleRateHz > 0 ? static_cast<double>(r->frames) / r->sampleRateHz : 0.0;
    c.frames = r->frames;
    c.sampleRateHz = r->sampleRateHz;
    c.samplesSha256 = r->samplesSha256;
    started.clip = c;
    return started;
}

void ClipPlayer::stop() {
    if (stop_) stop_();
}

} // namespace underfoot::experiment
