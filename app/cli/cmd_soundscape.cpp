// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot soundscape list | render | generators | coherence`: the background environments.
#include "app/cli/CommandRegistry.h"
#include "engine/dsp/Denormals.h"
#include "engine/io/AudioFile.h"
#include "soundscapes/Coherence.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace underfoot::cli::soundscape_command {
namespace {

using namespace underfoot;
using soundscapes::LayerKind;

struct RenderOptions {
    std::string soundscape;
    double seconds = 30.0;
    std::uint64_t seed = 1;
    double rateHz = 48000.0;
    std::string output;
    std::string format = "pcm24";
};

int listSoundscapes() {
    const auto& coherence = soundscapes::CoherenceTable::builtin();
    for (const auto& id : soundscapes::builtinSoundscapeIds()) {
        const auto def = soundscapes::loadSoundscape(id);
        const auto surfaces = coherence.surfacesCoherentWith(id);
        fmt::print("{:<16} {} — {}\n", id, def.name, def.description);
        std::vector<std::string> layers;
        for (const auto& l : def.layers)
            layers.push_back(fmt::format(
                "{} ({})", l.name,
                l.source == soundscapes::LayerSource::Procedural ? l.generator : "recording"));
        fmt::print("{:<16} layers: {}\n", "", fmt::join(layers, ", "));
        fmt::print("{:<16} level {:.1f} dBFS, {:+.1f} dB re footsteps; coherent with: {}\n", "",
                   def.targetLevelDbfs, def.footstepReferenceGainDb,
                   surfaces.empty() ? std::string("-")
                                    : fmt::format("{}", fmt::join(surfaces, ", ")));
    }
    return 0;
}

int listGenerators() {
    for (const auto& g : soundscapes::generatorCatalogue()) {
        fmt::print("{:<11} [{}] {}\n", g.name, g.kind == LayerKind::Bed ? "bed" : "event",
                   g.description);
        for (const auto& p : g.params)
            fmt::print("{:<11}   {} = {} ({} .. {}): {}\n", "", p.name, p.defaultValue, p.minValue,
                       p.maxValue, p.description);
    }
    return 0;
}

int showCoherence(const std::string& surface) {
    const auto& table = soundscapes::CoherenceTable::builtin();
    for (const auto& e : table.entries()) {
        if (!surface.empty() && e.surface != surface) continue;
        fmt::print("{:<18} coherent: {:<15} incoherent (study): {}\n", e.surface,
                   e.coherent.value_or("-"),
                   e.incoherent.empty() ? std::string("-")
                                        : fmt::format("{}", fmt::join(e.incoherent, ", ")));
    }
    if (!surface.empty() && !table.coherentSoundscapeFor(surface) &&
        table.incoherentSoundscapesFor(surface).empty())
        throw cli::UserError(fmt::format("no soundscape is declared for surface '{}'", surface));
    return 0;
}

int render(const RenderOptions& o) {
    if (!(o.seconds > 0.0 && o.seconds <= 3600.0))
        throw cli::UserError(
            fmt::format("--seconds {} is out of range (expected 0 < s <= 3600)", o.seconds));
    if (!(o.rateHz >= 8000.0 && o.rateHz <= 192000.0))
        throw cli::UserError(
            fmt::format("--rate {} is out of range (expected 8000 to 192000)", o.rateHz));
    engine::SampleFormat format = engine::SampleFormat::Pcm24;
    if (o.format == "pcm16")
        format = engine::SampleFormat::Pcm16;
    else if (o.format == "float32")
        format = engine::SampleFormat::Float32;
    else if (o.format != "pcm24")
        throw cli::UserError(
            fmt::format("--format '{}' (expected pcm16, pcm24 or float32)", o.format));

    std::unique_ptr<soundscapes::SoundscapeRenderer> renderer;
    try {
        renderer = std::make_unique<soundscapes::SoundscapeRenderer>(
            soundscapes::loadSoundscape(o.soundscape));
        renderer->prepare({o.rateHz, 1024});
    } catch (const soundscapes::DefinitionError& e) {
        throw cli::UserError(e.what());
    }
    renderer->reset(o.seed);

    const auto frames = static_cast<std::size_t>(std::llround(o.seconds * o.rateHz));
    std::vector<float> left(frames), right(frames);
    {
        engine::ScopedFlushDenormals ftz;
        constexpr int kBlock = 1024;
        for (std::size_t done = 0; done < frames;) {
            const int n = static_cast<int>(std::min<std::size_t>(kBlock, frames - done));
            renderer->process(left.data() + done, right.data() + done, n);
            done += static_cast<std::size_t>(n);
        }
    }
    engine::AudioBuffer out;
    out.sampleRateHz = o.rateHz;
    out.channels = 2;
    out.samples.resize(2 * frames);
    double power = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < frames; ++i) {
        out.samples[2 * i] = left[i];
        out.samples[2 * i + 1] = right[i];
        power += 0.5 * (static_cast<double>(left[i]) * left[i] +
                        static_cast<double>(right[i]) * right[i]);
        peak = std::max({peak, std::fabs(static_cast<double>(left[i])),
                         std::fabs(static_cast<double>(right[i]))});
    }
    const double levelDb = 10.0 * std::log10(power / static_cast<double>(frames) + 1e-30);
    if (peak > 1.0 && format != engine::SampleFormat::Float32)
        throw cli::UserError(fmt::format("the render peaks at {:.2f} (above full scale): lower "
                                         "target_level_dbfs in the definition or use --format "
                                         "float32",
                                         peak));
    try {
        engine::writeAudioFile(o.output, out, format);
    } catch (const engine::FileError& e) {
        throw cli::UserError(e.what());
    }
    const auto& def = renderer->definition();
    fmt::print("{}: {:.1f} s at {:.0f} Hz, seed {} -> {}\n", def.id, o.seconds, o.rateHz, o.seed,
               o.output);
    fmt::print("level {:.1f} dBFS (target {:.1f}), peak {:.1f} dBFS\n", levelDb,
               def.targetLevelDbfs, 20.0 * std::log10(peak + 1e-30));
    for (std::size_t i = 0; i < renderer->layerCount(); ++i) {
        const auto& l = def.layers[i];
        const auto& s = renderer->layerStats(i);
        if (l.kind == LayerKind::Event)
            fmt::print("  {:<14} {} events (declared {:.1f}/min), {} dropped\n", l.name,
                       s.eventsStarted, l.ratePerMinute, s.eventsDropped);
    }
    return 0;
}

const cli::CommandRegistrar registrar("soundscape", [](CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand("soundscape", "Background environments (experiment 2): list, "
                                                 "render, generators, coherence");
    cmd->require_subcommand(1);

    auto* list = cmd->add_subcommand("list", "List the shipped soundscapes");
    list->callback([&exitCode] { exitCode = listSoundscapes(); });

    auto* gens = cmd->add_subcommand("generators", "List the procedural generators and parameters");
    gens->callback([&exitCode] { exitCode = listGenerators(); });

    auto surface = std::make_shared<std::string>();
    auto* coh = cmd->add_subcommand("coherence", "Coherent and incoherent soundscapes per surface");
    coh->add_option("surface", *surface, "Only this surface (e.g. beach_sand)");
    coh->callback([&exitCode, surface] { exitCode = showCoherence(*surface); });

    auto opts = std::make_shared<RenderOptions>();
    auto* r = cmd->add_subcommand("render", "Render a soundscape to a WAV/FLAC file");
    r->add_option("soundscape", opts->soundscape, "Soundscape id or definition file (.toml)")
        ->required();
    r->add_option("--seconds", opts->seconds, "Duration in seconds")->capture_default_str();
    r->add_option("--seed", opts->seed, "Random seed")->capture_default_str();
    r->add_option("--rate", opts->rateHz, "Sample rate in Hz")->capture_default_str();
    r->add_option("--format", opts->format, "pcm16, pcm24 or float32")->capture_default_str();
    r->add_option("-o,--output", opts->output, "Output file (.wav or .flac)")->required();
    r->callback([&exitCode, opts] { exitCode = render(*opts); });
});

} // namespace
} // namespace underfoot::cli::soundscape_command
