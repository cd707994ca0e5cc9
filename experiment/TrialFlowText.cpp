// SPDX-License-Identifier: GPL-3.0-or-later
// The trial flow for a text front end (`underfoot session`): its prompts and the reading of a
// typed line, so that the terminal only prints them and forwards what is typed.
#include "experiment/TrialFlow.h"

#include <fmt/format.h>

namespace underfoot::experiment {

std::string TrialFlow::startPrompt() const {
    if (!inTrial() || session_.playing()) return "";
    return protocol().clips.enabled ? "Press Enter to play the clip. "
                                    : "Press Enter to start the stimulus. ";
}

std::string TrialFlow::lapPrompt() const {
    if (!inTrial() || !session_.playing() || session_.lapsDone() >= session_.lapCount()) return "";
    return fmt::format("Lap {} of {} ({}). Press Enter when it is walked. ",
                       session_.lapsDone() + 1, session_.lapCount(),
                       session_.currentLapSilent() ? "silent baseline" : "with sound");
}

std::vector<std::string> TrialFlow::sectionLines(int index) const {
    std::vector<std::string> lines;
    if (index < 0 || index >= static_cast<int>(sections_.size())) return lines;
    const AnswerSection& section = sections_[static_cast<std::size_t>(index)];
    if (section.kind == SectionKind::Scale) return lines;
    lines.push_back(section.prompt);
    for (const auto& option : section.options)
        lines.push_back(fmt::format("  {}. {}", option.letter, option.label));
    return lines;
}

std::string TrialFlow::sectionInputPrompt(int index) const {
    if (index < 0 || index >= static_cast<int>(sections_.size())) return "";
    const AnswerSection& section = sections_[static_cast<std::size_t>(index)];
    if (section.kind != SectionKind::Scale)
        return protocol().clips.enabled ? "letter (r: listen again)> " : "letter> ";
    const Scale& s = *section.scale;
    if (s.anchors.empty())
        return fmt::format("{} [{} {} .. {} {}]> ", s.prompt, s.min, s.minLabel, s.max, s.maxLabel);
    std::string anchors;
    for (const auto& text : anchorTexts(s)) anchors += (anchors.empty() ? "" : ", ") + text;
    return fmt::format("{} [{} .. {}; {}]> ", s.prompt, s.min, s.max, anchors);
}

FlowResult TrialFlow::typeLine(int index, const std::string& line) {
    if (index < 0 || index >= static_cast<int>(sections_.size()))
        return {Refusal::NotInTrial, "no question is asked now"};
    const AnswerSection& section = sections_[static_cast<std::size_t>(index)];
    if (protocol().clips.enabled && line == "r") return replay();
    if (section.kind == SectionKind::Scale) {
        const Scale& s = *section.scale;
        int value = 0;
        std::size_t used = 0;
        try {
            value = std::stoi(line, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != line.size())
            return {Refusal::NotAllowed,
                    fmt::format("expected a whole number from {} to {}", s.min, s.max)};
        return setRating(s.id, value);
    }
    if (line.size() == 1) return choose(section.kind, line[0]);
    if (section.options.empty()) return {Refusal::NotAllowed, "this question has no answer list"};
    return {Refusal::NotAllowed,
            fmt::format("expected one of the letters {}-{} (or 'quit' to interrupt)",
                        section.options.front().letter, section.options.back().letter)};
}

bool TrialFlow::sectionAnswered(int index) const {
    for (const int open : unansweredSections())
        if (open == index) return false;
    return index >= 0 && index < static_cast<int>(sections_.size());
}

std::string TrialFlow::commentPrompt() const {
    return protocol().questions.comment ? "comment (Enter for none)> " : "";
}

std::string TrialFlow::continuePrompt() const {
    switch (session_.phase()) {
    case SessionPhase::Briefing:
        return "Briefing done? Press Enter to start. ";
    case SessionPhase::Break:
        return "Press Enter to continue. ";
    default:
        return "";
    }
}

std::string TrialFlow::pausePrompt() const {
    if (!session_.paused()) return "";
    return fmt::format("PAUSED — {}\nThe trial will be presented again. Fix the sensor, then "
                       "press Enter to resume. ",
                       session_.pauseReason());
}

std::string TrialFlow::noSoundNotice() {
    return "NO SOUND: this session plays nothing (data entry: the answers are typed in as given; "
           "stored with the session).";
}

} // namespace underfoot::experiment
