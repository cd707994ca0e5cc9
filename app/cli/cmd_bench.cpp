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

#include <memory>
#include <string>
#include <vector>

namespace underfoot::cli::bench_command {
namespace {
namespace eng = underfoot::engine;

struct BenchArgs {
    std::string only = "all";
    double seconds = 5.0;
    int repeats = 5;
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
    if (isScenario(a.only) && a.repeats == 1) {
        // One plain run, for instruction counting under callgrind (`--repeats 1`).
        const auto m = eng::measureScenario(a.only, a.seconds, 1);
        fmt::print("{}: {:.1f} ns/sample over {:.1f} s (checksum {:.6g})\n", m.id, m.nsPerSample,
                   a.seconds, m.checksum);
        return 0;
    }
    if (a.only == "all" || a.only == "scenarios" || isScenario(a.only)) {
        fmt::print("### Model scenarios (issue #18), 48 kHz, 64-frame blocks, per-block minimum "
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
        fmt::print("### Scaling (issue #18): ns per output sample, 48 kHz, 64-frame blocks, "
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
        fmt::print("### Modes and event cap: spectral distance to the most accurate setting, cost "
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
            eng::SceneBenchSpec spec;
            spec.surface = row.surface;
            spec.impulseResponse = row.impulseResponse;
            spec.voices = 2;
            spec.seconds = 2.0 * a.seconds;
            spec.repeats = a.repeats;
            std::unique_ptr<SoundscapeAmbience> ambience;
            if (!row.soundscape.empty()) {
                ambience = std::make_unique<SoundscapeAmbience>(row.soundscape);
                spec.ambience = ambience.get();
            }
            const auto r = eng::measureScene(spec);
            std::string name = row.surface;
            if (!row.impulseResponse.empty()) name += " + " + row.impulseResponse;
            if (!row.soundscape.empty()) name += " + " + row.soundscape;
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
    std::vector<std::string> choices = {"all",    "impact",         "knobs",     "surfaces",
                                        "scenes", "impact-default", "scenarios", "scaling"};
    for (const auto& id : eng::scenarioIds()) choices.push_back(id);
    cmd->add_option("--only", args->only,
                    "all, impact, knobs, surfaces, scenes, scenarios, scaling (not in all), "
                    "impact-default (for callgrind), or one scenario: impact-strikes, "
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
    cmd->callback([args, &exitCode] { exitCode = runBench(*args); });
});

} // namespace
} // namespace underfoot::cli::bench_command
