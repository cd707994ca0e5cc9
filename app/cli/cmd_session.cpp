// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot session`: runs a session headless in the terminal (answers read from stdin), or a
// whole simulated study (--simulate) with synthetic participants answering from confusion
// matrices. With --live the stimuli play through the audio device (app/wiring LivePlayer): GRF
// or gait recordings and the audio figures are stored with each trial, FSR shoes (--serial) and
// gyroscopes (--osc) drive the sensor stimuli, and a sensor fault pauses the session.
#include "app/cli/CommandRegistry.h"
#include "app/wiring/Adapters.h"
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "app/wiring/SessionRig.h"
#include "base/Plural.h"
#include "base/Version.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/io/AudioDevice.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Clips.h"
#include "experiment/Protocol.h"
#include "experiment/RatingModel.h"
#include "experiment/Session.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"
#include "experiment/TrialFlow.h"

#include <fmt/core.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace underfoot::cli::session_command {
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
    bool takeOver = false; ///< take over another process's session lease (after a crash)
    bool showStimulus = false;
    bool simulate = false;
    std::vector<std::string> confusion;
    int participants = 0;
    double soundscapeAccuracy = 0.85;
    std::string prefix = "S";
    std::string clips;
    std::string ratingModel;
    // Live audio and sensors.
    bool live = false;
    std::string settings;   ///< audio settings TOML (`underfoot devices --save`)
    std::string recordings; ///< folder of the trials' recordings (default: next to the study)
    int oscPort = -1;       ///< gyroscopes (OSC/UDP) for gyro and water stimuli
    std::string serial;     ///< FSR shoes' port
    int baud = 500000;
    std::string thresholds; ///< the participant's step thresholds (underfoot sensors calibrate)
    std::uint64_t stepSeed = 1;
};

namespace eng = underfoot::engine;
namespace wir = underfoot::wiring;

std::string askLine(const std::string& prompt);

wir::SessionRigOptions rigOptions(const Options& o) {
    wir::SessionRigOptions r;
    r.settingsFile = o.settings;
    r.studyFile = o.study;
    r.recordings = o.recordings;
    r.serial = o.serial;
    r.baud = o.baud;
    r.thresholds = o.thresholds;
    r.stepSeed = o.stepSeed;
    r.oscPort = o.oscPort;
    return r;
}

std::unique_ptr<wir::SessionRig> openClipRig(const Options& o) {
    try {
        auto rig = wir::SessionRig::openForClips(rigOptions(o));
        fmt::print("live audio: clips play through {}\n", rig->summary());
        return rig;
    } catch (const std::exception& e) {
        throw UserError(std::string("session --live: no sound can be played: ") + e.what());
    }
}

std::unique_ptr<wir::SessionRig> openLiveRig(const Options& o) {
    try {
        auto rig = wir::SessionRig::openLive(rigOptions(o));
        fmt::print("live audio: {}\n", rig->summary());
        return rig;
    } catch (const std::exception& e) {
        throw UserError(std::string("session --live: no sound can be played: ") + e.what());
    }
}

/// While the session is paused by a sensor fault: says why, and resumes when the experimenter
/// confirms that the sensor is back (refused, with the reason, while it still fails).
void waitOutSensorFault(Session& session, const TrialFlow& flow) {
    while (session.paused()) {
        fmt::print("\n");
        askLine(flow.pausePrompt());
        try {
            session.resumeAfterFault();
        } catch (const std::logic_error& e) {
            fmt::print("not yet: {}\n", e.what());
        }
    }
}

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

/// Asks one question of the trial flow until the flow has its answer: prints the flow's lines
/// and prompt and forwards each typed line (the flow reads it: a letter, a number, 'r' to hear
/// a clip again); 'quit' interrupts.
void askSection(TrialFlow& flow, int index) {
    while (!flow.sectionAnswered(index)) {
        for (const auto& line : flow.sectionLines(index)) fmt::print("{}\n", line);
        if (const auto r = flow.typeLine(index, askLine(flow.sectionInputPrompt(index))); !r)
            fmt::print("{}\n", r.message);
    }
}

/// The terminal's session: a thin adapter of experiment::TrialFlow. It prints the participant's
/// screen model (heading, text, questions) and the flow's prompts, and forwards what is typed
/// (the flow reads it); the experimenter's lines
/// (stimulus, group, clip file) appear only with --show-stimulus and are marked as such.
int runInteractive(const Options& o) {
    StudyStore store = StudyStore::open(o.study);
    if (!o.protocol.empty()) store.verifyProtocol(loadProtocol(o.protocol));
    const Protocol& p = store.protocol();
    {
        // A session records only real people's answers, never a simulation's.
        if (const std::string why = personSessionRefusal(store.participant(o.participant));
            !why.empty())
            throw UserError("session: " + why);
    }
    SilentPlayer silent; // data entry, unless --live wires the engine in
    if (p.clips.enabled && o.clips.empty())
        throw UserError(fmt::format("session: protocol {} is a listening test; give --clips "
                                    "FOLDER (made by `underfoot clips --protocol ... -o "
                                    "FOLDER`)",
                                    p.id));
    std::unique_ptr<wir::SessionRig> rig;
    if (o.live) rig = p.clips.enabled ? openClipRig(o) : openLiveRig(o);
    std::unique_ptr<ClipPlayer> clipPlayer;
    if (p.clips.enabled) {
        const bool show = o.showStimulus;
        ClipPlayer::PlayFunction play = [show](const std::string& path) {
            fmt::print("  [no sound: the clip would play now{}]\n",
                       show ? " — experimenter: " + path : std::string());
        };
        std::function<void()> stop;
        if (rig) {
            wir::ClipAudio* audio = rig->clipAudio.get();
            play = [audio, show](const std::string& path) {
                audio->play(path);
                fmt::print("  [playing{}]\n", show ? " — experimenter: " + path : std::string());
            };
            stop = [audio] { audio->stop(); };
        }
        clipPlayer = std::make_unique<ClipPlayer>(p, o.clips, play, stop);
    }
    if (!o.live)
        fmt::print("{} Add --live [--settings FILE] to play the stimuli.\n",
                   TrialFlow::noSoundNotice());
    StimulusPlayer& player = clipPlayer ? static_cast<StimulusPlayer&>(*clipPlayer)
                             : rig      ? static_cast<StimulusPlayer&>(*rig->player)
                                        : silent;
    Session session(store, o.participant, player,
                    {o.experimenter, o.live ? o.audio : "none (data entry, no sound)",
                     o.clips.empty() ? o.sensor : "clips " + o.clips, underfoot::base::version(),
                     o.live, o.takeOver});
    TrialFlow flow(store, session);
    fmt::print("{} — participant {}, session {}{}{}\n", participantTitle(p), o.participant,
               session.sessionNumber(),
               session.resumed() ? fmt::format(", resuming at trial {} of {}",
                                               session.current().index + 1, session.trialCount())
                                 : "",
               o.showStimulus
                   ? fmt::format(" [experimenter: group {}]", session.participant().groupId)
                   : "");
    std::string shownPart;
    try {
        while (session.phase() != SessionPhase::Finished) {
            const ParticipantScreen screen = flow.participantScreen();
            switch (screen.page) {
            case ParticipantScreen::Page::Briefing:
                fmt::print("\n{}\n\n{}\n", screen.heading, screen.text);
                fmt::print("\n");
                askLine(flow.continuePrompt());
                session.finishBriefing();
                flow.reset();
                continue;
            case ParticipantScreen::Page::Break:
                fmt::print("\n{}. {}\n", screen.heading, screen.text);
                askLine(flow.continuePrompt());
                session.finishBreak();
                flow.reset();
                continue;
            case ParticipantScreen::Page::Finished:
            case ParticipantScreen::Page::Waiting:
                continue;
            case ParticipantScreen::Page::Trial:
                break;
            }
            const TrialRecord t = session.current();
            fmt::print("\n{}{}\n", screen.heading,
                       o.showStimulus ? fmt::format(" [experimenter: stimulus {}]", t.stimulus.id)
                                      : "");
            if (!screen.part.empty() && screen.part != shownPart) {
                shownPart = screen.part;
                fmt::print("\n{}\n", screen.part);
            }
            if (const std::string prompt = flow.startPrompt(); !prompt.empty()) {
                askLine(prompt);
                if (const auto r = flow.start(); !r) {
                    fmt::print("not started: {}\n", r.message);
                    if (session.paused()) waitOutSensorFault(session, flow);
                    flow.reset();
                    continue;
                }
            }
            bool faulted = false;
            for (std::string lap; !(lap = flow.lapPrompt()).empty();) {
                askLine(lap);
                if ((faulted = session.checkSensors())) break;
                if (const auto r = flow.completeLap(); !r) fmt::print("{}\n", r.message);
            }
            if (faulted || session.checkSensors()) {
                waitOutSensorFault(session, flow);
                flow.reset();
                continue; // the same trial again, from the start
            }
            for (int i = 0; i < static_cast<int>(flow.sections().size()); ++i) askSection(flow, i);
            if (const std::string prompt = flow.commentPrompt(); !prompt.empty())
                flow.setComment(askLine(prompt));
            if (session.checkSensors()) { // nothing stored: the trial comes again
                waitOutSensorFault(session, flow);
                flow.reset();
                continue;
            }
            if (const auto r = flow.commit(); !r) {
                fmt::print("not stored: {}\n", r.message);
                if (session.paused()) waitOutSensorFault(session, flow);
                flow.reset();
                continue; // the same trial: its questions again
            }
            if (o.ack) fmt::print("ack {} {}\n", o.participant, t.index + 1);
        }
    } catch (const Interrupted&) {
        session.interrupt();
        fmt::print("\nsession interrupted; {}. Run the same command to resume.\n",
                   progressText(session.answeredCount(), session.trialCount()));
        return 3;
    }
    fmt::print("\nsession complete: {} answered\n", counted(session.trialCount(), "trial"));
    return 0;
}

int runSimulation(const Options& o) {
    StudyStore store = StudyStore::open(o.study);
    if (!o.protocol.empty()) store.verifyProtocol(loadProtocol(o.protocol));
    const bool needsMatrix = store.protocol().questions.asksSurface();
    MatrixByGroup matrices;
    if (o.confusion.empty() && needsMatrix) {
        // The published matrices the protocol names ([simulation], protocols/data/).
        try {
            matrices = defaultMatrices(store.protocol(), o.protocol);
        } catch (const std::runtime_error& e) {
            throw UserError(e.what());
        }
        if (matrices.empty())
            throw UserError(fmt::format("--simulate: protocol {} asks which surface and names no "
                                        "confusion matrix in [simulation]; give --confusion "
                                        "[GROUP=]FILE",
                                        store.protocol().id));
        for (const auto& [group, file] : store.protocol().simulation.confusion)
            fmt::print("confusion matrix{}: {} (named by the protocol)\n",
                       group.empty() ? "" : " of group " + group, file);
    }
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
    std::string ratingModelFile = o.ratingModel;
    if (ratingModelFile.empty() && !store.protocol().simulation.ratingModel.empty()) {
        try {
            ratingModelFile = findProtocolFile(store.protocol(),
                                               store.protocol().simulation.ratingModel, o.protocol);
        } catch (const std::runtime_error& e) {
            throw UserError(e.what());
        }
        fmt::print("rating model: {} (named by the protocol)\n",
                   store.protocol().simulation.ratingModel);
    }
    if (!ratingModelFile.empty()) {
        auto model = std::make_shared<RatingModel>(loadRatingModel(ratingModelFile));
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
        settings.clipDir = o.clips; // each simulated trial stores the clip it stands for
    }
    int real = 0;
    for (const auto& p : store.participants()) real += p.simulated ? 0 : 1;
    if (real > 0)
        fmt::print("{} left untouched: a simulation answers only for the simulated participants it "
                   "creates\n",
                   counted(real, "real participant"));
    const int answers = simulateStudy(store, matrices, o.participants, settings, o.prefix,
                                      [&](const std::string& code, int index) {
                                          if (!o.ack) return;
                                          fmt::print("ack {} {}\n", code, index + 1);
                                          std::fflush(stdout);
                                      });
    int simulated = 0;
    for (const auto& p : store.participants()) simulated += p.simulated ? 1 : 0;
    fmt::print("simulated: {} committed; {} simulated and {} real {} in the study\n",
               counted(answers, "answer"), simulated, real,
               plural(simulated + real, "participant"));
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
        cmd->add_flag("--ack", o.ack,
                      "print 'ack CODE TRIAL' (1-based trial number) after each committed "
                      "answer");
        cmd->add_flag("--take-over", o.takeOver,
                      "take over the participant's session from another process that holds it "
                      "(after a crash on another machine; journaled)");
        cmd->add_flag("--show-stimulus", o.showStimulus,
                      "show the stimulus id to the "
                      "experimenter");
        cmd->add_flag("--simulate", o.simulate,
                      "synthetic participants answering from "
                      "confusion matrices");
        cmd->add_option("--confusion", o.confusion,
                        "[GROUP=]FILE confusion matrix CSV (published format); repeat per group; "
                        "default: the published matrices the protocol names in [simulation]");
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
                        "level, stimulus and participant field (protocols/simulation/); default: "
                        "the one the protocol names in [simulation]");
        cmd->add_flag("--live", o.live,
                      "play the stimuli through the audio device (recordings and audio figures "
                      "stored with each trial; a sensor fault pauses the session)");
        cmd->add_option("--settings", o.settings,
                        "audio settings file for --live (`underfoot devices --save`)");
        cmd->add_option("--recordings", o.recordings,
                        "folder of the trials' recordings (default: recordings/ beside the "
                        "study)");
        cmd->add_option("--osc", o.oscPort,
                        "UDP port of the OSC gyroscopes (gyro and water "
                        "stimuli)")
            ->check(CLI::Range(0, 65535));
        cmd->add_option("--serial", o.serial, "serial port of the FSR shoes (FSR stimuli)");
        cmd->add_option("--baud", o.baud, "baud rate of the FSR shoes")->capture_default_str();
        cmd->add_option("--thresholds", o.thresholds,
                        "the participant's step thresholds (`underfoot sensors calibrate`)");
        cmd->callback([&exitCode, &o] {
            try {
                if (!o.live && (!o.settings.empty() || o.oscPort >= 0 || !o.serial.empty() ||
                                !o.thresholds.empty() || !o.recordings.empty()))
                    throw UserError("session: --settings, --recordings, --osc, --serial and "
                                    "--thresholds belong to --live");
                if (o.simulate && o.live)
                    throw UserError("session: --simulate plays nothing (synthetic participants "
                                    "answer at once); --live belongs to a person's session");
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
} // namespace underfoot::cli::session_command
