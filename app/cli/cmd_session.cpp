// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot session`: runs a session headless in the terminal (answers read from stdin), or a
// whole simulated study (--simulate) with synthetic participants answering from confusion
// matrices.
#include "app/cli/CommandRegistry.h"
#include "experiment/Clips.h"
#include "experiment/Protocol.h"
#include "experiment/RatingModel.h"
#include "experiment/Session.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <fmt/core.h>

#include <cstdio>
#include <iostream>
#include <memory>

namespace {

using namespace underfoot::experiment;
using underfoot::cli::UserError;

struct Options {
    std::string study;
    std::string participant;
    std::string protocol;
    std::string experimenter;
    std::string audio = "default";
    std::string sensor = "default";
    bool ack = false;
    bool showStimulus = false;
    bool simulate = false;
    std::vector<std::string> confusion;
    int participants = 0;
    double soundscapeAccuracy = 0.85;
    std::string prefix = "S";
    std::string clips;
    std::string ratingModel;
};

Options& opts() {
    static Options o;
    return o;
}

/// Reads one line; false at end of input.
bool readLine(std::string& line) {
    if (!std::getline(std::cin, line)) return false;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    while (!line.empty() && line.front() == ' ') line.erase(line.begin());
    return true;
}

struct Interrupted {};

std::string askLine(const std::string& prompt) {
    fmt::print("{}", prompt);
    std::fflush(stdout);
    std::string line;
    if (!readLine(line)) throw Interrupted{};
    if (line == "quit" || line == "q!") throw Interrupted{};
    return line;
}

std::string askOption(const std::string& prompt, const std::vector<AnswerOption>& options) {
    fmt::print("{}\n", prompt);
    for (const auto& o : options) fmt::print("  {}. {}\n", o.letter, o.label);
    while (true) {
        const std::string line = askLine("letter> ");
        if (line.size() == 1)
            for (const auto& o : options)
                if (o.letter == line[0]) return o.id;
        fmt::print("expected one of the letters {}-{} (or 'quit' to interrupt)\n",
                   options.front().letter, options.back().letter);
    }
}

std::string anchorsText(const Scale& s) {
    if (s.anchors.empty()) return fmt::format("{} .. {}", s.min, s.max);
    std::string out;
    for (const auto& [value, label] : s.anchors)
        out += fmt::format("{}{} = {}", out.empty() ? "" : ", ", value, label);
    return fmt::format("{} .. {}; {}", s.min, s.max, out);
}

int askScale(const Scale& s, bool replayable = false) {
    while (true) {
        const std::string line =
            askLine(s.anchors.empty() ? fmt::format("{} [{} {} .. {} {}]> ", s.prompt, s.min,
                                                    s.minLabel, s.max, s.maxLabel)
                                      : fmt::format("{} [{}]> ", s.prompt, anchorsText(s)));
        if (replayable && line == "r") return s.min - 1; // caller replays the clip
        try {
            std::size_t used = 0;
            const int v = std::stoi(line, &used);
            if (used == line.size() && v >= s.min && v <= s.max) return v;
        } catch (const std::exception&) {
        }
        fmt::print("expected a whole number from {} to {}\n", s.min, s.max);
    }
}

int runInteractive(const Options& o) {
    StudyStore store = StudyStore::open(o.study);
    if (!o.protocol.empty()) store.verifyProtocol(loadProtocol(o.protocol));
    const Protocol& p = store.protocol();
    SilentPlayer silent; // headless: the engine is wired in by the app
    std::unique_ptr<ClipPlayer> clipPlayer;
    if (p.clips.enabled) {
        if (o.clips.empty())
            throw UserError(fmt::format("session: protocol {} is a listening test; give --clips "
                                        "FOLDER (made by `underfoot clips --protocol ... -o "
                                        "FOLDER`)",
                                        p.id));
        clipPlayer = std::make_unique<ClipPlayer>(
            p, o.clips, [](const std::string& path) { fmt::print("  [playing {}]\n", path); });
    }
    StimulusPlayer& player = clipPlayer ? static_cast<StimulusPlayer&>(*clipPlayer) : silent;
    Session session(store, o.participant, player,
                    {o.experimenter, o.audio, o.clips.empty() ? o.sensor : "clips " + o.clips,
                     UNDERFOOT_VERSION});
    const Questions& q = p.questions;
    fmt::print("{} — participant {} (group {}), session {}{}\n", p.title, o.participant,
               session.participant().groupId, session.sessionNumber(),
               session.resumed()
                   ? fmt::format(", resuming at trial {}", session.current().index + 1)
                   : "");
    int shownBlock = 0;
    try {
        while (session.phase() != SessionPhase::Finished) {
            switch (session.phase()) {
            case SessionPhase::Briefing:
                if (!p.description.empty()) fmt::print("\n{}\n", p.description);
                askLine("\nBriefing done? Press Enter to start. ");
                session.finishBriefing();
                break;
            case SessionPhase::Break:
                askLine("\nBreak. Press Enter to continue. ");
                session.finishBreak();
                break;
            case SessionPhase::Practice:
            case SessionPhase::Trial: {
                const TrialRecord t = session.current();
                fmt::print("\n{} {} of {}{}\n", t.practice ? "Practice trial" : "Trial",
                           t.index + 1, session.trialCount(),
                           o.showStimulus ? fmt::format(" — stimulus {}", t.stimulus.id) : "");
                if (p.clips.enabled) {
                    if (p.ordering.blocks == BlockKind::Scale && !t.practice &&
                        t.block != shownBlock && !session.askedScales().empty()) {
                        shownBlock = t.block;
                        fmt::print("\nPart {} of {}: {}\n", t.block, q.scales.size(),
                                   session.askedScales().front()->prompt);
                    }
                    askLine("Press Enter to play the clip. ");
                    session.presentClip();
                    while (true) {
                        for (const Scale* s : session.askedScales()) {
                            int v = 0;
                            while ((v = askScale(*s, p.clips.replay)) < s->min) {
                                session.presentClip();
                                fmt::print("  (replay {})\n", session.replayCount());
                            }
                            session.rate(s->id, v);
                        }
                        const std::string comment =
                            q.comment ? askLine("comment (Enter for none)> ") : std::string();
                        try {
                            session.submitRatings(comment);
                        } catch (const StoreError& e) {
                            fmt::print("not stored: {}\n", e.what());
                            continue;
                        }
                        break;
                    }
                    if (o.ack) fmt::print("ack {} {}\n", o.participant, t.index);
                    break;
                }
                askLine("Press Enter to start the stimulus. ");
                session.play();
                for (int lap = session.lapsDone(); lap < session.lapCount(); ++lap) {
                    askLine(
                        fmt::format("Lap {} of {} ({}). Press Enter when it is walked. ", lap + 1,
                                    session.lapCount(),
                                    session.currentLapSilent() ? "silent baseline" : "with sound"));
                    session.completeLap();
                }
                while (true) {
                    TrialAnswer a;
                    if (q.asksSurface()) a.answer = askOption(q.surfacePrompt, q.surfaceOptions);
                    for (const Scale* s : session.askedScales()) a.ratings[s->id] = askScale(*s);
                    if (q.asksSoundscape(session.participant().groupId))
                        a.soundscapeAnswer = askOption(q.soundscapePrompt, q.soundscapeOptions);
                    if (q.comment) a.comment = askLine("comment (Enter for none)> ");
                    try {
                        session.answer(a);
                    } catch (const StoreError& e) {
                        fmt::print("not stored: {}\n", e.what());
                        continue;
                    }
                    if (o.ack) fmt::print("ack {} {}\n", o.participant, t.index);
                    break;
                }
                break;
            }
            case SessionPhase::Finished:
                break;
            }
        }
    } catch (const Interrupted&) {
        session.interrupt();
        fmt::print("\nsession interrupted; {} of {} trials answered. Run the same command to "
                   "resume.\n",
                   session.answeredCount(), session.trialCount());
        return 3;
    }
    fmt::print("\nsession complete: {} trials answered\n", session.trialCount());
    return 0;
}

int runSimulation(const Options& o) {
    StudyStore store = StudyStore::open(o.study);
    if (!o.protocol.empty()) store.verifyProtocol(loadProtocol(o.protocol));
    const bool needsMatrix = store.protocol().questions.asksSurface();
    if (o.confusion.empty() && needsMatrix)
        throw UserError("--simulate needs at least one --confusion [GROUP=]FILE (the protocol "
                        "asks which surface)");
    MatrixByGroup matrices;
    for (const auto& spec : o.confusion) {
        const auto eq = spec.find('=');
        const std::string group = eq == std::string::npos ? "" : spec.substr(0, eq);
        const std::string file = eq == std::string::npos ? spec : spec.substr(eq + 1);
        if (!group.empty() && !store.protocol().group(group))
            throw UserError(fmt::format("--confusion {}: '{}' is not a group of protocol {}", spec,
                                        group, store.protocol().id));
        try {
            matrices[group] = loadConfusionMatrix(file);
        } catch (const std::runtime_error& e) {
            throw UserError(e.what());
        }
    }
    if (!needsMatrix) matrices.try_emplace(""); // ratings only: no matrix is consulted
    // Every group must be answerable before anything is written.
    for (const auto& g : store.protocol().groups) {
        if (!needsMatrix) break;
        const auto it = matrices.count(g.id) ? matrices.find(g.id) : matrices.find("");
        if (it == matrices.end())
            throw UserError(fmt::format("no --confusion matrix for group '{}'", g.id));
        Protocol one = store.protocol();
        one.groups = {g};
        if (auto problems = checkMatrixAgainst(it->second, one); !problems.empty()) {
            std::string all;
            for (const auto& s : problems) all += (all.empty() ? "" : "\n") + s;
            throw UserError(all);
        }
    }
    SimulationSettings settings;
    settings.soundscapeAccuracy = o.soundscapeAccuracy;
    if (!o.ratingModel.empty()) {
        auto model = std::make_shared<RatingModel>(loadRatingModel(o.ratingModel));
        if (auto problems = checkRatingModel(*model, store.protocol()); !problems.empty()) {
            std::string all;
            for (const auto& s : problems) all += (all.empty() ? "" : "\n") + s;
            throw UserError(all);
        }
        settings.ratingModel = std::move(model);
    }
    if (!o.clips.empty() && store.protocol().clips.enabled) {
        if (auto problems = checkClips(store.protocol(), o.clips); !problems.empty()) {
            std::string all;
            for (const auto& s : problems) all += (all.empty() ? "" : "\n") + s;
            throw UserError(all);
        }
    }
    const int answers = simulateStudy(store, matrices, o.participants, settings, o.prefix,
                                      [&](const std::string& code, int index) {
                                          if (!o.ack) return;
                                          fmt::print("ack {} {}\n", code, index);
                                          std::fflush(stdout);
                                      });
    fmt::print("simulated: {} answers committed; {} participants in the study\n", answers,
               store.participants().size());
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "session", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand(
            "session", "Run a session headless (answers from stdin: letters for the answer "
                       "list, numbers for scales; 'quit' interrupts, the same command resumes), "
                       "or simulate a whole study with --simulate");
        cmd->add_option("--study", o.study, "study file")->required();
        cmd->add_option("--participant", o.participant, "participant code (interactive mode)");
        cmd->add_option("--protocol", o.protocol,
                        "protocol file to check against the study (refused if it differs)");
        cmd->add_option("--experimenter", o.experimenter, "experimenter (recorded)");
        cmd->add_option("--audio", o.audio, "audio configuration (recorded)");
        cmd->add_option("--sensor", o.sensor, "sensor configuration (recorded)");
        cmd->add_flag("--ack", o.ack, "print 'ack CODE TRIAL' after each committed answer");
        cmd->add_flag("--show-stimulus", o.showStimulus,
                      "show the stimulus id to the "
                      "experimenter");
        cmd->add_flag("--simulate", o.simulate,
                      "synthetic participants answering from "
                      "confusion matrices");
        cmd->add_option("--confusion", o.confusion,
                        "[GROUP=]FILE confusion matrix CSV (published format); repeat per group");
        cmd->add_option("--participants", o.participants,
                        "simulate until this many participants have completed")
            ->check(CLI::Range(0, 100000));
        cmd->add_option("--soundscape-accuracy", o.soundscapeAccuracy,
                        "probability that a synthetic participant names the soundscape")
            ->check(CLI::Range(0.0, 1.0));
        cmd->add_option("--prefix", o.prefix, "code prefix of synthetic participants");
        cmd->add_option("--clips", o.clips,
                        "clip folder of a listening test (from `underfoot clips`); checked "
                        "before anything is stored");
        cmd->add_option("--rating-model", o.ratingModel,
                        "rating model (TOML) of synthetic participants: effects per factor "
                        "level, stimulus and participant field (protocols/simulation/)");
        cmd->callback([&exitCode, &o] {
            try {
                if (o.simulate) {
                    exitCode = runSimulation(o);
                } else {
                    if (o.participant.empty())
                        throw UserError("session: --participant is required (or --simulate)");
                    exitCode = runInteractive(o);
                }
            } catch (const ProtocolError& e) {
                throw UserError(e.what());
            } catch (const StoreError& e) {
                throw UserError(e.what());
            }
        });
    }};

} // namespace
