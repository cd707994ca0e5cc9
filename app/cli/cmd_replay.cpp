// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot replay`: re-render exactly what a participant heard in one trial (app/wiring
// renderTrialReplay: stored stimulus, render seed, GRF or gait recording, at the live trial's
// sample rate and block size).
#include "app/cli/CommandRegistry.h"
#include "app/wiring/Replay.h"

#include <fmt/core.h>

#include <memory>

namespace underfoot::cli::replay_command {
namespace {

struct ReplayArgs {
    wiring::ReplayRequest request;
    int trialNumber = 1; ///< as people read it: 1-based ("trial 3 of 40", the export's `trial`)
    std::string output;
};

int runReplay(ReplayArgs a) {
    a.request.trial = a.trialNumber - 1; // the stored index is 0-based
    wiring::ReplayRender r;
    try {
        r = wiring::renderTrialReplay(a.request);
        engine::writeAudioFile(a.output, r.audio, engine::SampleFormat::Float32);
    } catch (const std::exception& e) {
        throw UserError(std::string("replay: ") + e.what());
    }
    fmt::print("{} -> {}\n", r.description, a.output);
    // A replay that is not what was heard must not pass for it (exit 1; the file is kept).
    return r.matchesHeard == false ? 1 : 0;
}

CommandRegistrar reg("replay", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<ReplayArgs>();
    auto& q = args->request;
    auto* cmd = app.add_subcommand("replay", "Re-render what a participant heard in one trial");
    cmd->add_option("--study", q.study, "study file (.db)")->required();
    cmd->add_option("--participant", q.participant, "participant code")->required();
    cmd->add_option("--trial", args->trialNumber,
                    "trial number, 1-based as shown in the session (\"trial 3 of 40\") and in "
                    "the export's `trial` column (= trial_index + 1)")
        ->required()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--seconds", q.walkSeconds,
                    "length when the virtual walker (or gait) drove the trial")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
    cmd->add_option("--rate", q.sampleRateHz,
                    "sample rate, Hz (default: the live trial's, from its meters file; else 48000)")
        ->check(CLI::Range(8000.0, 384000.0));
    cmd->add_option("--block", q.blockSize,
                    "render block size (default: the live trial's; else 256)")
        ->check(CLI::Range(1, 65536));
    cmd->add_option("--clips", q.clipsDir,
                    "clip folder, for a trial that played a lab-supplied clip (default: the "
                    "session's)");
    cmd->add_option("-o,--output", args->output, "output .wav")->required();
    cmd->callback([args, &exitCode] { exitCode = runReplay(*args); });
});

} // namespace
} // namespace underfoot::cli::replay_command
