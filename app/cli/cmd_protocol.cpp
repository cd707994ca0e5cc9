// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot protocol check FILE`: validates a protocol and prints its plan summary.
// `underfoot protocol power` lives in cmd_protocol_power.cpp.
#include "analysis/model/Catalog.h"
#include "app/cli/CommandRegistry.h"
#include "app/wiring/StimulusRender.h"
#include "base/Plural.h"
#include "experiment/Catalogue.h"
#include "experiment/Plan.h"
#include "experiment/Protocol.h"
#include "experiment/Random.h"
#include "experiment/RatingModel.h"
#include "experiment/Simulation.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <thread>

namespace underfoot::cli::protocol_command {
namespace {

/// "1 repetition", "2 repetitions": `n` with the singular or the plural noun.
std::string count(std::size_t n, std::string_view singular, std::string_view plural) {
    return fmt::format("{} {}", n, n == 1 ? singular : plural);
}

using namespace underfoot::experiment;

std::string minutes(double seconds) {
    return fmt::format("{:.0f} min {:02.0f} s", std::floor(seconds / 60.0),
                       std::fmod(seconds, 60.0));
}

void printSummary(const Protocol& p, std::uint64_t seed, int participants) {
    fmt::print("{} — {} (version {})\n", p.id, p.title, p.version);
    if (!p.reference.empty()) fmt::print("reference: {}\n", p.reference);
    fmt::print("sha256: {}\n", p.hash);
    fmt::print("design: {}-subject, {}, {}, order {}{}{}\n", toString(p.design),
               count(p.stimuli.size(), "stimulus", "stimuli"),
               count(static_cast<std::size_t>(p.ordering.repetitions), "repetition", "repetitions"),
               p.ordering.order == OrderKind::Random ? "random per participant" : "fixed",
               p.ordering.blocks == BlockKind::Repetition ? ", one block per repetition"
               : p.ordering.blocks == BlockKind::Scale    ? ", one block per scale"
                                                          : "",
               p.ordering.noImmediateRepeat ? ", no immediate repeat" : "");
    if (p.ordering.counterbalance == Counterbalance::LatinSquare)
        fmt::print("counterbalanced: Williams Latin square, {} orders (groups order1..order{})\n",
                   p.groups.size(), p.groups.size());
    if (p.laps.total() > 0)
        fmt::print("laps per condition: {} silent baseline, then {} with sound\n", p.laps.baseline,
                   p.laps.feedback);
    if (p.clips.enabled) {
        int lab = 0;
        for (const auto& s : p.stimuli) lab += s.clip ? 1 : 0;
        fmt::print("listening test: {} rendered by `underfoot clips` ({:g} s, seed {}), {} "
                   "supplied by the lab; replay {}\n",
                   count(p.stimuli.size() - static_cast<std::size_t>(lab), "clip", "clips"),
                   p.clips.seconds, p.clips.seed, lab,
                   p.clips.replay ? "allowed (counted)" : "not allowed");
    }
    for (const auto& f : p.participantFields)
        fmt::print("participant field: {} ({}){}\n", f.id, f.label,
                   f.options.empty() ? std::string(" free text")
                                     : fmt::format(": {}", fmt::join(f.options, ", ")));
    fmt::print("questions: {}{}{}{}\n",
               p.questions.asksSurface()
                   ? fmt::format("surface ({} options)", p.questions.surfaceOptions.size())
                   : "no surface question",
               p.questions.scales.empty()
                   ? ""
                   : ", " + count(p.questions.scales.size(), "scale", "scales"),
               p.questions.soundscapeOptions.empty() ? "" : ", soundscape",
               p.questions.comment ? ", comment" : "");
    const PlanSummary summary = summarizePlans(p, seed, participants);
    fmt::print("\nPer participant\n");
    fmt::print("  {:<14} {:>8} {:>6} {:>6} {:>7}  {}\n", "group", "practice", "trials", "breaks",
               "target", "estimated duration");
    for (std::size_t i = 0; i < summary.groups.size(); ++i) {
        const auto& g = summary.groups[i];
        fmt::print("  {:<14} {:>8} {:>6} {:>6} {:>7}  {}\n", g.groupId, g.practiceTrials,
                   g.mainTrials, g.breaks,
                   p.groups[i].target > 0 ? std::to_string(p.groups[i].target) : "-",
                   minutes(g.estimatedDurationS));
    }
    fmt::print("\nBalance over {} simulated participant{} per group (seed {}); positions count "
               "from 1\n",
               participants, participants == 1 ? "" : "s", seed);
    for (const auto& table : summary.balance) {
        fmt::print("  group {}\n", table.groupId);
        fmt::print("    {:<20} {:>13} {:>11} {:>13} {:>7}\n", "stimulus", "presentations",
                   "times first", "mean position", "(ideal)");
        const std::size_t positions = table.counts.empty() ? 0 : table.counts[0].size();
        const double ideal = positions > 0 ? (static_cast<double>(positions) + 1.0) / 2.0 : 0.0;
        for (std::size_t s = 0; s < table.stimulusIds.size(); ++s) {
            int total = 0;
            double weighted = 0;
            for (std::size_t pos = 0; pos < positions; ++pos) {
                total += table.counts[s][pos];
                weighted += static_cast<double>(table.counts[s][pos] * (static_cast<int>(pos) + 1));
            }
            fmt::print("    {:<20} {:>13} {:>11} {:>13.2f} {:>7.1f}\n", table.stimulusIds[s], total,
                       positions ? table.counts[s][0] : 0, total ? weighted / total : 0.0, ideal);
        }
    }
}

const underfoot::cli::CommandRegistrar registrar{
    "protocol", [](CLI::App& app, int& exitCode) {
        auto* cmd = app.add_subcommand("protocol", "Protocol files: validate and summarise");
        cmd->require_subcommand(1);
        auto* check = cmd->add_subcommand(
            "check", "Validate a protocol (every problem with file:line:column) and print the "
                     "plan summary: trials per participant, balance table, estimated duration");
        static std::string file;
        static std::uint64_t seed = 1;
        static int participants = 0;
        check->add_option("FILE", file, "protocol TOML file")->required();
        check->add_option("--seed", seed, "study seed for the balance table")->default_val(1);
        check
            ->add_option("--participants", participants,
                         "participants per group for the balance table (default: the group "
                         "target, else 20)")
            ->check(CLI::Range(0, 100000));
        check->callback([&exitCode] {
            Protocol p;
            try {
                p = loadProtocol(file);
            } catch (const ProtocolError& e) {
                fmt::print(stderr, "{}\n", e.what());
                fmt::print(stderr, "underfoot: {} in {}\n", counted(e.problems().size(), "problem"),
                           file);
                exitCode = 2;
                return;
            }
            int n = participants;
            if (n == 0) {
                for (const auto& g : p.groups) n = std::max(n, g.target);
                if (n == 0) n = 20;
            }
            for (const auto& w : p.warnings) fmt::print(stderr, "{}\n", w.toString());
            // Check means runs: every distinct stimulus renders a short piece now, so that a
            // protocol that passes never fails at `clips`, `replay` or in a session.
            int rendered = 0;
            const auto problems = wiring::checkStimuliRender(p, 0.3, &rendered);
            if (!problems.empty()) {
                std::size_t causes = 0;
                for (const auto& line : problems) {
                    const bool more = line.rfind("  ", 0) == 0; // the stimuli a cause also stops
                    causes += more ? 0 : 1;
                    fmt::print(stderr, "{}{}\n", more ? "" : file + ": ", line);
                }
                fmt::print(stderr, "underfoot: {} stimulus problem{} in {}\n", causes,
                           causes == 1 ? "" : "s", file);
                exitCode = 2;
                return;
            }
            printSummary(p, seed, n);
            fmt::print("\nrenders: {} made, every stimulus renders\n",
                       counted(rendered, "distinct stimulus render"));
            exitCode = 0;
        });
    }};

} // namespace
} // namespace underfoot::cli::protocol_command
