// SPDX-License-Identifier: GPL-3.0-or-later
// The participant-visible contract for the terminal: `underfoot session` (data entry; clip
// protocols with their rendered clip folder) runs one participant per group of every shipped
// protocol to its end, and no line it prints, read trial by trial, shows what only the
// experimenter may read (tests/experiment/support/ParticipantScreens.h: notes, group names, the
// current stimulus's ids, clip file names, seeds, the correct answer).
#include "app/wiring/ClipPlayer.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"
#include "experiment/TrialFlow.h"
#include "tests/common/ReadFile.h"
#include "tests/common/ScratchDir.h"
#include "tests/experiment/support/ParticipantScreens.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <sys/wait.h>

namespace xp = underfoot::experiment;
namespace xt = underfoot::experiment::test;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;

using underfoot::test::readFile;

namespace {

/// The protocol's own wording (prompts, option labels, anchors, briefing): what the terminal
/// prints on every trial alike; removed from a trial's lines to leave what varies.
std::vector<std::string> fixedWording(const xp::Protocol& p) {
    // The terminal's own prompts too ("Enter for none" is not the group "none").
    std::vector<std::string> out{p.questions.surfacePrompt, p.questions.soundscapePrompt,
                                 p.briefing, "comment (Enter for none)> "};
    // (the comment prompt is the trial core's: TrialFlow.TextPromptsAndTypedLinesAreTheCores)
    for (const auto& o : p.questions.surfaceOptions) out.push_back(o.label);
    for (const auto& o : p.questions.soundscapeOptions) out.push_back(o.label);
    for (const auto& s : p.questions.scales) {
        out.push_back(s.prompt);
        out.push_back(s.minLabel);
        out.push_back(s.maxLabel);
        for (const auto& a : xp::anchorTexts(s)) out.push_back(a);
    }
    std::sort(out.begin(), out.end(),
              [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
    return out;
}

std::string withoutWording(std::string text, const std::vector<std::string>& wording) {
    for (const auto& w : wording) {
        if (w.empty()) continue;
        for (std::size_t at; (at = text.find(w)) != std::string::npos;) text.erase(at, w.size());
    }
    return text;
}

struct TerminalFigures {
    int trials = 0;
    int searched = 0;
    std::vector<std::string> found;
};

/// Runs one participant per group of `p` through `underfoot session` (with `extra` arguments)
/// and searches every part of its output with the trial it belongs to.
TerminalFigures runTerminal(const xp::Protocol& p, const std::string& scratch,
                            const std::string& extra) {
    TerminalFigures f;
    const std::regex heading(R"(^(Practice trial|Trial) (\d+) of \d+)");
    const fs::path dir = underfoot::test::scratchDir(scratch);
    if (p.clips.enabled) wir::renderClipFolder(p, (dir / "clips").string());
    const std::string study = (dir / "study.db").string();
    std::vector<std::string> codes;
    {
        xp::StudyStore store = xp::StudyStore::create(study, p, {"T", "lab", 3, "t"});
        const std::size_t groups = std::max<std::size_t>(1, p.groups.size());
        for (std::size_t g = 0; g < groups; ++g) {
            std::map<std::string, std::string> fields;
            for (const auto& field : p.participantFields)
                fields[field.id] = field.options.empty() ? "x" : field.options.front();
            xp::NewParticipant who{"P" + std::to_string(g + 1), {}, "", "", "", {}, ""};
            if (p.design == xp::DesignKind::Between) {
                who.groupOverride = p.groups[g].id;
                who.overrideReason = "every group's lines";
            }
            store.registerParticipant(who, fields);
            codes.push_back(who.code);
        }
    }
    // Answers the terminal takes whatever it asks: a letter, then a number, repeated (a refused
    // line is asked again); Enter prompts and comments take either.
    {
        std::ofstream in(dir / "input.txt");
        for (int i = 0; i < 4000; ++i) in << "a\n1\n";
    }
    const auto wording = fixedWording(p);
    for (const auto& code : codes) {
        const fs::path out = dir / (code + ".txt");
        const std::string command = fmt::format(
            "'{}' session --study '{}' --participant {}{}{} < '{}' > '{}' 2>&1", UNDERFOOT_CLI,
            study, code, p.clips.enabled ? " --clips '" + (dir / "clips").string() + "'" : "",
            extra, (dir / "input.txt").string(), out.string());
        EXPECT_EQ(std::system(command.c_str()), 0) << command << "\n" << readFile(out);
        const xp::StudyStore store = xp::StudyStore::openForReading(study);
        const auto stored = store.trials(code);
        // Split the lines at each trial heading; each part is read with its trial.
        std::istringstream lines(readFile(out));
        std::string line, part;
        const xp::TrialRecord* current = nullptr;
        const auto check = [&] {
            const auto forbidden = xt::forbiddenStrings(p, current);
            f.searched += static_cast<int>(forbidden.size());
            // The answer lists print the options, whose labels may be the ids ("b. gravel"); the
            // protocol's wording is the screen model's, searched there.
            const std::string own = withoutWording(part, wording);
            for (const auto& hit : xt::leaks(own, own, forbidden))
                f.found.push_back(fmt::format("{} {} {}: {}", p.id, code,
                                              current ? fmt::format("trial {}", current->index + 1)
                                                      : "before the trials",
                                              hit));
            part.clear();
        };
        while (std::getline(lines, line)) {
            std::smatch m;
            if (std::regex_search(line, m, heading)) {
                check();
                const int index = std::stoi(m[2].str()) - 1;
                current = nullptr;
                for (const auto& t : stored)
                    if (t.index == index) current = &t;
                EXPECT_NE(current, nullptr) << line;
                ++f.trials;
            }
            part += line + "\n";
        }
        check();
    }
    return f;
}

} // namespace

TEST(TerminalParticipantLines, NoLineOfAnyShippedProtocolShowsWhatOnlyTheExperimenterMayRead) {
    int protocols = 0, trials = 0, searched = 0;
    for (const auto& entry : fs::directory_iterator(xp::shippedProtocolDir())) {
        if (entry.path().extension() != ".toml") continue;
        const xp::Protocol p = xp::loadProtocol(entry.path().string());
        bool labClips = false;
        for (const auto& s : p.stimuli) labClips = labClips || s.clip.has_value();
        if (labClips) continue; // the lab's recordings are not shipped (wading_realism)
        ++protocols;
        const TerminalFigures f = runTerminal(p, "terminal_lines_" + p.id, "");
        trials += f.trials;
        searched += f.searched;
        for (const auto& hit : f.found) ADD_FAILURE() << hit;
    }
    EXPECT_GE(protocols, 6);
    std::printf("terminal lines: %d protocols, %d trials, %d forbidden-string searches\n",
                protocols, trials, searched);
}

// The experimenter's lines of --show-stimulus name the stimulus: the search finds them.
TEST(TerminalParticipantLines, ExperimenterLinesAreFound) {
    const xp::Protocol p = xp::loadProtocol(xp::shippedProtocolDir() + "/tvcg2011_exp2.toml");
    const TerminalFigures f = runTerminal(p, "terminal_lines_injected", " --show-stimulus");
    ASSERT_FALSE(f.found.empty());
    bool stimulus = false, group = false;
    for (const auto& hit : f.found) {
        stimulus = stimulus || hit.find("stimulus id '") != std::string::npos;
        group = group || hit.find("group id '") != std::string::npos;
    }
    EXPECT_TRUE(stimulus);
    EXPECT_TRUE(group);
}

// The terminal prints the trial core's prompts and control lines (briefing, NO SOUND) and forwards
// what is typed. With the laps of the
// protocol changed (1 silent baseline lap and 2 with sound instead of 3 + 3), `underfoot session`
// asks exactly the lap prompts that the core's TrialFlow gives for that protocol; the lines the
// protocol refuses (a rating off its scale, a word) are refused with the core's messages and
// never stored.
TEST(TerminalParticipantLines, LapPromptsAndTypedLinesComeFromTheTrialCore) {
    const fs::path dir = underfoot::test::scratchDir("terminal_core_prompts");
    std::string text = readFile(fs::path(xp::shippedProtocolDir()) / "wading_interactive.toml");
    const auto at = text.find("baseline = 3\nfeedback = 3");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 25, "baseline = 1\nfeedback = 2");
    const xp::Protocol p = xp::parseProtocol(text, "laps.toml");
    const std::string study = (dir / "study.db").string();
    const std::string copy = (dir / "core.db").string();
    {
        xp::StudyStore store = xp::StudyStore::create(study, p, {"L", "lab", 3, "t"});
        store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    }
    fs::copy_file(study, copy, fs::copy_options::overwrite_existing);
    // The core's prompts for P1's first trial, from a session on a copy of the study.
    std::vector<std::string> corePrompts;
    std::string rangeMessage;
    std::size_t scales = 0;
    {
        xp::StudyStore store = xp::StudyStore::open(copy);
        xp::SilentPlayer silent;
        xp::Session session(store, "P1", silent, {});
        xp::TrialFlow flow(store, session);
        corePrompts.push_back(flow.continuePrompt()); // the briefing's
        EXPECT_EQ(flow.pausePrompt(), "");            // no sensor fault
        session.finishBriefing();
        flow.reset();
        EXPECT_EQ(flow.continuePrompt(), "");
        corePrompts.push_back(flow.startPrompt());
        ASSERT_TRUE(flow.start());
        for (std::string lap; !(lap = flow.lapPrompt()).empty();) {
            corePrompts.push_back(lap);
            ASSERT_TRUE(flow.completeLap());
        }
        scales = flow.sections().size();
        for (int i = 0; i < static_cast<int>(scales); ++i) {
            ASSERT_EQ(flow.sections()[static_cast<std::size_t>(i)].kind, xp::SectionKind::Scale);
            corePrompts.push_back(flow.sectionInputPrompt(i));
        }
        corePrompts.push_back(flow.commentPrompt());
        rangeMessage = xp::ratingRangeProblem(*flow.sections().front().scale, 99);
        session.interrupt();
    }
    ASSERT_GE(scales, 1u);
    // briefing, start, 3 laps, the scales, comment
    ASSERT_EQ(corePrompts.size(), 2u + 3u + scales + 1u);
    EXPECT_NE(corePrompts[2].find("Lap 1 of 3 (silent baseline)"), std::string::npos);
    {
        std::ofstream in(dir / "input.txt");
        in << "\n\n\n\n\n";    // briefing, start, three laps
        in << "99\nfour\n4\n"; // first scale: off the scale, a word, then 4
        for (std::size_t i = 1; i < scales; ++i) in << "4\n";
        in << "\nquit\n"; // no comment; stop at the next trial
    }
    const fs::path out = dir / "out.txt";
    const std::string command =
        fmt::format("'{}' session --study '{}' --participant P1 < '{}' > '{}' 2>&1", UNDERFOOT_CLI,
                    study, (dir / "input.txt").string(), out.string());
    const int status = std::system(command.c_str());
    const std::string printed = readFile(out);
    EXPECT_EQ(WEXITSTATUS(status), 3) << "interrupted by 'quit'\n" << printed;
    std::size_t from = 0;
    for (const auto& prompt : corePrompts) {
        const auto found = printed.find(prompt, from);
        EXPECT_NE(found, std::string::npos) << "the core's prompt '" << prompt << "' in order in:\n"
                                            << printed;
        if (found != std::string::npos) from = found + prompt.size();
    }
    EXPECT_NE(printed.find(xp::TrialFlow::noSoundNotice()), std::string::npos) << printed;
    EXPECT_NE(printed.find(rangeMessage), std::string::npos) << printed;
    EXPECT_NE(printed.find("expected a whole number from 1 to 7"), std::string::npos) << printed;
    const xp::StudyStore store = xp::StudyStore::openForReading(study);
    int answered = 0;
    for (const auto& t : store.trials("P1")) {
        if (!t.answered) continue;
        ++answered;
        EXPECT_EQ(t.lapsDone, 3);
        for (const auto& [scale, value] : t.answer.ratings) EXPECT_EQ(value, 4) << scale;
    }
    EXPECT_EQ(answered, 1);
}
