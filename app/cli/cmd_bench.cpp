// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot bench`: what accuracy costs in time (engine/render/AccuracyCost.h), as Markdown.
#include "app/cli/CommandRegistry.h"
#include "engine/render/AccuracyCost.h"
#include "engine/render/SceneBench.h"
#include "engine/scene/LiveScene.h"
#include "engine/surfaces/Surface.h"
#include "soundscapes/Coherence.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

// Callgrind's client requests (valgrind's headers, header only): no-ops outside valgrind.
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define UNDERFOOT_HAVE_CALLGRIND 1
#else
#define UNDERFOOT_HAVE_CALLGRIND 0
#endif

namespace underfoot::cli::bench_command {
namespace {
namespace eng = underfoot::engine;

struct BenchArgs {
    std::string only = "all";
    double seconds = 5.0;
    int repeats = 5;
    std::vector<std::string> scenes; ///< scene-instructions: these scenes only (empty: all)
    bool listScenes = false;         ///< scene-instructions: print the scenes' ids, run nothing
};

bool isScenario(const std::string& id) {
    for (const auto& s : eng::scenarioIds())
        if (s == id) return true;
    return false;
}

/// A soundscape as the live scene's background (as `underfoot live --soundscape` adapts it).
class SoundscapeAmbience final : public eng::AmbienceSource {
  public:
    explicit SoundscapeAmbience(const std::string& id)
        : renderer_(underfoot::soundscapes::loadSoundscape(id)), id_(id) {}
    void prepare(const eng::ProcessSpec& spec) override { renderer_.prepare(spec); }
    void reset(std::uint64_t seed) noexcept override { renderer_.reset(seed); }
    void process(float* l, float* r, int n) noexcept override { renderer_.process(l, r, n); }
    std::string name() const override { return id_; }

  private:
    underfoot::soundscapes::SoundscapeRenderer renderer_;
    std::string id_;
};

struct SceneRow {
    std::string surface, impulseResponse, soundscape;
    /// As printed in the tables: "creaking_wood + hall + forest".
    std::string name() const {
        std::string n = surface;
        if (!impulseResponse.empty()) n += " + " + impulseResponse;
        if (!soundscape.empty()) n += " + " + soundscape;
        return n;
    }
    /// As given to --scene: "creaking_wood+hall+forest".
    std::string id() const {
        std::string n = name();
        std::erase(n, ' ');
        return n;
    }
};

/// The shipped scenes: every surface with its coherent soundscape (soundscapes/data/
/// coherence.toml), every preset with a reverb, and the live engine's heaviest reference scene
/// (creaking wood + the hall + the forest, as tests/bench/bench_live.cpp).
std::vector<SceneRow> shippedScenes() {
    std::vector<SceneRow> rows;
    const auto& coherence = underfoot::soundscapes::CoherenceTable::builtin();
    for (const auto& info : eng::listSurfaces())
        if (auto sc = coherence.coherentSoundscapeFor(info.id)) rows.push_back({info.id, "", *sc});
    for (const auto& info : eng::listSurfaces())
        if (info.reverb) rows.push_back({info.id, "", ""});
    rows.push_back({"creaking_wood", "hall", "forest"});
    return rows;
}

/// The timed scene benchmark's spec of one shipped scene (`--seconds` s: a walk of twice that).
eng::SceneBenchSpec sceneSpec(const SceneRow& row, const BenchArgs& a,
                              std::unique_ptr<SoundscapeAmbience>& ambience) {
    eng::SceneBenchSpec spec;
    spec.surface = row.surface;
    spec.impulseResponse = row.impulseResponse;
    spec.voices = 2;
    spec.seconds = 2.0 * a.seconds;
    spec.repeats = a.repeats;
    if (!row.soundscape.empty()) {
        ambience = std::make_unique<SoundscapeAmbience>(row.soundscape);
        spec.ambience = ambience.get();
    }
    return spec;
}

/// `--only scene-instructions`: the instructions of every 64-frame block of the
/// shipped scenes, counted by callgrind, so that worst / median does not depend on the machine's
/// load. Each scene runs once on the timed benchmark's input and seed (scene and background
/// reset as before its first repeat); after each block callgrind's counts are dumped (and so
/// zeroed) with the label "<scene id> <block>": a dump's total is that block's instructions.
/// tools/perf/scene_block_instructions.py runs this under callgrind and reads the dumps. Outside
/// valgrind the client requests do nothing: refused (exit code 2).
int runSceneInstructions(const BenchArgs& a) {
    const auto all = shippedScenes();
    if (a.listScenes) {
        for (const auto& row : all) fmt::print("{}\n", row.id());
        return 0;
    }
    std::vector<SceneRow> rows;
    for (const auto& id : a.scenes) {
        const auto it =
            std::find_if(all.begin(), all.end(), [&](const SceneRow& r) { return r.id() == id; });
        if (it == all.end()) {
            std::string ids;
            for (const auto& row : all) ids += (ids.empty() ? "" : ", ") + row.id();
            throw UserError(fmt::format("bench: no shipped scene '{}' (scenes: {})", id, ids));
        }
        rows.push_back(*it);
    }
    if (rows.empty()) rows = all;
#if UNDERFOOT_HAVE_CALLGRIND
    const bool underValgrind = RUNNING_ON_VALGRIND != 0;
#else
    const bool underValgrind = false;
#endif
    if (!underValgrind)
        throw UserError(
            "bench --only scene-instructions counts each block's instructions through "
            "callgrind's client requests, which do nothing outside valgrind" +
            std::string(UNDERFOOT_HAVE_CALLGRIND ? ""
                                                 : " (and this build has no valgrind headers)") +
            ": run python3 tools/perf/scene_block_instructions.py (or this command under valgrind "
            "--tool=callgrind --combine-dumps=yes --instr-atstart=no)");
#if UNDERFOOT_HAVE_CALLGRIND
    for (const auto& row : rows) {
        std::unique_ptr<SoundscapeAmbience> ambience;
        const auto spec = sceneSpec(row, a, ambience);
        eng::SceneBlocks scene(spec);
        std::vector<std::string> labels(scene.blocks());
        for (std::size_t b = 0; b < labels.size(); ++b)
            labels[b] = fmt::format("{} {}", row.id(), b);
        scene.reset();
        // Dumping zeroes the counts, so each dump holds one block and the loop's few
        // instructions (the same for every block). Zeroing before every block as well made the
        // run 1.7x slower (callgrind walks every cost centre to zero it).
        CALLGRIND_START_INSTRUMENTATION; // the setup above runs uninstrumented (faster)
        CALLGRIND_ZERO_STATS;
        for (std::size_t b = 0; b < labels.size(); ++b) {
            scene.process(b);
            CALLGRIND_DUMP_STATS_AT(labels[b].c_str());
        }
        CALLGRIND_STOP_INSTRUMENTATION;
        // One line per scene for the script: id, blocks, the IR's taps (0: no room), checksum.
        fmt::print("scene {} blocks {} block_frames {} rate {} reverb_taps {} checksum {:.9g} "
                   "name {}\n",
                   row.id(), scene.blocks(), eng::kBenchBlock, eng::kBenchRateHz,
                   scene.hasReverb() ? scene.reverbLength() : 0, scene.checksum(), row.name());
        std::fflush(stdout);
    }
#endif
    return 0;
}

void printSceneHeader(const char* what) {
    fmt::print(
        "| {} | reverb taps | x real time | ns/sample | ns/sample, mean of per-block minima | "
        "median block | p99 block | worst block | worst / median | worst / 1333 us "
        "budget |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        what);
}

void printSceneRow(const std::string& name, const eng::SceneBenchResult& r) {
    const auto& s = r.stats;
    fmt::print(
        "| {} | {} | {:.0f} | {:.1f} | {:.1f} | {:.2f} us | {:.2f} us | {:.2f} us | {:.2f} | "
        "{:.2f} % |\n",
        name, r.hasReverb ? std::to_string(r.irLength) : std::string("-"), s.realTimeFactor,
        s.nsPerSample, s.minimaNsPerSample, s.medianUs, s.p99Us, s.worstUs, s.worstOverMedian(),
        100.0 * s.budgetShare());
}

int runBench(const BenchArgs& a) {
    if (a.only == "scene-instructions") return runSceneInstructions(a);
    if (isScenario(a.only) && a.repeats == 1) {
        // One plain run, for instruction counting under callgrind (`--repeats 1`).
        const auto m = eng::measureScenario(a.only, a.seconds, 1);
        fmt::print("{}: {:.1f} ns/sample over {:.1f} s (checksum {:.6g})\n", m.id, m.nsPerSample,
                   a.seconds, m.checksum);
        return 0;
    }
    if (a.only == "all" || a.only == "scenarios" || isScenario(a.only)) {
        fmt::print("### Model scenarios, 48 kHz, 64-frame blocks, per-block minimum "
                   "of {} runs\n\n",
                   a.repeats);
        fmt::print("| scenario | ns/sample | median block | p99 block | worst block | worst block "
                   "/ 1333 us budget |\n|---|---:|---:|---:|---:|---:|\n");
        for (const auto& id : eng::scenarioIds()) {
            if (a.only != "all" && a.only != "scenarios" && a.only != id) continue;
            const auto m = eng::measureScenario(id, a.seconds, a.repeats);
            fmt::print("| {} | {:.1f} | {:.2f} us | {:.2f} us | {:.2f} us | {:.2f} % |\n", id,
                       m.nsPerSample, m.medianBlockNs / 1e3, m.p99BlockNs / 1e3, m.maxBlockNs / 1e3,
                       100.0 * m.budgetShare);
        }
        fmt::print("\n");
    }
    if (a.only == "scaling") {
        fmt::print("### Scaling: ns per output sample, 48 kHz, 64-frame blocks, "
                   "per-block minimum of {} runs of {:.1f} s\n\n",
                   a.repeats, a.seconds);
        fmt::print("| axis | value | ns/sample | per unit |\n|---|---:|---:|---:|\n");
        for (const auto& p : eng::measureScaling(a.seconds, a.repeats))
            fmt::print("| {} | {} | {:.1f} | {:.2f} |\n", p.axis, p.value, p.nsPerSample,
                       p.perUnit);
        fmt::print("\n");
        return 0;
    }
    if (a.only == "impact-default") {
        // For instruction counting under callgrind: the default impact alone.
        eng::ImpactSetting def;
        for (const auto& s : eng::defaultImpactSettings())
            if (s.name.ends_with("(default)")) def = s;
        const auto m = eng::measureImpact(def, a.seconds);
        fmt::print("{:.1f} ns/sample over {:.1f} s of strikes\n", m.nsPerSample, a.seconds);
        return 0;
    }
    if (a.only == "all" || a.only == "impact") {
        fmt::print(
            "### Impact (3 modes, 48 kHz): error against 8x oversampled double Newton, cost\n\n");
        fmt::print(
            "| setting | contact time | contact time error | restitution | restitution error | "
            "spectral distance | ns/sample | median 64-sample block | worst block / median |\n");
        fmt::print("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (const auto& s : eng::defaultImpactSettings()) {
            const auto m = eng::measureImpact(s, a.seconds);
            fmt::print("| {} | {:.3f} ms | {:.2f} % | {:.4f} | {:.4f} | {:.2f} dB | {:.1f} | "
                       "{:.2f} us | {:.2f}x |\n",
                       s.name, m.contactTimeMs, m.contactTimeErrorPct, m.restitution,
                       m.restitutionError, m.spectralDistanceDb, m.nsPerSample,
                       m.medianBlockNs / 1e3, m.maxBlockNs / m.medianBlockNs);
        }
        fmt::print("\n");
    }
    if (a.only == "all" || a.only == "knobs") {
        fmt::print("### Modes, event cap and the friction solve's Newton stop: spectral distance "
                   "to the most accurate setting (the friction: to its 50-pass reference), cost "
                   "(one voice)\n\n");
        fmt::print("| knob | setting | spectral distance | ns/sample |\n|---|---:|---:|---:|\n");
        for (const auto& k : eng::measureKnobs(a.seconds))
            fmt::print("| {} | {} | {:.2f} dB | {:.1f} |\n", k.knob, k.setting,
                       k.spectralDistanceDb, k.nsPerSample);
        fmt::print("\n");
    }
    if (a.only == "all" || a.only == "scenes") {
        fmt::print("### Shipped scenes: one walker (two voices, one per foot), the reverb, the "
                   "soundscape (unity gain, as the live headphone mix), 48 kHz, 64-frame blocks, "
                   "{} runs of {:.0f} s\n\n",
                   a.repeats, 2.0 * a.seconds);
        fmt::print("| scene | reverb taps | x real time | x real time per voice | ns/sample | "
                   "median block | p99 block | worst block | worst / median | worst / 1333 us "
                   "budget |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (const auto& row : shippedScenes()) {
            std::unique_ptr<SoundscapeAmbience> ambience;
            const auto spec = sceneSpec(row, a, ambience);
            const auto r = eng::measureScene(spec);
            const std::string name = row.name();
            const auto& st = r.stats;
            fmt::print("| {} | {} | {:.0f} | {:.0f} | {:.1f} | {:.2f} us | {:.2f} us | {:.2f} us | "
                       "{:.2f} | {:.2f} % |\n",
                       name, r.hasReverb ? std::to_string(r.irLength) : std::string("-"),
                       st.realTimeFactor, st.realTimeFactor * spec.voices, st.nsPerSample,
                       st.medianUs, st.p99Us, st.worstUs, st.worstOverMedian(),
                       100.0 * st.budgetShare());
        }
        fmt::print("\n");
    }
    if (a.only == "all" || a.only == "surfaces") {
        // engine/render/SceneBench: the same timing as tests/bench/bench_reverb (one harness).
        fmt::print("### One voice of every surface, virtual walker at 100 steps/min, 48 kHz, "
                   "64-frame blocks, {} runs\n\n",
                   a.repeats);
        fmt::print("x real time and ns/sample: the fastest run's thread CPU time; blocks: "
                   "per-block minimum over the runs (steady clock).\n\n");
        printSceneHeader("surface");
        for (const auto& info : eng::listSurfaces()) {
            eng::SceneBenchSpec spec;
            spec.surface = info.id;
            spec.seconds = 2.0 * a.seconds;
            spec.repeats = a.repeats;
            printSceneRow(info.id, eng::measureScene(spec));
        }
        fmt::print("\n");
    }
    return 0;
}

CommandRegistrar reg("bench", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<BenchArgs>();
    auto* cmd = app.add_subcommand(
        "bench", "Measure what accuracy costs: error against a reference and CPU time per setting");
    std::vector<std::string> choices = {"all",       "impact",  "knobs",
                                        "surfaces",  "scenes",  "impact-default",
                                        "scenarios", "scaling", "scene-instructions"};
    for (const auto& id : eng::scenarioIds()) choices.push_back(id);
    cmd->add_option(
           "--only", args->only,
           "all, impact, knobs, surfaces, scenes, scenarios, scaling (not in all), "
           "impact-default (for callgrind), scene-instructions (instructions per block "
           "of the shipped scenes; under callgrind: tools/perf/scene_block_instructions.py), "
           "or one scenario: impact-strikes, "
           "impact-pressed, impact-metal, friction-creak, aggregate-gravel, bubbles, "
           "aggregate-gravel-1voice")
        ->check(CLI::IsMember(choices))
        ->capture_default_str();
    cmd->add_option("--repeats", args->repeats,
                    "runs per scenario (per-block minimum); 1 = one plain run of --only's "
                    "scenario, for callgrind")
        ->check(CLI::Range(1, 50))
        ->capture_default_str();
    cmd->add_option("--seconds", args->seconds, "audio seconds per measurement")
        ->check(CLI::Range(0.5, 600.0))
        ->capture_default_str();
    cmd->add_option("--scene", args->scenes,
                    "with --only scene-instructions: this shipped scene only (repeatable; ids as "
                    "--list-scenes prints them)");
    cmd->add_flag("--list-scenes", args->listScenes,
                  "with --only scene-instructions: print the shipped scenes' ids and stop");
    cmd->callback([args, &exitCode] { exitCode = runBench(*args); });
});

} // namespace
} // namespace underfoot::cli::bench_command
