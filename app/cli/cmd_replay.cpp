// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot replay`: re-render exactly what a participant heard in one trial, from the study's
// stored stimulus, render seed and (when the input was recorded) GRF recording.
#include "app/cli/CommandRegistry.h"
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "experiment/Store.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/core.h>

#include <filesystem>
#include <memory>

namespace underfoot::cli {
namespace {
namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

struct ReplayArgs {
    std::string study, participant, output;
    int trial = 1;
    double seconds = 10.0;
    double rate = 48000.0;
};

/// The virtual walker's parameters from a stimulus's `walker = { ... }` table.
eng::WalkerParameters walkerFrom(const exp::Parameters& p) {
    std::string spec;
    for (const auto& [key, value] : p) {
        if (!(key == "cadence" || key == "mass" || key == "shoe" || key == "variability"))
            throw UserError(
                fmt::format("replay: walker parameter `{}` is not one the engine's virtual walker "
                            "knows (cadence, mass, shoe, variability)",
                            key));
        const double* v = std::get_if<double>(&value);
        if (!v) throw UserError(fmt::format("replay: walker parameter `{}` must be a number", key));
        spec += fmt::format("{}{}={}", spec.empty() ? "" : ",", key, *v);
    }
    try {
        return spec.empty() ? eng::WalkerParameters{} : eng::WalkerParameters::parse(spec);
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("replay: ") + e.what());
    }
}

int runReplay(const ReplayArgs& a) {
    exp::ReplayInfo info;
    try {
        const auto store = exp::StudyStore::open(a.study);
        info = store.trialForReplay(a.participant, a.trial);
    } catch (const std::exception& e) {
        throw UserError(std::string("replay: ") + e.what());
    }
    const auto& stimulus = info.stimulus;
    eng::GrfSignal grf;
    std::string source;
    if (info.grfRecording) {
        fs::path path = *info.grfRecording;
        if (path.is_relative()) path = fs::path(a.study).parent_path() / path;
        eng::GrfLoadOptions options;
        options.targetRateHz = a.rate;
        try {
            grf = eng::loadGrfFile(path.string(), options);
        } catch (const std::exception& e) {
            throw UserError(std::string("replay: the trial's GRF recording: ") + e.what());
        }
        source = "recorded GRF " + path.string();
    } else if (stimulus.input.kind == exp::InputKind::Walker) {
        const auto walker = walkerFrom(stimulus.input.walker);
        grf = eng::walkerGrf(walker, a.seconds, a.rate, info.renderSeed);
        source = "virtual walker " + walker.toString();
    } else {
        throw UserError(fmt::format("replay: trial {} of {} was driven by a live sensor and no GRF "
                                    "recording is stored for it, "
                                    "so what was heard cannot be re-rendered exactly",
                                    a.trial, a.participant));
    }

    eng::RenderOptions options;
    options.sampleRateHz = a.rate;
    options.seed = info.renderSeed;
    options.tailSeconds = 1.0;
    if (stimulus.reverb) options.scene.impulseResponse = *stimulus.reverb;
    eng::RenderResult r;
    try {
        r = eng::renderSurface(stimulus.surface, grf, options);
    } catch (const std::exception& e) {
        throw UserError(std::string("replay: ") + e.what());
    }
    if (stimulus.soundscape) {
        // The background as the participant heard it: same seed, calibrated level, mixed in.
        soundscapes::SoundscapeRenderer ambience(soundscapes::loadSoundscape(*stimulus.soundscape));
        ambience.prepare({a.rate, 1024});
        ambience.reset(info.renderSeed);
        const std::size_t n = r.audio.frames();
        std::vector<float> l(n), rr(n);
        ambience.process(l.data(), rr.data(), static_cast<int>(n));
        for (std::size_t i = 0; i < n; ++i) {
            r.audio.samples[2 * i] += l[i];
            r.audio.samples[2 * i + 1] += rr[i];
        }
    }
    eng::writeAudioFile(a.output, r.audio, eng::SampleFormat::Float32);
    fmt::print("{} trial {} ({}{}{}): {:.1f} s from {}, render seed {} -> {}\n", info.participant,
               info.trialIndex, stimulus.surface, stimulus.soundscape ? " + " : "",
               stimulus.soundscape.value_or(""), double(r.audio.frames()) / a.rate, source,
               info.renderSeed, a.output);
    return 0;
}

CommandRegistrar reg("replay", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<ReplayArgs>();
    auto* cmd = app.add_subcommand("replay", "Re-render what a participant heard in one trial");
    cmd->add_option("--study", args->study, "study file (.db)")->required();
    cmd->add_option("--participant", args->participant, "participant code")->required();
    cmd->add_option("--trial", args->trial, "trial index (as in the export's trial_index)")
        ->required()
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--seconds", args->seconds, "length when the virtual walker drove the trial")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
    cmd->add_option("--rate", args->rate, "sample rate, Hz")->capture_default_str();
    cmd->add_option("-o,--output", args->output, "output .wav")->required();
    cmd->callback([args, &exitCode] { exitCode = runReplay(*args); });
});

} // namespace
} // namespace underfoot::cli
