// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot replay`: re-render exactly what a participant heard in one trial, from the study's
// stored stimulus, render seed and (when the input was recorded) GRF or gait recording, at the
// sample rate and block size the live engine ran at (read from the recording's meters file):
// the surfaces decide per block, so only the live block size reproduces a live trial exactly.
#include "app/cli/CommandRegistry.h"
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "experiment/Clips.h"
#include "experiment/Store.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/core.h>

#include <toml++/toml.h>

#include <filesystem>
#include <memory>
#include <optional>

namespace underfoot::cli {
namespace {
namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

struct ReplayArgs {
    std::string study, participant, output;
    int trial = 1;
    double seconds = 10.0;
    std::optional<double> rate;   ///< default: the live trial's rate, else 48 kHz
    std::optional<int> blockSize; ///< default: the live trial's block size, else 256
};

/// What the live engine wrote next to a trial's recording (app/wiring LivePlayer).
struct LiveRun {
    std::optional<double> rate;
    std::optional<int> blockSize;
};

LiveRun readMetersFile(const fs::path& recording) {
    LiveRun run;
    const fs::path meters = recording.string() + ".meters.toml";
    if (!fs::exists(meters)) return run;
    try {
        const toml::table t = toml::parse_file(meters.string());
        if (auto r = t["sample_rate"].value<double>(); r && *r > 0) run.rate = *r;
        if (auto b = t["block_size"].value<std::int64_t>(); b && *b > 0 && *b <= 65536)
            run.blockSize = static_cast<int>(*b);
    } catch (const toml::parse_error& e) {
        throw UserError(fmt::format("replay: {}:{}:{}: {}", meters.string(), e.source().begin.line,
                                    e.source().begin.column, e.description()));
    }
    return run;
}

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
    if (stimulus.clip)
        throw UserError(fmt::format(
            "replay: trial {} of {} played the lab-supplied clip `{}` (in the study's clip "
            "folder); that file is what was heard, nothing is rendered for it",
            a.trial, a.participant, *stimulus.clip));
    std::optional<fs::path> recording;
    LiveRun live;
    if (info.grfRecording) {
        recording = fs::path(*info.grfRecording);
        if (recording->is_relative()) recording = fs::path(a.study).parent_path() / *recording;
        live = readMetersFile(*recording);
    }
    const double rate = a.rate.value_or(live.rate.value_or(48000.0));
    const int blockSize = a.blockSize.value_or(live.blockSize.value_or(256));
    if (!(rate >= 8000 && rate <= 384000))
        throw UserError(fmt::format("replay: --rate {} Hz: expected 8000 to 384000", rate));

    if (!stimulus.wading.empty() || stimulus.surface == "water") {
        // Wading: the recorded gait of a live trial, else the virtual gait of the stimulus.
        eng::AudioBuffer audio;
        std::string source;
        try {
            eng::WadingOptions options =
                eng::wadingOptionsFromParameters(exp::parameterStrings(stimulus.wading));
            options.seed = info.renderSeed;
            options.sampleRateHz = rate;
            if (recording) {
                audio = eng::renderWading(options, eng::readGaitCsv(recording->string()));
                source = "recorded gait " + recording->string();
            } else {
                audio = eng::renderWading(options, a.seconds);
                source = fmt::format("virtual gait, {} steps/min", options.cadenceStepsPerMin);
            }
        } catch (const std::exception& e) {
            throw UserError(std::string("replay: ") + e.what());
        }
        eng::writeAudioFile(a.output, audio, eng::SampleFormat::Float32);
        fmt::print("{} trial {} (wading): {:.1f} s from {}, seed {} -> {}\n", info.participant,
                   info.trialIndex, double(audio.frames()) / rate, source, info.renderSeed,
                   a.output);
        return 0;
    }

    eng::GrfSignal grf;
    std::string source;
    if (recording) {
        const fs::path& path = *recording;
        eng::GrfLoadOptions options;
        options.targetRateHz = rate;
        try {
            grf = eng::loadGrfFile(path.string(), options);
        } catch (const std::exception& e) {
            throw UserError(std::string("replay: the trial's GRF recording: ") + e.what());
        }
        source = "recorded GRF " + path.string();
    } else if (stimulus.input.kind == exp::InputKind::Walker) {
        const auto walker = walkerFrom(stimulus.input.walker);
        grf = eng::walkerGrf(walker, a.seconds, rate, info.renderSeed);
        source = "virtual walker " + walker.toString();
    } else {
        throw UserError(fmt::format("replay: trial {} of {} was driven by a live sensor and no GRF "
                                    "recording is stored for it, "
                                    "so what was heard cannot be re-rendered exactly",
                                    a.trial, a.participant));
    }

    eng::RenderOptions options;
    options.sampleRateHz = rate;
    options.blockSize = blockSize;
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
        ambience.prepare({rate, 1024});
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
    fmt::print("{} trial {} ({}{}{}): {:.1f} s from {}, render seed {}, block {} -> {}\n",
               info.participant, info.trialIndex, stimulus.surface,
               stimulus.soundscape ? " + " : "", stimulus.soundscape.value_or(""),
               double(r.audio.frames()) / rate, source, info.renderSeed, blockSize, a.output);
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
    cmd->add_option("--rate", args->rate,
                    "sample rate, Hz (default: the live trial's, from its meters file; else 48000)")
        ->check(CLI::Range(8000.0, 384000.0));
    cmd->add_option("--block", args->blockSize,
                    "render block size (default: the live trial's; else 256)")
        ->check(CLI::Range(1, 65536));
    cmd->add_option("-o,--output", args->output, "output .wav")->required();
    cmd->callback([args, &exitCode] { exitCode = runReplay(*args); });
});

} // namespace
} // namespace underfoot::cli
