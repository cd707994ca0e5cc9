// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot bench`: what accuracy costs in time (engine/render/AccuracyCost.h), as Markdown.
#include "app/cli/CommandRegistry.h"
#include "engine/render/AccuracyCost.h"

#include <fmt/core.h>

#include <memory>

namespace underfoot::cli {
namespace {
namespace eng = underfoot::engine;

struct BenchArgs {
    std::string only = "all";
    double seconds = 5.0;
};

int runBench(const BenchArgs& a) {
    if (a.only == "impact-default") {
        // For instruction counting under callgrind: the default impact alone.
        const auto m = eng::measureImpact(eng::defaultImpactSettings()[5], a.seconds);
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
    if (a.only == "all" || a.only == "surfaces") {
        fmt::print("### One voice of every surface, virtual walker at 100 steps/min, 48 kHz\n\n");
        fmt::print("| surface | x real time | ns/sample |\n|---|---:|---:|\n");
        for (const auto& c : eng::measureSurfaceCosts(2.0 * a.seconds))
            fmt::print("| {} | {:.0f} | {:.1f} |\n", c.id, c.realTimeFactor, c.nsPerSample);
    }
    return 0;
}

CommandRegistrar reg("bench", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<BenchArgs>();
    auto* cmd = app.add_subcommand(
        "bench", "Measure what accuracy costs: error against a reference and CPU time per setting");
    cmd->add_option("--only", args->only,
                    "all, impact, knobs, surfaces, or impact-default (for callgrind)")
        ->check(CLI::IsMember({"all", "impact", "knobs", "surfaces", "impact-default"}))
        ->capture_default_str();
    cmd->add_option("--seconds", args->seconds, "audio seconds per measurement")
        ->check(CLI::Range(0.5, 600.0))
        ->capture_default_str();
    cmd->callback([args, &exitCode] { exitCode = runBench(*args); });
});

} // namespace
} // namespace underfoot::cli
