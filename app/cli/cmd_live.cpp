// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot live`: plays a surface live on the audio device (docs/explanation/live-audio.md) and
// prints the meters, xruns and callback load at the end.
//   live --surface wood [--walker cadence=100 | --mics | --grf FILE] [--seconds 10]
//        [--reverb hall] [--soundscape forest] [--haptics audio|haptic|both] [--pairs both]
//        [--settings settings.toml] [--api jack] [--device system] [--seed 1]
//        [--record grf.wav] [--record-output out.wav]
#include "app/cli/CommandRegistry.h"
#include "app/wiring/Adapters.h"
#include "engine/control/GrfFile.h"
#include "engine/scene/LiveEngine.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

namespace underfoot::cli::live_command {
namespace {
namespace eng = underfoot::engine;

struct LiveArgs {
    std::string surface, walker = "cadence=100", grf, reverb, soundscape, haptics = "audio",
                         pairs = "both", settings, api, device, record, recordOutput;
    bool mics = false, quiet = false;
    bool grfTare = true;
    double seconds = 10.0;
    std::uint64_t seed = 1;
};

std::string db(float x) {
    return x > 0 ? fmt::format("{:.1f} dBFS", 20.0 * std::log10(x)) : std::string("silent");
}

int runLive(const LiveArgs& a) {
    eng::AudioSettings settings;
    try {
        if (!a.settings.empty()) settings = eng::loadAudioSettings(a.settings);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("live --settings: ") + e.what());
    }
    if (!a.api.empty()) settings.api = a.api;
    if (!a.device.empty()) settings.device = a.device;

    eng::LiveSceneDescription d;
    d.surface = a.surface;
    d.impulseResponse = a.reverb;
    d.seed = a.seed;
    try {
        d.modality = eng::parseOutputModality(a.haptics);
        const auto pairs = a.pairs == "both"   ? eng::HapticPairs::Both
                           : a.pairs == "heel" ? eng::HapticPairs::Heel
                           : a.pairs == "toe"  ? eng::HapticPairs::Toe
                           : a.pairs == "none"
                               ? eng::HapticPairs::None
                               : throw std::invalid_argument(fmt::format(
                                     "--pairs {}: expected both, heel, toe or none", a.pairs));
        d.hapticPairs = {pairs, pairs};
        if (a.mics) {
            d.control = eng::ControlKind::Microphones;
        } else if (!a.grf.empty()) {
            d.control = eng::ControlKind::GrfReplay;
        } else {
            d.control = eng::ControlKind::Walker;
            d.walker = eng::WalkerParameters::parse(a.walker);
        }
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("live: ") + e.what());
    }
    if (d.modality != eng::OutputModality::Audio && !settings.channels.hasHaptics())
        throw UserError("live --haptics: the audio settings map no actuator channels; add "
                        "[channels.haptic] to the settings file (docs/reference/settings.md)");

    eng::LiveEngine engine;
    try {
        engine.open(settings);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("live: ") + e.what());
    }
    const auto spec = engine.processSpec();
    std::shared_ptr<eng::AudioRecorder> grfRecorder, outRecorder;
    std::unique_ptr<eng::LiveScene> scene;
    try {
        if (d.control == eng::ControlKind::GrfReplay) {
            eng::GrfLoadOptions o;
            o.targetRateHz = spec.sampleRateHz;
            o.tare = a.grfTare ? eng::GrfTareMode::Apply
                               : eng::GrfTareMode::Off; // (--record stores the GRF as tared:
                                                        // replays read it as it is)
            d.grf = eng::loadGrfFile(a.grf, o);
            fmt::print(stderr, "{}", eng::describeGrfTare(d.grf, a.grf));
        }
        if (!a.soundscape.empty()) d.ambience = wiring::makeSoundscapeAmbience(a.soundscape);
        const int grfChannels = d.control == eng::ControlKind::Walker ? 2
                                : d.control == eng::ControlKind::Microphones
                                    ? 1
                                    : static_cast<int>(d.grf.channels.size());
        if (!a.record.empty())
            d.grfRecorder = grfRecorder =
                eng::makeGrfRecorder(a.record, grfChannels, spec.sampleRateHz);
        if (!a.recordOutput.empty())
            d.outputRecorder = outRecorder =
                std::make_shared<eng::AudioRecorder>(a.recordOutput, 2, spec.sampleRateHz);
        scene = eng::LiveScene::create(std::move(d), spec, engine.settings().channels);
    } catch (const std::exception& e) {
        throw UserError(std::string("live: ") + e.what());
    }
    scene->setMeasureCost(true);
    const std::string summary = scene->summary();
    fmt::print("device: {} \"{}\", {} Hz, {} frames ({:.2f} ms), {} out / {} in\n",
               engine.openedApi(), engine.openedDevice(), engine.settings().sampleRateHz,
               engine.settings().blockSize,
               1e3 * engine.settings().blockSize / engine.settings().sampleRateHz,
               engine.outputChannels(), engine.inputChannels());
    fmt::print("scene: {}\n", summary);
    try {
        engine.start();
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("live: ") + e.what());
    }
    engine.submit(std::move(scene));
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 1; s <= static_cast<int>(std::ceil(a.seconds)); ++s) {
        std::this_thread::sleep_until(
            t0 + std::chrono::duration<double>(std::min<double>(s, a.seconds)));
        if (a.quiet) continue;
        const auto m = engine.meters();
        fmt::print(
            "{:5.1f} s  L {:>11}  R {:>11}  GRF {:6.0f} N  load {:4.1f} %  xruns {}\n",
            std::min<double>(s, a.seconds), db(m.outputPeak[0]),
            db(m.outputPeak[static_cast<std::size_t>(engine.settings().channels.headphonesRight)]),
            m.grfPeakNewtons, m.loadPercent, m.xruns);
    }
    engine.submit(nullptr);
    engine.waitIdle(engine.settings().crossfadeMs * 1e-3 + 2.0);
    const auto m = engine.meters();
    const auto retired = engine.takeRetired();
    engine.close();
    if (grfRecorder) grfRecorder->finish();
    if (outRecorder) outRecorder->finish();

    const double audioSeconds = double(m.frames) / engine.settings().sampleRateHz;
    fmt::print("{:.2f} s played: {} blocks, {} xruns; callback load avg {:.2f} %, max {:.1f} %, "
               "worst block {:.3f} ms of {:.3f} ms\n",
               audioSeconds, m.blocks, m.xruns, m.averageLoadPercent, m.maxLoadPercent,
               m.maxBlockSeconds * 1e3,
               1e3 * engine.settings().blockSize / engine.settings().sampleRateHz);
    if (!retired.empty()) {
        std::string costs;
        for (const auto& c : retired.front()->nodeCosts())
            costs += c.present ? fmt::format("  {} {:.2f} %", eng::toString(c.node),
                                             100.0 * c.seconds / std::max(audioSeconds, 1e-9))
                               : fmt::format("  {} -", eng::toString(c.node));
        fmt::print("node cost (% of one core):{}\n", costs);
    }
    if (grfRecorder)
        fmt::print("GRF recorded: {} ({} frames, {} dropped{})\n", grfRecorder->path(),
                   grfRecorder->writtenFrames(), grfRecorder->droppedFrames(),
                   grfRecorder->error().empty() ? "" : ", " + grfRecorder->error());
    if (outRecorder)
        fmt::print("output recorded: {} ({} frames, {} dropped)\n", outRecorder->path(),
                   outRecorder->writtenFrames(), outRecorder->droppedFrames());
    return (grfRecorder && !grfRecorder->error().empty()) ? 1 : 0;
}

CommandRegistrar reg("live", [](CLI::App& app, int& exitCode) {
    auto a = std::make_shared<LiveArgs>();
    auto* cmd = app.add_subcommand("live", "Play a surface live on the audio device");
    cmd->add_option("--surface", a->surface, "surface id or preset .toml")->required();
    auto* walker =
        cmd->add_option("--walker", a->walker, "virtual walker: cadence=100,mass=70,shoe=0.5")
            ->capture_default_str();
    auto* mics = cmd->add_flag("--mics", a->mics,
                               "drive with the microphones (Cook envelope, loudest input)");
    auto* grf = cmd->add_option("--grf", a->grf, "drive with a GRF recording (.wav/.csv)");
    cmd->add_flag("--grf-tare,!--no-grf-tare", a->grfTare,
                  "with --grf: take each channel's force-plate zero off first (as `render "
                  "--grf-tare`; default on)");
    mics->excludes(grf);
    walker->excludes(mics);
    walker->excludes(grf);
    cmd->add_option("--seconds", a->seconds, "how long to play")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 86400.0));
    cmd->add_option("--reverb", a->reverb, "impulse response (name or file)");
    cmd->add_option("--soundscape", a->soundscape, "soundscape id or definition file");
    cmd->add_option("--haptics", a->haptics, "audio, haptic or both")->capture_default_str();
    cmd->add_option("--pairs", a->pairs, "actuator pairs per shoe: both, heel, toe, none")
        ->capture_default_str();
    cmd->add_option("--settings", a->settings, "audio settings file (underfoot devices --save)");
    cmd->add_option("--api", a->api, "override the settings' audio API");
    cmd->add_option("--device", a->device, "override the settings' device");
    cmd->add_option("--seed", a->seed, "render seed")->capture_default_str();
    cmd->add_option("--record", a->record, "record the GRF (WAV, replayable)");
    cmd->add_option("--record-output", a->recordOutput, "record the headphone output (WAV)");
    cmd->add_flag("--quiet", a->quiet, "no meter line per second");
    cmd->callback([a, &exitCode] { exitCode = runLive(*a); });
});

} // namespace
} // namespace underfoot::cli::live_command
