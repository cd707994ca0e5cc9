// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot fit`: fit a surface preset to recorded footsteps (analysis by synthesis, NLopt).
//   fit --surface gravel [--real FILES_OR_DIRS...] -o gravel_fitted.toml [--evaluations 80]
//   fit --surface wood --modes 8     modal estimate (matrix pencil) of every recorded strike
//   fit --surface wood -o wood.toml --no-modal-seed   refine the preset's own modes only
//   fit --surface beach_sand -o s.toml --contrast 2 --margin 0.1   (the defaults) also push the
//       render away from the nearest other material of the recordings cache (realism/Fit.h)
//   fit --surface beach_sand -o s.toml --seeds 3,7,8,11   the objective averaged over one render
//       per seed (a margin that must hold for every realisation of a random surface)
//   fit --surface beach_sand -o s.toml --starts 8   global search: BOBYQA from the preset and
//       from 7 Sobol points of the knobs' box, the best kept (realism/Fit.h)
// Solids (impact layers) are first seeded with the recordings' modes (realism/ModalSeed.h).
// Without --real the recordings of the surface's material come from the cache of
// scripts/fetch-recordings.sh. The output is a normal preset with a [provenance] table.
#include "app/cli/CommandRegistry.h"
#include "base/Plural.h"
#include "engine/surfaces/Surface.h"
#include "realism/Fit.h"
#include "realism/Modal.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

namespace underfoot::cli::fit_command {
namespace {
namespace eng = underfoot::engine;
namespace rl = underfoot::realism;
namespace fs = std::filesystem;

struct FitArgs {
    std::string surface, output, recordings;
    std::vector<std::string> real;
    int evaluations = 80;
    rl::FitOptions options;
    bool quiet = false;
    int modes = 0; ///< --modes K: print K modes of every recording and stop
    bool noModalSeed = false;
};

// The cache's recordings without the unseen sources' (rl::unseenSources: presets are never
// fitted on them), saying so when `say` and it held some.
std::vector<rl::Recording> cacheRecordings(const std::string& dir, bool say) {
    const auto all = rl::loadManifest(dir);
    auto kept = rl::withoutUnseenSources(all);
    if (say && kept.size() < all.size()) {
        std::string names;
        for (const auto& s : rl::unseenSources())
            if (std::any_of(all.begin(), all.end(),
                            [&](const rl::Recording& r) { return r.source == s; }))
                names += (names.empty() ? "" : ", ") + s;
        fmt::print("note: the unseen sources ({}: {} of {}) are left out: no preset is fitted "
                   "on them (--real names files to fit to)\n",
                   names, counted(all.size() - kept.size(), "file"), dir);
    }
    return kept;
}

// Recordings of every other material in the cache, for the contrastive objective; empty (with
// a note) when there is no cache or it holds no other material.
std::vector<rl::Recording> otherMaterials(const FitArgs& a, const std::string& own) {
    const auto dir = a.recordings.empty() ? rl::defaultRecordingsDir() : a.recordings;
    std::vector<rl::Recording> out;
    try {
        for (auto& r : cacheRecordings(dir, !a.real.empty())) // else runFit said it
            if (!r.material.empty() && r.material != own) out.push_back(r);
    } catch (const std::runtime_error& e) {
        if (!a.recordings.empty()) throw UserError(e.what()); // named explicitly: must load
        fmt::print("note: no recordings cache ({}): fitting without contrast\n", e.what());
        return {};
    }
    if (out.empty())
        fmt::print("note: {} holds no other material: fitting without contrast\n", dir);
    return out;
}

// The matrix pencil modes of every recording (strongest step, from its peak): the starting
// point for a solid's modal parameters (frequencies, T60s, relative gains).
int printModes(const std::vector<rl::Recording>& real, int k) {
    rl::ModalOptions o;
    o.modes = k;
    for (const auto& r : real) {
        std::vector<rl::Mode> modes;
        try {
            modes = rl::modesOfRecording(r.path, o);
        } catch (const std::invalid_argument& e) {
            fmt::print("{}: {}\n", r.file, e.what());
            continue;
        }
        fmt::print("{} ({} modes, strongest first):\n", r.file, modes.size());
        const double top = modes.empty() ? 1.0 : modes.front().amplitude;
        for (const auto& m : modes)
            fmt::print("  {:8.1f} Hz  T60 {:6.3f} s  gain {:6.1f} dB\n", m.frequencyHz, m.t60S,
                       20 * std::log10(m.amplitude / top));
    }
    return 0;
}

std::string presetFile(const std::string& s) {
    if (s.size() > 5 && s.substr(s.size() - 5) == ".toml") return s;
    return (fs::path(eng::surfacesDirectory()) / (s + ".toml")).string();
}

int runFit(FitArgs& a) {
    if (a.surface.empty()) throw UserError("fit: --surface is required");
    if (a.output.empty() && a.modes == 0) throw UserError("fit: -o FILE.toml is required");
    const auto file = presetFile(a.surface);
    if (!fs::exists(file))
        throw UserError(fmt::format("fit: no preset {} (see `underfoot surfaces`)", file));
    std::vector<rl::Recording> real;
    try {
        if (!a.real.empty()) {
            real = rl::collectRecordings(a.real);
        } else {
            const auto m = rl::materialOfSurface(a.surface);
            if (m.empty())
                throw UserError(fmt::format(
                    "fit: no recorded material is known for \"{}\"; name recordings with --real",
                    a.surface));
            for (auto& r : cacheRecordings(
                     a.recordings.empty() ? rl::defaultRecordingsDir() : a.recordings, true))
                if (r.material == m) real.push_back(r);
            if (real.empty())
                throw UserError(fmt::format("fit: the recordings cache has no {} recordings", m));
        }
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    if (a.modes > 0) {
        try {
            return printModes(real, a.modes);
        } catch (const eng::FileError& e) {
            throw UserError(e.what());
        }
    }
    if (!(std::isfinite(a.options.contrast) && a.options.contrast >= 0))
        throw UserError(fmt::format("fit: --contrast {}: expected a number >= 0 (0 = plain fit)",
                                    a.options.contrast));
    if (!(std::isfinite(a.options.margin) && a.options.margin >= 0 && a.options.margin <= 5))
        throw UserError(
            fmt::format("fit: --margin {}: expected a distance from 0 to 5", a.options.margin));
    if (a.options.contrast > 0) {
        a.options.ownMaterial = rl::materialOfSurface(a.surface);
        try {
            a.options.others = otherMaterials(a, a.options.ownMaterial);
        } catch (const std::runtime_error& e) {
            throw UserError(e.what());
        }
    }
    a.options.maxEvaluations = a.evaluations;
    a.options.modalSeed = !a.noModalSeed;
    if (!a.quiet)
        a.options.progress = [](int n, int budget, double d, double best) {
            if (n % 10 == 0)
                fmt::print("  evaluation {} of at most {}: distance {:.3f} (best {:.3f})\n", n,
                           budget, d, best);
            return true;
        };
    rl::FitResult r;
    try {
        r = rl::fitSurface(file, real, a.options);
    } catch (const eng::PresetError& e) {
        throw UserError(e.what());
    } catch (const eng::FileError& e) {
        throw UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("fit: ") + e.what());
    }
    std::ofstream out(a.output);
    if (!out) throw UserError(fmt::format("-o {}: cannot write this file", a.output));
    out << "# Fitted by `underfoot fit` to " << counted(real.size(), "recording")
        << "; see [provenance] at the end and docs/explanation/realism.md.\n"
        << r.presetText;
    out.close();
    // The result must load as a normal preset.
    try {
        eng::Surface::load(a.output);
    } catch (const eng::PresetError& e) {
        throw UserError(
            fmt::format("fit: the fitted preset does not load (engine bug): {}", e.what()));
    }
    if (r.modalSeeded) {
        fmt::print("modal seed from {} ({} modes; distance {:.3f} -> {:.3f} seeded):\n",
                   r.seedStart, r.seededModes.size(), r.distanceBefore, r.distanceSeeded);
        for (const auto& m : r.seededModes)
            fmt::print("  {:8.1f} Hz  T60 {:6.3f} s  gain {:6.1f} dB  support {:4.0f} %  ({} "
                       "estimates)\n",
                       m.frequencyHz, m.t60S, 20 * std::log10(m.gain), 100 * m.support,
                       m.observations);
        for (const auto& f : r.seedSkipped) fmt::print("  (no mode from {})\n", f);
    } else if (r.seedTried) {
        fmt::print("modal seed tried: the preset's own modes refined better and were kept\n");
    }
    fmt::print("{}: distance {:.3f} -> {:.3f} after {} evaluations ({}) in {:.1f} s -> {}\n",
               a.surface, r.distanceBefore, r.distanceAfter, r.evaluations, r.optimiser, r.seconds,
               a.output);
    if (a.options.seeds.size() > 1)
        fmt::print("render seeds: {} (distances are means over one render per seed)\n",
                   fmt::join(a.options.seeds, ","));
    if (r.startPoints > 1) {
        fmt::print("starts: {} (best from {}):", r.startPoints,
                   r.bestStartPoint == 0 ? std::string("the preset")
                                         : fmt::format("Sobol point {}", r.bestStartPoint));
        for (double o : r.startObjectives) fmt::print(" {:.3f}", o);
        fmt::print("\n");
    }
    if (r.contrastive)
        fmt::print("nearest other material: {} {:.3f} -> {} {:.3f} (contrast {}, margin {}: {})\n",
                   r.before.nearestMaterial, r.before.nearest, r.after.nearestMaterial,
                   r.after.nearest, a.options.contrast, a.options.margin,
                   r.after.own < r.after.nearest ? "closer to its own recordings"
                                                 : "NOT closer to its own recordings");
    for (const auto& k : r.knobs)
        fmt::print("  {:<14} {:>7.3f}   ({})\n", k.name, k.value, k.meaning);
    return 0;
}

CommandRegistrar reg("fit", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<FitArgs>();
    auto* cmd = app.add_subcommand("fit", "Fit a surface preset to recorded footsteps (analysis by "
                                          "synthesis; docs/explanation/realism.md)");
    cmd->add_option("-s,--surface", args->surface, "surface id or preset .toml");
    cmd->add_option("--real", args->real,
                    "recorded footsteps: files or folders (default: the recordings cache, "
                    "material of the surface, without the unseen sources of "
                    "fetch-recordings.sh --unseen)");
    cmd->add_option("--recordings", args->recordings,
                    "recordings cache (default build/recordings)");
    cmd->add_option("--evaluations", args->evaluations, "renders the optimiser may try")
        ->capture_default_str()
        ->check(CLI::Range(5, 2000));
    cmd->add_option("--walker", args->options.spec.walker, "virtual walker of the renders")
        ->capture_default_str();
    cmd->add_option("--seconds", args->options.spec.seconds, "length of each render")
        ->capture_default_str()
        ->check(CLI::Range(2.0, 60.0));
    auto* seedOption = cmd->add_option("--seed", args->options.spec.seed, "seed of the renders")
                           ->capture_default_str();
    cmd->add_option("--seeds", args->options.seeds,
                    "several render seeds, e.g. 3,7,8,11: the objective is the mean over one "
                    "render per seed, so a thin margin must hold for every one (realism/Fit.h)")
        ->delimiter(',')
        ->excludes(seedOption);
    args->options.contrast = 2.0; // the CLI's defaults (the library's are 0: plain fit)
    args->options.margin = 0.1;
    cmd->add_option("--contrast", args->options.contrast,
                    "weight LAMBDA of the penalty max(0, d_own - d_nearest_other + margin) "
                    "against the other materials of the recordings cache; 0 = minimise the "
                    "distance to the own recordings only")
        ->capture_default_str();
    cmd->add_option("--margin", args->options.margin,
                    "how much closer (in distance units) the render must be to its own "
                    "recordings than to any other material's before the penalty stops")
        ->capture_default_str();
    cmd->add_option("--keep", args->options.keep,
                    "knobs to hold at the preset's values (e.g. grain_band: a designed property "
                    "the fit must not move)");
    cmd->add_option("--starts", args->options.starts,
                    "starting points of the optimiser: the preset and N - 1 Sobol points of the "
                    "knobs' box, each refined with up to --evaluations renders; the best is kept")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("-o,--output", args->output, "fitted preset (.toml)");
    cmd->add_flag("-q,--quiet", args->quiet, "no progress lines");
    cmd->add_option("--modes", args->modes,
                    "print the K strongest modes (matrix pencil: Hz, T60, gain) of every "
                    "recording's strongest step instead of fitting")
        ->check(CLI::Range(1, 64));
    cmd->add_flag("--no-modal-seed", args->noModalSeed,
                  "solids: start from the preset's own modes instead of the recordings' modes "
                  "(matrix pencil, clustered across files and sources)");
    cmd->callback([args, &exitCode] { exitCode = runFit(*args); });
});

} // namespace
} // namespace underfoot::cli::fit_command
