// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/LabRecordings.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <system_error>

namespace underfoot::realism {
namespace fs = std::filesystem;

namespace {
constexpr const char* kLabManifest = "lab-manifest.csv";

bool isFetched(const std::string& source) {
    const auto& f = fetchedSources();
    return std::find(f.begin(), f.end(), source) != f.end();
}

void checkName(const std::string& name) {
    if (name.empty() || name.size() > 40)
        throw std::invalid_argument(fmt::format(
            "source name \"{}\": expected 1 to 40 characters (lower-case letters, digits, '-', "
            "'_')",
            name));
    for (char c : name)
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_'))
            throw std::invalid_argument(fmt::format(
                "source name \"{}\": '{}' is not allowed (lower-case letters, digits, '-', '_')",
                name, c));
    if (isFetched(name))
        throw std::invalid_argument(fmt::format(
            "source name \"{}\" is a package scripts/fetch-recordings.sh fetches; give your "
            "recordings a name of their own (your lab, your floor)",
            name));
    if (name == "synthetic" || name == "user")
        throw std::invalid_argument(fmt::format(
            "source name \"{}\" is reserved (the listener's name for {}); choose another", name,
            name == "synthetic" ? "the renders" : "files named with --real"));
}

// A manifest cell: no separator, quote or line break, no space at either end.
void checkCell(const char* what, const std::string& value, bool mayBeEmpty) {
    if (value.empty() && !mayBeEmpty)
        throw std::invalid_argument(fmt::format("the {} must not be empty", what));
    if (value.find_first_of(",\"\r\n") != std::string::npos)
        throw std::invalid_argument(fmt::format(
            "the {} \"{}\" holds a comma, a quote or a line break, which the manifest cannot "
            "keep",
            what, value));
    if (!value.empty() && (value.front() == ' ' || value.back() == ' '))
        throw std::invalid_argument(
            fmt::format("the {} \"{}\" begins or ends with a space", what, value));
}

// Every row of the cache's manifests (none when it has neither).
std::vector<Recording> cacheRows(const std::string& dir) {
    if (!fs::exists(fs::path(dir) / "manifest.csv") && !fs::exists(fs::path(dir) / kLabManifest))
        return {};
    return loadManifest(dir);
}

std::vector<Recording> labRows(const std::vector<Recording>& all) {
    std::vector<Recording> out;
    for (const auto& r : all)
        if (!isFetched(r.source)) out.push_back(r);
    return out;
}

// Writes the lab's manifest beside its final name, then renames it over the old one.
void writeLabManifest(const std::string& dir, const std::vector<Recording>& rows) {
    const auto path = fs::path(dir) / kLabManifest;
    const auto tmp = fs::path(dir) / (std::string(kLabManifest) + ".tmp");
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(fmt::format("{}: cannot be written", tmp.string()));
        out << kManifestHeader << "\n";
        for (const auto& r : rows)
            out << fmt::format("{},{},{},{},{},{},{}\n", r.file, r.source, r.package, r.version,
                               r.licence, r.material, r.recordist);
        out.flush();
        if (!out) throw std::runtime_error(fmt::format("{}: cannot be written", tmp.string()));
    }
    fs::rename(tmp, path);
}
} // namespace

std::vector<AddedRecording> addLabRecordings(const std::string& dir, const LabSource& source,
                                             const std::vector<std::string>& paths) {
    checkName(source.name);
    const auto& known = knownMaterials();
    if (std::find(known.begin(), known.end(), source.material) == known.end()) {
        std::string list;
        for (const auto& m : known) list += (list.empty() ? "" : ", ") + m;
        throw std::invalid_argument(
            fmt::format("unknown material \"{}\"; expected one of: {}", source.material, list));
    }
    checkCell("licence", source.licence, false);
    checkCell("recordist", source.recordist, true);
    checkCell("date", source.date, false);
    if (paths.empty()) throw std::invalid_argument("no audio file or folder to add");

    const auto all = cacheRows(dir);
    auto rows = labRows(all);
    std::set<std::string> listed;
    for (const auto& r : all) listed.insert(r.file);

    // Every check first: nothing is copied or written unless every file can be added.
    const auto files = collectRecordings(paths);
    std::map<std::string, std::string> byName; // manifest name -> the file it comes from
    std::vector<AddedRecording> added;
    std::vector<std::pair<std::string, fs::path>> copies;
    const AnalysisOptions analysis;
    for (const auto& f : files) {
        const auto base = fs::path(f.path).filename().string();
        checkCell("file name", base, false);
        const std::string name = source.name + "/" + source.material + "/" + base;
        if (auto [it, fresh] = byName.emplace(name, f.path); !fresh)
            throw std::invalid_argument(
                fmt::format("{} and {} would both be {}: rename one", it->second, f.path, name));
        if (listed.count(name))
            throw std::invalid_argument(fmt::format(
                "{}: {} is already in the cache (remove the source first, or rename the file)",
                f.path, name));
        const auto target = fs::path(dir) / name;
        if (fs::exists(target))
            throw std::invalid_argument(
                fmt::format("{}: {} exists but no manifest lists it; move it away first", f.path,
                            target.string()));
        const auto steps = describeFile(f.path, analysis); // throws engine::FileError
        if (steps.empty())
            throw std::runtime_error(fmt::format(
                "{}: no footstep found (each step must stand out of the background by its onset)",
                f.path));
        added.push_back({name, steps.size()});
        copies.emplace_back(f.path, target);
    }

    std::vector<fs::path> done, madeDirs; // undone if anything fails
    try {
        for (const auto& [from, to] : copies) {
            for (auto d = to.parent_path(); !d.empty() && !fs::exists(d); d = d.parent_path())
                madeDirs.push_back(d);
            fs::create_directories(to.parent_path());
            fs::copy_file(from, to);
            done.push_back(to);
        }
        for (const auto& a : added) {
            Recording r;
            r.file = a.file;
            r.source = source.name;
            r.package = "lab";
            r.version = source.date;
            r.licence = source.licence;
            r.material = source.material;
            r.recordist = source.recordist;
            rows.push_back(std::move(r));
        }
        writeLabManifest(dir, rows);
    } catch (...) {
        std::error_code ec;
        for (const auto& p : done) fs::remove(p, ec);
        for (const auto& d : madeDirs) fs::remove(d, ec); // innermost first; only if empty
        throw;
    }
    return added;
}

std::size_t removeLabSource(const std::string& dir, const std::string& source) {
    if (isFetched(source))
        throw std::invalid_argument(fmt::format(
            "\"{}\" is fetched by scripts/fetch-recordings.sh, not added by a lab: fetch again "
            "without it (UNDERFOOT_RECORDINGS_SKIP) instead",
            source));
    auto rows = labRows(cacheRows(dir));
    std::set<std::string> sources;
    for (const auto& r : rows) sources.insert(r.source);
    if (!sources.count(source)) {
        std::string list;
        for (const auto& s : sources) list += (list.empty() ? "" : ", ") + s;
        throw std::invalid_argument(fmt::format("{}: no lab source \"{}\" (it lists: {})",
                                                (fs::path(dir) / kLabManifest).string(), source,
                                                list.empty() ? "none" : list));
    }
    const auto n = std::size_t(std::count_if(
        rows.begin(), rows.end(), [&](const Recording& r) { return r.source == source; }));
    std::erase_if(rows, [&](const Recording& r) { return r.source == source; });
    writeLabManifest(dir, rows);
    fs::remove_all(fs::path(dir) / source);
    return n;
}

std::vector<SourceSummary> summariseSources(const std::vector<Recording>& recordings) {
    std::vector<SourceSummary> out;
    std::map<std::string, std::size_t> index;
    std::map<std::string, std::map<std::string, std::size_t>> counts;
    for (const auto& r : recordings) {
        if (!index.count(r.source)) {
            index[r.source] = out.size();
            SourceSummary s;
            s.source = r.source;
            s.package = r.package;
            s.lab = !isFetched(r.source);
            s.unseen = isUnseenSource(r.source);
            out.push_back(std::move(s));
        }
        ++counts[r.source][r.material];
    }
    for (auto& s : out) s.files.assign(counts[s.source].begin(), counts[s.source].end());
    return out;
}

} // namespace underfoot::realism
