// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot render`: footsteps on a surface, offline, through the live processing code.
#include "app/cli/CommandRegistry.h"
#include "engine/control/GrfFile.h"
#include "engine/io/AudioFile.h"
#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"
#include "engine/wading/WadingScene.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <memory>

namespace underfoot::cli::render_command {
namespace {
namespace eng = underfoot::engine;

struct RenderArgs {
    std::vector<std::string> surfaces;
    bool all = false;
    std::string walker = "cadence=100";
    std::string grfFile;
    double seconds = 10.0;
    double tail = 1.0;
    std::uint64_t seed = 7;
    double rate = 48000.0;
    int block = 256;
    int oversampling = 1;
    int newton = 6;
    bool explicitImpact = false;
    bool dry = false;
    std::string output;
    std::string format = "pcm24";
    double grfFullScale = 1000.0;
    bool grfTare = true;
    bool quiet = false;
};

eng::SampleFormat parseFormat(const std::string& f) {
    if (f == "pcm16") return eng::SampleFormat::Pcm16;
    if (f == "pcm24") return eng::SampleFormat::Pcm24;
    if (f == "float") return eng::SampleFormat::Float32;
    throw UserError("--format: expected pcm16, pcm24 or float, got \"" + f + "\"");
}

int runRender(const RenderArgs& a) {
    std::vector<std::string> surfaces = a.surfaces;
    if (a.all)
        for (const auto& info : eng::listSurfaces()) surfaces.push_back(info.id);
    if (surfaces.empty())
        throw UserError(
            "render: name a surface with --surface (see `underfoot surfaces`) or use --all");
    if (a.output.empty())
        throw UserError("render: -o is required (a .wav file, or a folder for several surfaces)");
    const bool many = surfaces.size() > 1 || std::filesystem::is_directory(a.output);
    if (many) std::filesystem::create_directories(a.output);

    eng::GrfSignal grf;
    std::string source;
    try {
        if (!a.grfFile.empty()) {
            eng::GrfLoadOptions lo;
            lo.targetRateHz = a.rate;
            lo.fullScaleNewtons = a.grfFullScale;
            lo.tare = a.grfTare ? eng::GrfTareMode::Apply : eng::GrfTareMode::Off;
            grf = eng::loadGrfFile(a.grfFile, lo);
            source = a.grfFile;
            if (!a.quiet) fmt::print(stderr, "{}", eng::describeGrfTare(grf, a.grfFile));
        } else {
            const auto params = eng::WalkerParameters::parse(a.walker);
            grf = eng::walkerGrf(params, a.seconds, a.rate, a.seed);
            source = "virtual walker " + params.toString();
        }
    } catch (const eng::FileError& e) {
        throw UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string(a.grfFile.empty() ? "--walker: " : "--grf: ") + e.what());
    }

    eng::RenderOptions options;
    options.sampleRateHz = a.rate;
    options.blockSize = a.block;
    options.seed = a.seed;
    options.tailSeconds = a.tail;
    options.scene.reverb = a.dry ? eng::ReverbMode::Off : eng::ReverbMode::AsPreset;
    options.scene.accuracy.oversampling = a.oversampling;
    options.scene.accuracy.newtonIterations = a.newton;
    options.scene.accuracy.explicitImpact = a.explicitImpact;
    const auto format = parseFormat(a.format);
    for (const auto& s : surfaces) {
        eng::RenderResult r;
        try {
            r = eng::renderSurface(s, grf, options);
        } catch (const eng::PresetError& e) {
            throw UserError(e.what());
        } catch (const eng::FileError& e) {
            throw UserError(e.what());
        }
        const std::string path = many ? (std::filesystem::path(a.output) /
                                         (std::filesystem::path(s).stem().string() + ".wav"))
                                            .string()
                                      : a.output;
        float peak = 0;
        for (float v : r.audio.samples) peak = std::max(peak, std::fabs(v));
        if (peak >= 1.0f && format != eng::SampleFormat::Float32)
            throw UserError(fmt::format("{}: the render peaks at {:.1f} dBFS and would clip in {}; "
                                        "lower the surface's gain_db or use --format float",
                                        s, 20 * std::log10(peak), a.format));
        if (r.limiter.acted())
            fmt::print(stderr,
                       "underfoot: note: {}: the output safety limiter acted on {} samples (up to "
                       "{:.2f} dB of gain reduction); lower the surface's gain_db for a clean "
                       "render\n",
                       s, r.limiter.samplesLimited, r.limiter.maxReductionDb);
        eng::writeAudioFile(path, r.audio, format);
        if (!a.quiet)
            fmt::print("{}: {:.1f} s from {}, seed {}, peak {:.1f} dBFS, {:.0f}x real time -> {}\n",
                       s, double(r.audio.frames()) / a.rate, source, a.seed,
                       peak > 0 ? 20 * std::log10(peak) : -999.0, r.realTimeFactor, path);
    }
    return 0;
}

CommandRegistrar reg("render", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand("render", "Render footsteps on a surface to an audio file");
    cmd->add_option("-s,--surface", args->surfaces,
                    "surface id(s) (see `underfoot surfaces`) or preset .toml file(s)")
        ->delimiter(',');
    cmd->add_flag("--all", args->all, "render every bundled surface (then -o is a folder)");
    cmd->add_option("--walker", args->walker,
                    "virtual walker: cadence=STEPS/MIN,mass=KG,shoe=0..1,variability=0..0.2")
        ->capture_default_str();
    cmd->add_option(
        "--grf", args->grfFile,
        "drive with a GRF file instead (mono/multichannel WAV, or CSV time_s,<name>...)");
    cmd->add_option("--grf-full-scale", args->grfFullScale,
                    "newtons of a full-scale sample in a WAV GRF")
        ->capture_default_str();
    cmd->add_flag("--grf-tare,!--no-grf-tare", args->grfTare,
                  "take each GRF channel's force-plate zero (level + 4 x its noise, measured on "
                  "the samples near 0 N) off before rendering, so that plate noise starts no "
                  "contact in the air (default on; a clean file is left as it is)");
    cmd->add_option("--seconds", args->seconds, "length of the walk (virtual walker)")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 86400.0));
    cmd->add_option("--tail", args->tail, "seconds rendered after the GRF ends")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 60.0));
    cmd->add_option("--seed", args->seed, "seed of every random process (same seed, same samples)")
        ->capture_default_str();
    cmd->add_option("--rate", args->rate, "sample rate, Hz")
        ->capture_default_str()
        ->check(CLI::Range(8000.0, 384000.0));
    cmd->add_option("--block", args->block, "block size, samples")
        ->capture_default_str()
        ->check(CLI::Range(1, 8192));
    cmd->add_option("--oversampling", args->oversampling, "contact oversampling: 1, 2, 4 or 8")
        ->capture_default_str()
        ->check(CLI::IsMember({1, 2, 4, 8}));
    cmd->add_option("--newton", args->newton, "impact solver iteration cap")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    cmd->add_flag("--explicit", args->explicitImpact, "explicit impact force (fast, inaccurate)");
    cmd->add_flag("--dry", args->dry, "no reverb even when the preset has one");
    cmd->add_option("--format", args->format, "pcm16, pcm24 or float")->capture_default_str();
    cmd->add_option("-o,--output", args->output, "output .wav (or folder)");
    cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
    cmd->callback([args, &exitCode] { exitCode = runRender(*args); });
});

/// One line per key every bundled surface and wading preset reads, tab-separated, for
/// tools/docs/presets_reference.py (docs/reference/presets.md).
void printKeys() {
    std::vector<eng::KeyInfo> keys;
    std::vector<std::pair<std::string, std::size_t>> models; // model, keys up to here
    try {
        for (const auto& s : eng::listSurfaces()) {
            eng::KeyCatalog catalog(keys);
            (void)eng::Surface::load(s.file);
            models.emplace_back("surface", keys.size());
        }
        std::vector<std::string> wading;
        for (const auto& e : std::filesystem::directory_iterator(eng::wadingPresetDirectory()))
            if (e.path().extension() == ".toml") wading.push_back(e.path().string());
        std::sort(wading.begin(), wading.end());
        for (const auto& w : wading) {
            eng::KeyCatalog catalog(keys);
            (void)eng::loadWadingPreset(w);
            models.emplace_back("wading", keys.size());
        }
    } catch (const eng::PresetError& e) {
        throw UserError(e.what());
    }
    auto clean = [](std::string s) {
        for (char& c : s)
            if (c == '\t' || c == '\n') c = ' ';
        return s;
    };
    fmt::print("model\tfile\tkey\ttype\tunit\tmin\tmax\tdefault\trequired\tvalue\tallowed\thelp\n");
    std::size_t i = 0;
    for (const auto& [model, end] : models) {
        for (; i < end; ++i) {
            const auto& k = keys[i];
            const bool ranged = k.type == "number" || k.type == "integer";
            fmt::print("{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\n", model,
                       std::filesystem::path(k.file).stem().string(), k.path, k.type, clean(k.unit),
                       ranged ? fmt::format("{:g}", k.minValue) : "",
                       ranged ? fmt::format("{:g}", k.maxValue) : "", clean(k.defaultText),
                       k.required ? "yes" : "no", clean(k.valueText), clean(k.allowed),
                       clean(k.help));
        }
    }
}

CommandRegistrar regSurfaces("surfaces", [](CLI::App& app, int& exitCode) {
    auto verbose = std::make_shared<bool>(false);
    auto keys = std::make_shared<bool>(false);
    auto* cmd = app.add_subcommand("surfaces", "List the bundled surfaces");
    cmd->add_flag("-v,--verbose", *verbose, "also list each surface's layers and parameters");
    cmd->add_flag("--keys", *keys,
                  "print every preset key the bundled surface and wading presets read, "
                  "tab-separated (for docs/reference/presets.md)");
    cmd->callback([verbose, keys, &exitCode] {
        if (*keys) {
            printKeys();
            exitCode = 0;
            return;
        }
        std::vector<eng::SurfaceInfo> list;
        try {
            list = eng::listSurfaces();
        } catch (const eng::PresetError& e) {
            throw UserError(e.what());
        }
        for (const auto& s : list) {
            fmt::print("{:<22} {:<9} {}{}\n", s.id, eng::toString(s.category), s.description,
                       s.reverb ? fmt::format(" [reverb: {}]", s.reverb->impulseResponse) : "");
            if (*verbose) {
                for (const auto& l : s.layerPurposes) fmt::print("    layer {}\n", l);
                // Keep the surface alive while iterating: a range-for over a member of a
                // temporary reads freed memory.
                const auto surface = eng::Surface::load(s.file);
                for (const auto& p : surface->parameters())
                    fmt::print("      {:<36} {:>12g} {:<14} [{:g}, {:g}]  {}\n", p.path, p.value,
                               p.unit, p.minValue, p.maxValue, p.help);
            }
        }
        exitCode = 0;
    });
});

} // namespace
} // namespace underfoot::cli::render_command
