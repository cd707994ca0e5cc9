// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot recordings`: the recordings cache's sources, and a lab's own recordings added as a
// source of their own (realism/LabRecordings.h).
//   recordings list [--recordings DIR]
//   recordings add --source mylab --material gravel --licence CC-BY-4.0 [--recordist NAME]
//                  [--recordings DIR] FILES_OR_FOLDERS...
//   recordings remove --source mylab [--recordings DIR]
#include "app/cli/CommandRegistry.h"
#include "base/Plural.h"
#include "engine/io/AudioFile.h"
#include "realism/LabRecordings.h"

#include <fmt/core.h>

#include <ctime>
#include <stdexcept>

namespace underfoot::cli::recordings_command {
namespace {
namespace rl = underfoot::realism;

struct Options {
    std::string recordings;
    rl::LabSource source;
    std::vector<std::string> paths;
};

Options& opts() {
    static Options o;
    return o;
}

std::string cacheDir(const Options& o) {
    return o.recordings.empty() ? rl::defaultRecordingsDir() : o.recordings;
}

std::string todayUtc() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[16];
    std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
    return buf;
}

// Runs f, turning the errors of bad input (a name, a file, a manifest) into UserError.
template <typename F>
int guarded(F f) {
    try {
        return f();
    } catch (const engine::FileError& e) {
        throw UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
}

int list(const Options& o) {
    const auto dir = cacheDir(o);
    const auto recs = rl::loadManifest(dir);
    const auto sources = rl::summariseSources(recs);
    fmt::print("{}: {} from {}\n", dir, counted(recs.size(), "file"),
               counted(sources.size(), "source"));
    for (const auto& s : sources) {
        std::string files;
        std::size_t n = 0;
        for (const auto& [m, k] : s.files) {
            files += fmt::format("{}{} {}", files.empty() ? "" : ", ", m, k);
            n += k;
        }
        const char* kind = s.lab      ? "lab (lab-manifest.csv)"
                           : s.unseen ? "fetched, unseen (never tuned on)"
                                      : "fetched";
        fmt::print("  {:<12} {:>3}  {}  [{}]\n", s.source, n, files, kind);
    }
    return 0;
}

int add(Options o) {
    const auto dir = cacheDir(o);
    if (o.source.date.empty()) o.source.date = todayUtc();
    const auto added = rl::addLabRecordings(dir, o.source, o.paths);
    std::size_t steps = 0;
    for (const auto& a : added) steps += a.steps;
    fmt::print("added {} ({}) of {} as source {} to {} (lab-manifest.csv)\n",
               counted(added.size(), "file"), counted(steps, "step"), o.source.material,
               o.source.name, dir);
    for (const auto& a : added) fmt::print("  {}  {}\n", a.file, counted(a.steps, "step"));
    fmt::print("`underfoot compare --listener` and `--figures` now hold {} out like any "
               "source\n",
               o.source.name);
    for (const auto& s : rl::summariseSources(rl::loadManifest(dir)))
        if (s.source == o.source.name && s.files.size() == 1)
            fmt::print("note: {} has one material: the listener centres every source on its "
                       "own median, which a one-material source turns into that material. Add "
                       "a second material (your lab's hard floor will do) for its verdicts to "
                       "count (docs/howto/judge-on-your-recordings.md)\n",
                       o.source.name);
    return 0;
}

int remove(const Options& o) {
    const auto dir = cacheDir(o);
    const auto n = rl::removeLabSource(dir, o.source.name);
    fmt::print("removed source {} ({}) from {}\n", o.source.name, counted(n, "file"), dir);
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "recordings", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand(
            "recordings",
            "The recordings cache: list its sources; add a lab's own recorded footsteps as a "
            "source of their own, or remove them (docs/howto/judge-on-your-recordings.md)");
        cmd->require_subcommand(1);
        const char* dirHelp = "recordings cache of scripts/fetch-recordings.sh (default "
                              "$UNDERFOOT_RECORDINGS or build/recordings)";

        auto* ls = cmd->add_subcommand("list", "Files per source and material");
        ls->add_option("--recordings", o.recordings, dirHelp);
        ls->callback([&exitCode, &o] { exitCode = guarded([&] { return list(o); }); });

        auto* ad = cmd->add_subcommand(
            "add", "Copy audio files into the cache as a lab source (one material per call); "
                   "every file must read and hold at least one step, or nothing is added");
        ad->add_option("--source", o.source.name,
                       "name of the source: your lab or recording session (lower-case letters, "
                       "digits, '-', '_'; not a fetched package's)")
            ->required();
        ad->add_option("--material", o.source.material,
                       "material walked on: wood, metal, hard, ice, gravel, sand, snow, dirt, "
                       "grass, water or carpet")
            ->required();
        ad->add_option("--licence", o.source.licence,
                       "licence of the audio (e.g. CC-BY-4.0, or lab-internal)")
            ->required();
        ad->add_option("--recordist", o.source.recordist, "who recorded it");
        ad->add_option("--date", o.source.date,
                       "the manifest's version column (default: today, UTC, YYYY-MM-DD)");
        ad->add_option("--recordings", o.recordings, dirHelp);
        ad->add_option("files", o.paths, "audio files (.wav .ogg .flac .aiff) or folders")
            ->required();
        ad->callback([&exitCode, &o] { exitCode = guarded([&] { return add(o); }); });

        auto* rm = cmd->add_subcommand(
            "remove", "Remove a lab source: its rows of lab-manifest.csv and its folder");
        rm->add_option("--source", o.source.name, "the lab source to remove")->required();
        rm->add_option("--recordings", o.recordings, dirHelp);
        rm->callback([&exitCode, &o] { exitCode = guarded([&] { return remove(o); }); });
    }};

} // namespace
} // namespace underfoot::cli::recordings_command
