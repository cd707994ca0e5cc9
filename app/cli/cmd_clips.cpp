// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot clips`: renders the clips of a listening-test protocol once (wading stimuli through
// the wading simulation, footstep stimuli through the footstep renderer), checks the clips the
// lab supplies, and writes the manifest (seed, length, SHA-256 of every file) that the session
// checks before it starts.
#include "app/cli/CommandRegistry.h"
#include "engine/io/AudioFile.h"
#include "engine/render/Renderer.h"
#include "engine/wading/Wading.h"
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

/// Footsteps driven by the protocol's virtual walker (cadence, mass, shoe, variability).
eng::AudioBuffer renderFootsteps(const exp::ClipJob& job, double rate) {
    std::string spec;
    for (const auto& [key, value] : exp::parameterStrings(job.stimulus.input.walker))
        spec += fmt::format("{}{}={}", spec.empty() ? "" : ",", key, value);
    const auto walker = spec.empty() ? eng::WalkerParameters{} : eng::WalkerParameters::parse(spec);
    const auto grf = eng::walkerGrf(walker, job.seconds, rate, job.seed);
    eng::RenderOptions options;
    options.sampleRateHz = rate;
    options.seed = job.seed;
    options.tailSeconds = 0.5;
    if (job.stimulus.reverb) options.scene.impulseResponse = *job.stimulus.reverb;
    return eng::renderSurface(job.stimulus.surface, grf, options).audio;
}

eng::AudioBuffer renderWadingClip(const exp::ClipJob& job, double rate) {
    auto params = exp::parameterStrings(job.stimulus.wading);
    eng::WadingOptions options = eng::wadingOptionsFromParameters(params);
    options.seed = job.seed;
    options.sampleRateHz = rate;
    return eng::renderWading(options, job.seconds);
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
    fs::create_directories(a.output);
    std::vector<exp::ClipRecord> records;
    const auto started = std::chrono::steady_clock::now();
    for (const auto& job : jobs) {
        exp::ClipRecord r;
        r.stimulusId = job.stimulus.id;
        r.file = fs::path(job.path).lexically_relative(a.output).generic_string();
        r.source = job.source;
        r.seed = job.seed;
        if (job.source == exp::ClipSource::Lab) {
            eng::AudioBuffer audio;
            try {
                audio = eng::readAudioFile(job.path);
            } catch (const std::exception& e) {
                throw UserError(fmt::format("clips: lab-supplied clip of stimulus '{}': {}",
                                            job.stimulus.id, e.what()));
            }
            r.sampleRateHz = audio.sampleRateHz;
            r.frames = audio.frames();
            r.seconds = static_cast<double>(r.frames) / audio.sampleRateHz;
        } else {
            eng::AudioBuffer audio;
            try {
                audio = job.source == exp::ClipSource::Wading ? renderWadingClip(job, a.rate)
                                                              : renderFootsteps(job, a.rate);
            } catch (const std::exception& e) {
                throw UserError(fmt::format("clips: stimulus '{}' ({}:{}): {}", job.stimulus.id,
                                            protocol.sourceName, job.stimulus.id, e.what()));
            }
            eng::writeAudioFile(job.path, audio);
            r.sampleRateHz = audio.sampleRateHz;
            r.frames = audio.frames();
            r.seconds = job.seconds;
        }
        r.sha256 = exp::fileSha256(job.path);
        fmt::print("{:<14} {:<9} seed {:<20} {:6.2f} s  {}\n", r.stimulusId,
                   exp::toString(r.source), r.seed, static_cast<double>(r.frames) / r.sampleRateHz,
                   job.path);
        records.push_back(std::move(r));
    }
    exp::writeClipManifest(a.output, records);
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
