// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot clips`: renders the clips of a listening-test protocol once (wading stimuli through
// the wading simulation, footstep stimuli through the footstep renderer), checks the clips the
// lab supplies, and writes the manifest (seed, length, SHA-256 of every file) that the session
// checks before it starts. The rendering is app/wiring renderClipFolder, which the console uses.
#include "app/cli/CommandRegistry.h"
#include "app/wiring/ClipPlayer.h"
#include "base/Plural.h"
#include "engine/io/AudioDevice.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Clips.h"

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <thread>

namespace underfoot::cli::clips_command {
namespace {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

struct ClipsArgs {
    std::string protocol;
    std::string output;
    double rate = 48000.0;
    bool checkOnly = false;
    bool live = false;    ///< play every clip through the audio device afterwards
    std::string settings; ///< audio settings TOML for --live (`underfoot devices --save`)
};

/// --live: plays the clip folder's clips in protocol order through the configured device, each
/// to its end; refuses with the reason when the device cannot be opened (an option
/// that promises sound plays it or says why not).
void playClips(const ClipsArgs& a, const std::vector<exp::ClipJob>& jobs) {
    eng::AudioSettings settings;
    eng::LiveEngine engine;
    try {
        if (!a.settings.empty()) settings = eng::loadAudioSettings(a.settings);
        engine.open(settings);
        engine.start();
    } catch (const std::exception& e) {
        throw UserError(std::string("clips --live: no sound can be played: ") + e.what());
    }
    fmt::print("live audio: {} / {} at {} Hz, block {}\n", engine.openedApi(),
               engine.openedDevice(), engine.settings().sampleRateHz, engine.settings().blockSize);
    wiring::ClipAudio audio(engine);
    int n = 0;
    for (const auto& job : jobs) {
        try {
            audio.play(job.path);
        } catch (const std::exception& e) {
            throw UserError(fmt::format("clips --live: {}: {}", job.path, e.what()));
        }
        const double seconds =
            static_cast<double>(audio.lastFrames()) / engine.settings().sampleRateHz;
        fmt::print("playing {} of {}: {} ({:.1f} s)\n", ++n, jobs.size(), job.path, seconds);
        std::fflush(stdout);
        std::this_thread::sleep_for(std::chrono::duration<double>(seconds + 0.1));
        audio.stop();
    }
    engine.close();
}

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
        if (problems.empty())
            fmt::print("clips: {} ready in {}\n", counted(jobs.size(), "clip"), a.output);
        if (problems.empty() && a.live) playClips(a, jobs);
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
    fmt::print("clips: {} in {} ({:.1f} s); manifest {}\n", counted(records.size(), "clip"),
               a.output, elapsed,
               (fs::path(a.output) / exp::kClipManifest).lexically_normal().string());
    if (a.live) playClips(a, jobs);
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
        cmd->add_flag("--live", a.live,
                      "then play every clip, in order, through the audio device (refused with "
                      "the reason when it cannot be opened)");
        cmd->add_option("--settings", a.settings,
                        "audio settings file for --live (`underfoot devices --save`)");
        cmd->callback([&exitCode, &a] {
            if (!a.live && !a.settings.empty())
                throw UserError("clips: --settings belongs to --live");
            exitCode = runClips(a);
        });
    }};

} // namespace
} // namespace underfoot::cli::clips_command
