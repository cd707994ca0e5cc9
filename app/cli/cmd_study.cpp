// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot study ...`: create a study file, register / drop participants, exclude trials,
// inspect a study, its journal and what replay needs for a trial.
#include "app/cli/CommandRegistry.h"
#include "app/wiring/StimulusRender.h"
#include "base/Plural.h"
#include "base/Version.h"
#include "experiment/Export.h"
#include "experiment/Invitations.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"

#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>

namespace underfoot::cli::study_command {
namespace {

using namespace underfoot::experiment;
using underfoot::cli::UserError;

/// Runs `body`, turning the experiment library's input errors into UserError.
void guarded(const std::function<void()>& body) {
    try {
        body();
    } catch (const ProtocolError& e) {
        throw UserError(e.what());
    } catch (const StoreError& e) {
        throw UserError(e.what());
    }
}

struct Options {
    std::string study;
    std::string protocol;
    std::string code;
    std::string site;
    std::uint64_t seed = 1;
    std::string participant;
    int age = -1;
    std::string gender, shoes, hearing, group, reason;
    int trial = -1;
    bool include = false;
    std::vector<std::string> fields;
    std::string output;
};

Options& opts() {
    static Options o;
    return o;
}

const underfoot::cli::CommandRegistrar registrar{
    "study", [](CLI::App& app, int& exitCode) {
        auto* cmd = app.add_subcommand("study", "Study files: create, register participants, "
                                                "inspect");
        cmd->require_subcommand(1);
        Options& o = opts();

        auto* create = cmd->add_subcommand("create", "Create a study file from a protocol");
        create->add_option("--study", o.study, "new study file (.db)")->required();
        create->add_option("--protocol", o.protocol, "protocol TOML file")->required();
        create->add_option("--code", o.code, "study code")->required();
        create->add_option("--site", o.site, "site (lab) code");
        create->add_option("--seed", o.seed, "study seed (plans and assignment derive from it)")
            ->required();
        create->callback([&exitCode, &o] {
            guarded([&] {
                const Protocol p = loadProtocol(o.protocol);
                // A study is created only from a protocol whose every stimulus renders.
                if (const auto problems = wiring::checkStimuliRender(p); !problems.empty()) {
                    std::string all;
                    for (const auto& line : problems)
                        all += (all.empty() ? "" : "\n") +
                               (line.rfind("  ", 0) == 0 ? line : o.protocol + ": " + line);
                    throw UserError(all + "\nstudy create: nothing was created");
                }
                for (const auto& w : p.warnings) fmt::print(stderr, "{}\n", w.toString());
                StudyStore store = StudyStore::create(
                    o.study, p, {o.code, o.site, o.seed, underfoot::base::version()});
                fmt::print("created {} (study {}, protocol {} sha256 {})\n", o.study, o.code, p.id,
                           p.hash);
            });
            exitCode = 0;
        });

        auto* info = cmd->add_subcommand("info", "Show a study, its groups and participants");
        info->add_option("--study", o.study, "study file")->required();
        info->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::openForReading(o.study);
                const StudyInfo i = store.info();
                fmt::print("study {} (site {}), seed {}, created {}\n", i.code, i.site, i.seed,
                           i.createdAt);
                fmt::print("protocol {} version {} sha256 {}; schema {}\n", i.protocolId,
                           i.protocolVersion, i.protocolHash, i.schemaVersion);
                fmt::print("\n{:<14} {:>7} {:>9} {:>7} {:>6}\n", "group", "active", "completed",
                           "dropped", "target");
                for (const auto& g : store.groupCounts())
                    fmt::print("{:<14} {:>7} {:>9} {:>7} {:>6}\n", g.groupId, g.active, g.completed,
                               g.dropped, g.target);
                fmt::print("\n{:<10} {:>4} {:<12} {:<10} {:>8}  {}\n", "code", "idx", "group",
                           "status", "answered", "assignment");
                int simulated = 0;
                const auto counts = store.progressCounts();
                for (const auto& p : store.participants()) {
                    const auto [answered, planned] = counts.at(p.code);
                    fmt::print("{:<10} {:>4} {:<12} {:<10} {:>4}/{:<3}  {}{}\n", p.code, p.index,
                               p.groupId, toString(p.status), answered, planned,
                               p.assignment == Assignment::Override
                                   ? "override: " + p.overrideReason
                                   : "balanced",
                               p.simulated ? "  SIMULATED" : "");
                    simulated += p.simulated ? 1 : 0;
                }
                if (simulated > 0)
                    fmt::print("\n{} (`session --simulate`): not people; left out of "
                               "`analyze` unless --include-simulated\n",
                               counted(simulated, "simulated participant"));
            });
            exitCode = 0;
        });

        auto* reg = cmd->add_subcommand("register", "Register a participant (pseudonymous code; "
                                                    "no names) and store its plan");
        reg->add_option("--study", o.study, "study file")->required();
        reg->add_option("--participant", o.participant, "pseudonymous code, e.g. P07")->required();
        reg->add_option("--age", o.age, "age in years")->check(CLI::Range(0, 130));
        reg->add_option("--gender", o.gender, "gender (free text)");
        reg->add_option("--shoes", o.shoes, "shoe type");
        reg->add_option("--hearing", o.hearing, "self-reported hearing");
        reg->add_option("--group", o.group, "override the balanced group assignment");
        reg->add_option("--reason", o.reason, "reason for the override (journaled)");
        reg->add_option("--field", o.fields,
                        "NAME=VALUE answer to a [[participant_fields]] item of the protocol "
                        "(e.g. listening_device=laptop_speakers); repeat per field");
        reg->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::open(o.study);
                NewParticipant np{o.participant, std::nullopt, o.gender, o.shoes,
                                  o.hearing,     std::nullopt, o.reason, false};
                if (o.age >= 0) np.age = o.age;
                if (!o.group.empty()) np.groupOverride = o.group;
                std::map<std::string, std::string> fields;
                for (const auto& spec : o.fields) {
                    const auto eq = spec.find('=');
                    if (eq == std::string::npos || eq == 0)
                        throw StoreError(fmt::format("--field {}: expected NAME=VALUE", spec));
                    if (!fields.emplace(spec.substr(0, eq), spec.substr(eq + 1)).second)
                        throw StoreError(fmt::format("--field {}: '{}' is given twice", spec,
                                                     spec.substr(0, eq)));
                }
                const ParticipantInfo p = store.registerParticipant(np, fields);
                fmt::print("registered {} (index {}) in group {} ({}), {} trials planned\n", p.code,
                           p.index, p.groupId,
                           p.assignment == Assignment::Override ? "override" : "balanced",
                           store.trials(p.code).size());
            });
            exitCode = 0;
        });

        auto* drop = cmd->add_subcommand("drop", "Mark a participant as dropped out (frees the "
                                                 "group slot)");
        drop->add_option("--study", o.study, "study file")->required();
        drop->add_option("--participant", o.participant, "participant code")->required();
        drop->add_option("--reason", o.reason, "why (journaled)")->required();
        drop->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::open(o.study);
                store.dropParticipant(o.participant, o.reason);
                fmt::print("{} dropped\n", o.participant);
            });
            exitCode = 0;
        });

        auto* exclude = cmd->add_subcommand("exclude", "Exclude a trial from analysis (or "
                                                       "--include it again)");
        exclude->add_option("--study", o.study, "study file")->required();
        exclude->add_option("--participant", o.participant, "participant code")->required();
        exclude
            ->add_option("--trial", o.trial,
                         "trial number (1-based, as in the session and the export's `trial`)")
            ->required()
            ->check(CLI::PositiveNumber);
        exclude->add_option("--reason", o.reason, "why (journaled, exported)");
        exclude->add_flag("--include", o.include, "include the trial again");
        exclude->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::open(o.study);
                store.setExcluded(o.participant, o.trial - 1, !o.include, o.reason);
                fmt::print("{} trial {} {}\n", o.participant, o.trial,
                           o.include ? "included" : "excluded");
            });
            exitCode = 0;
        });

        auto* trial = cmd->add_subcommand("trial", "Show what replay needs for one trial "
                                                   "(stimulus, render seed, GRF recording)");
        trial->add_option("--study", o.study, "study file")->required();
        trial->add_option("--participant", o.participant, "participant code")->required();
        trial
            ->add_option("--trial", o.trial,
                         "trial number (1-based, as in the session and the export's `trial`)")
            ->required()
            ->check(CLI::PositiveNumber);
        trial->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::openForReading(o.study);
                const ReplayInfo r = store.trialForReplay(o.participant, o.trial - 1);
                fmt::print("study {} protocol sha256 {}\nparticipant {} trial {} (stored index "
                           "{})\nrender seed {}\n"
                           "GRF recording {}\naudio config {}\nsensor config {}\n\n{}",
                           r.study, r.protocolHash, r.participant, r.trialIndex + 1, r.trialIndex,
                           r.renderSeed, r.grfRecording.value_or("(none)"), r.audioConfig,
                           r.sensorConfig, stimulusToToml(r.stimulus));
                fmt::print("\n");
            });
            exitCode = 0;
        });

        auto* table = cmd->add_subcommand(
            "participants", "Write the participants CSV (code, group, status, age, gender, shoes, "
                            "hearing, one column per [[participant_fields]] item) and, with "
                            "--scales, the scales CSV, for `underfoot analyze --ratings`");
        table->add_option("--study", o.study, "study file")->required();
        table->add_option("-o,--output", o.output, "participants CSV (default: standard output)");
        table->add_option("--scales", o.reason, "also write the scales CSV to this file");
        table->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::openForReading(o.study);
                auto write = [&](const std::string& path, auto&& writer) {
                    if (path.empty() || path == "-") {
                        writer(std::cout);
                        return;
                    }
                    // A missing folder of the output file is created.
                    if (const auto folder = std::filesystem::path(path).parent_path();
                        !folder.empty()) {
                        std::error_code ec;
                        std::filesystem::create_directories(folder, ec);
                        if (ec)
                            throw StoreError(fmt::format("{}: cannot create the folder {} ({})",
                                                         path, folder.string(), ec.message()));
                    }
                    std::ofstream out(path, std::ios::binary);
                    if (!out) throw StoreError(fmt::format("{}: cannot write the file", path));
                    writer(out);
                    if (!out.flush()) throw StoreError(fmt::format("{}: write failed", path));
                };
                write(o.output, [&](std::ostream& out) { writeParticipantsCsv(store, out); });
                if (!o.reason.empty())
                    write(o.reason, [&](std::ostream& out) { writeScalesCsv(store, out); });
            });
            exitCode = 0;
        });

        auto* events = cmd->add_subcommand("events", "Print the append-only event journal");
        events->add_option("--study", o.study, "study file")->required();
        events->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::openForReading(o.study);
                for (const auto& e : store.events())
                    fmt::print("{} {:>6} {:<24} {:<8} {:>4} {}\n", e.at, e.id, e.kind,
                               e.participant,
                               e.trialIndex ? std::to_string(*e.trialIndex + 1) : "", // 1-based
                               e.detail);
            });
            exitCode = 0;
        });

        // Online participation: one secret link per future participant.
        struct InviteOptions {
            int count = 0;
            std::string group, prefix = "W", baseUrl = "http://127.0.0.1:8080";
        };
        static InviteOptions io;
        auto* invite = cmd->add_subcommand(
            "invite", "Create secret links for online participants (`underfoot serve`); the CSV "
                      "holds the only copy of each link (the study stores a hash)");
        invite->add_option("--study", o.study, "study file")->required();
        invite->add_option("--count", io.count, "number of links")
            ->required()
            ->check(CLI::Range(1, 10000));
        invite->add_option("--group", io.group, "register them in this group (override)");
        invite->add_option("--prefix", io.prefix, "participant code prefix (codes W001, ...)");
        invite->add_option("--base-url", io.baseUrl,
                           "public address of `underfoot serve` (or its TLS reverse proxy)");
        invite->add_option("-o,--output", o.output, "links CSV")->required();
        invite->callback([&exitCode, &o] {
            guarded([&] {
                StudyStore store = StudyStore::open(o.study);
                if (std::filesystem::exists(o.output))
                    throw StoreError(fmt::format("{}: the file already exists; expected a new "
                                                 "links file (links are shown only once)",
                                                 o.output));
                std::ofstream out(o.output, std::ios::binary);
                if (!out) throw StoreError(fmt::format("{}: cannot write the file", o.output));
                Invitations inv(store);
                const auto links = inv.create(
                    store, io.count, io.group.empty() ? std::nullopt : std::optional(io.group),
                    io.prefix);
                std::string base = io.baseUrl;
                while (!base.empty() && base.back() == '/') base.pop_back();
                out << "participant,link\n";
                for (const auto& l : links)
                    out << l.participantCode << ',' << base << "/p#" << l.token << '\n';
                if (!out.flush()) throw StoreError(fmt::format("{}: write failed", o.output));
                fmt::print("{} links written to {} ({} to {})\n", links.size(), o.output,
                           links.front().participantCode, links.back().participantCode);
            });
            exitCode = 0;
        });
    }};

} // namespace
} // namespace underfoot::cli::study_command
