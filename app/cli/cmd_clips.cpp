// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot clips`: renders the clips of a listening-test protocol once (wading stimuli through
// the wading simulation, footstep stimuli through the footstep renderer), checks the clips the
// lab supplies, and writes the manifest (seed, length, SHA-256 of every file) that the session
// checks before it starts. The rendering is app/wiring renderClipFolder, which the console uses.
#include "app/cli/CommandRegistry.h"
#include "app/wiring/ClipPlayer.h"
#include "experiment/Clips.h"

#include <fmt/core.h>

#include <chrono>
#include <filesystem>

namespace underfoot::cli {
namespace {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

struct ClipsArgs {
    std::string protocol;
    std::string output;
    double rate = 48000.0;
    bool checkOnly = false;
};

ClipsArgs& args() {
    static ClipsArgs a;
    return a;
}

int runClips(const ClipsArgs& a) {
    exp::Protocol protocol;
    try {
        protocol = exp::loadProtocol(a.protocol);
    } catch (const exp::ProtocolError& e) {
        throw UserError(e.what());
    }
    if (a.output.empty()) throw UserError("clips: -o FOLDER is required");
    std::vector<exp::ClipJob> jobs;
    try {
        jobs = exp::clipJobs(protocol, a.output);
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("clips: ") + e.what());
    }
    // Lab-supplied recordings first: a missing one stops everything, with its protocol line.
    if (const auto missing = exp::checkClipFiles(protocol, a.output); !missing.empty()) {
        std::string all;
        for (const auto& p : missing) all += (all.empty() ? "" : "\n") + p.toString();
        throw UserError(all);
    }
    if (a.checkOnly) {
        const auto problems = exp::checkClips(protocol, a.output);
        for (const auto& p : problems) fmt::print("{}\n", p);
        if (problems.empty()) fmt::print("clips: {} clips ready in {}\n", jobs.size(), a.output);
        return problems.empty() ? 0 : 1;
    }
    const auto started = std::chrono::steady_clock::now();
    std::vector<exp::ClipRecord> records;
    try {
        records = wiring::renderClipFolder(protocol, a.output, a.rate);
    } catch (const std::exception& e) {
        throw UserError(std::string("clips: ") + e.what());
    }
    for (const auto& r : records)
        fmt::print("{:<14} {:<9} seed {:<20} {:6.2f} s  {}\n", r.stimulusId,
                   exp::toString(r.source), r.seed, static_cast<double>(r.frames) / r.sampleRateHz,
                   (fs::path(a.output) / r.file).string());
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    fmt::print("clips: {} clips in {} ({:.1f} s); manifest {}/{}\n", records.size(), a.output,
               elapsed, a.output, exp::kClipManifest);
    return 0;
}

const CommandRegistrar registrar{
    "clips", [](CLI::App& app, int& exitCode) {
        ClipsArgs& a = args();
        auto* cmd = app.add_subcommand(
            "clips", "Render the clips of a listening-test protocol into a folder (wading and "
                     "footstep stimuli; lab-supplied recordings are checked), with a manifest of "
                     "seeds and SHA-256 sums");
        cmd->add_option("--protocol", a.protocol, "protocol file (.toml)")->required();
        cmd->add_option("-o,--output", a.output, "clip folder (lab recordings go in it too)");
        cmd->add_option("--rate", a.rate, "sample rate of rendered clips (Hz)")
            ->check(CLI::Range(8000.0, 192000.0));
        cmd->add_flag("--check", a.checkOnly,
                      "only check that every clip is present and unchanged (exit 1 otherwise)");
        cmd->callback([&exitCode, &a] { exitCode = runClips(a); });
    }};

} // namespace
} // namespace underfoot::cli
