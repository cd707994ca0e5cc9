// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/TrialFlow.h"
#include "base/Plural.h"

#include <fmt/format.h>

#include <algorithm>

namespace underfoot::experiment {

namespace {
std::vector<std::string> problemsFor(const Protocol& protocol, const std::string& groupId,
                                     const TrialAnswer& answer,
                                     const std::vector<const Scale*>& asked) {
    std::vector<std::string> problems;
    const Questions& q = protocol.questions;
    if (q.asksSurface()) {
        if (answer.answer.empty())
            problems.push_back("the surface answer is missing");
        else if (!q.surfaceOption(answer.answer))
            problems.push_back(
                fmt::format("'{}' is not an option of the answer list", answer.answer));
    } else if (!answer.answer.empty()) {
        problems.push_back("this protocol asks no surface question");
    }
    for (const Scale* scale : asked) {
        const auto it = answer.ratings.find(scale->id);
        if (it == answer.ratings.end())
            problems.push_back(fmt::format("the rating '{}' is missing", scale->id));
        else if (!ratingInRange(*scale, it->second))
            problems.push_back(fmt::format("rating '{}' is {}; expected {} to {}", scale->id,
                                           it->second, scale->min, scale->max));
    }
    for (const auto& [scaleId, value] : answer.ratings) {
        if (!q.scale(scaleId))
            problems.push_back(fmt::format("unknown scale '{}' (value {})", scaleId, value));
        else if (std::none_of(asked.begin(), asked.end(),
                              [&id = scaleId](const Scale* s) { return s->id == id; }))
            problems.push_back(fmt::format("scale '{}' is not asked in this trial", scaleId));
    }
    if (q.asksSoundscape(groupId)) {
        if (answer.soundscapeAnswer.empty())
            problems.push_back("the soundscape answer is missing");
        else if (!q.soundscapeOption(answer.soundscapeAnswer))
            problems.push_back(fmt::format("'{}' is not an option of the soundscape list",
                                           answer.soundscapeAnswer));
    } else if (!answer.soundscapeAnswer.empty()) {
        problems.push_back("the soundscape question is not asked to this group");
    }
    if (!answer.comment.empty() && !q.comment) problems.push_back("this protocol takes no comment");
    return problems;
}
} // namespace

std::vector<std::string> answerProblems(const Protocol& protocol, const std::string& groupId,
                                        const TrialAnswer& answer, const Stimulus& stimulus,
                                        int block) {
    return problemsFor(protocol, groupId, answer, askedScales(protocol, stimulus, block));
}

std::vector<std::string> answerProblems(const Protocol& protocol, const std::string& groupId,
                                        const TrialAnswer& answer) {
    std::vector<const Scale*> all;
    for (const auto& s : protocol.questions.scales) all.push_back(&s);
    return problemsFor(protocol, groupId, answer, all);
}

bool ratingInRange(const Scale& scale, int value) {
    return value >= scale.min && value <= scale.max;
}

std::string ratingRangeProblem(const Scale& scale, int value) {
    if (ratingInRange(scale, value)) return "";
    return fmt::format("{} is outside the scale {}–{}.", value, scale.min, scale.max);
}

std::string personSessionRefusal(const ParticipantInfo& participant) {
    if (!participant.simulated) return "";
    return fmt::format("participant {} is a simulated participant (made by --simulate); a "
                       "person's session needs a registered participant",
                       participant.code);
}

std::string lockRefusal(const Protocol& protocol, bool laterTrialStarted) {
    if (protocol.lock == LockRule::OnAnswer)
        return "Answers are locked once given (protocol rule lock = \"answer\").";
    if (laterTrialStarted)
        return "The previous answer is locked: a later trial's stimulus has started (protocol "
               "rule lock = \"next_trial\").";
    return "";
}

std::string progressText(int answered, int total) {
    return fmt::format("{} of {} answered", answered, counted(total, "trial"));
}

std::vector<std::string> anchorTexts(const Scale& scale) {
    std::vector<std::string> out;
    for (const auto& [value, wording] : scale.anchors)
        out.push_back(fmt::format("{} = {}", value, wording));
    if (out.empty()) {
        if (!scale.minLabel.empty())
            out.push_back(fmt::format("{} = {}", scale.min, scale.minLabel));
        if (!scale.maxLabel.empty())
            out.push_back(fmt::format("{} = {}", scale.max, scale.maxLabel));
    }
    return out;
}

std::string trialLabel(int index, int count, bool practice) {
    return fmt::format("{} {} of {}", practice ? "Practice trial" : "Trial", index + 1, count);
}

std::string participantTitle(const Protocol& protocol) {
    if (!protocol.participantTitle.empty()) return protocol.participantTitle;
    return protocol.clips.enabled ? "Listening study" : "Study";
}

std::string consentBriefing(const Protocol& protocol) {
    if (!protocol.briefing.empty()) return protocol.briefing;
    if (protocol.clips.enabled)
        return "You will hear short sound clips and answer a few questions about each one.";
    return "You will take part in a short study and answer a few questions after each trial.";
}

TrialFlow::TrialFlow(StudyStore& store, Session& session) : store_(store), session_(session) {
    reset();
}

FlowResult TrialFlow::holdRefusal() const {
    if (session_.paused())
        return {Refusal::Paused,
                fmt::format("paused by a sensor fault: {}", session_.pauseReason())};
    if (held_) return {Refusal::Paused, "paused by the experimenter (resume first)"};
    return {};
}

bool TrialFlow::inTrial() const {
    const SessionPhase p = session_.phase();
    return p == SessionPhase::Trial || p == SessionPhase::Practice;
}

void TrialFlow::reset() {
    refusedDone_ = Refusal::None;
    revising_.reset();
    revisedTrial_.reset();
    draft_ = {};
    pendingDigit_ = -1;
    active_ = 0;
    sections_.clear();
    if (inTrial()) buildSections(session_.current());
}

void TrialFlow::buildSections(const TrialRecord& trial) {
    sections_.clear();
    const Questions& q = protocol().questions;
    if (q.asksSurface()) {
        AnswerSection s;
        s.kind = SectionKind::Surface;
        s.prompt = q.surfacePrompt;
        s.options = q.surfaceOptions;
        sections_.push_back(std::move(s));
    }
    // Only the scales asked after this stimulus in this block.
    for (const Scale* asked : askedScales(protocol(), trial.stimulus, trial.block)) {
        AnswerSection s;
        s.kind = SectionKind::Scale;
        s.prompt = asked->prompt;
        s.scale = asked;
        sections_.push_back(std::move(s));
    }
    if (q.asksSoundscape(session_.participant().groupId)) {
        AnswerSection s;
        s.kind = SectionKind::Soundscape;
        s.prompt = q.soundscapePrompt;
        s.options = q.soundscapeOptions;
        sections_.push_back(std::move(s));
    }
}

int TrialFlow::firstSection(SectionKind kind) const {
    for (std::size_t i = 0; i < sections_.size(); ++i)
        if (sections_[i].kind == kind) return static_cast<int>(i);
    return -1;
}

void TrialFlow::setActive(int index) {
    pendingDigit_ = -1;
    if (sections_.empty()) {
        active_ = 0;
        return;
    }
    active_ = std::clamp(index, 0, static_cast<int>(sections_.size()) - 1);
}

FlowResult TrialFlow::chooseLetter(char letter) {
    if (sections_.empty()) return {Refusal::NotInTrial, "no question is asked now"};
    if (sections_[static_cast<std::size_t>(active_)].kind == SectionKind::Soundscape)
        return choose(SectionKind::Soundscape, letter);
    if (firstSection(SectionKind::Surface) >= 0) return choose(SectionKind::Surface, letter);
    return {Refusal::NotAllowed, "this trial asks no question answered by a letter"};
}

FlowResult TrialFlow::choose(SectionKind kind, char letter) {
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    const int section = firstSection(kind);
    if (section < 0 || kind == SectionKind::Scale)
        return {Refusal::NotAllowed, "this trial does not ask that question"};
    const Questions& q = protocol().questions;
    const char lower =
        static_cast<char>(letter >= 'A' && letter <= 'Z' ? letter - 'A' + 'a' : letter);
    const AnswerOption* o = kind == SectionKind::Surface ? q.surfaceOptionByLetter(lower)
                                                         : q.soundscapeOptionByLetter(lower);
    if (!o) return {Refusal::NotAllowed, fmt::format("No answer has the letter '{}' here.", lower)};
    (kind == SectionKind::Surface ? draft_.answer : draft_.soundscapeAnswer) = o->id;
    setActive(section + 1); // on to the next question
    return {};
}

FlowResult TrialFlow::typeDigit(int digit) {
    if (sections_.empty() || digit < 0 || digit > 9)
        return {Refusal::NotInTrial, "no rating is asked now"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    int section = active_;
    if (sections_[static_cast<std::size_t>(section)].kind != SectionKind::Scale) {
        section = -1;
        for (std::size_t i = 0; i < sections_.size(); ++i)
            if (sections_[i].kind == SectionKind::Scale &&
                !draft_.ratings.count(sections_[i].scale->id)) {
                section = static_cast<int>(i);
                break;
            }
        if (section < 0) return {Refusal::NotAllowed, "every rating of this trial is given"};
        setActive(section);
    }
    const Scale& sc = *sections_[static_cast<std::size_t>(section)].scale;
    int value = digit;
    if (pendingDigit_ >= 0 && pendingDigit_ * 10 + digit <= sc.max)
        value = pendingDigit_ * 10 + digit;
    if (!ratingInRange(sc, value)) {
        pendingDigit_ = -1;
        return {Refusal::OutOfRange, ratingRangeProblem(sc, value)};
    }
    draft_.ratings[sc.id] = value;
    if (value != 0 && value * 10 <= sc.max) {
        pendingDigit_ = value; // a second digit may follow
    } else {
        setActive(section + 1 < static_cast<int>(sections_.size()) ? section + 1 : section);
    }
    return {};
}

void TrialFlow::adjust(int delta) {
    if (sections_.empty() || !holdRefusal()) return;
    const auto& s = sections_[static_cast<std::size_t>(active_)];
    if (s.kind != SectionKind::Scale) return;
    const Scale& sc = *s.scale;
    const auto it = draft_.ratings.find(sc.id);
    const int from = it == draft_.ratings.end() ? (sc.min + sc.max) / 2 - delta : it->second;
    draft_.ratings[sc.id] = std::clamp(from + delta, sc.min, sc.max);
    pendingDigit_ = -1;
}

FlowResult TrialFlow::setRating(const std::string& scaleId, int value) {
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    for (std::size_t i = 0; i < sections_.size(); ++i) {
        const auto& s = sections_[i];
        if (s.kind != SectionKind::Scale || s.scale->id != scaleId) continue;
        if (!ratingInRange(*s.scale, value))
            return {Refusal::OutOfRange, ratingRangeProblem(*s.scale, value)};
        draft_.ratings[scaleId] = value;
        setActive(static_cast<int>(i));
        return {};
    }
    return {Refusal::NotAllowed, fmt::format("scale '{}' is not asked in this trial", scaleId)};
}

std::vector<std::string> TrialFlow::problems() const {
    if (!inTrial()) return {"no trial is current"};
    const TrialRecord& t = revisedTrial_ ? *revisedTrial_ : session_.current();
    return answerProblems(protocol(), session_.participant().groupId, draft_, t.stimulus, t.block);
}

std::vector<int> TrialFlow::unansweredSections() const {
    std::vector<int> open;
    for (std::size_t i = 0; i < sections_.size(); ++i) {
        const AnswerSection& s = sections_[i];
        const bool answered = s.kind == SectionKind::Surface ? !draft_.answer.empty()
                              : s.kind == SectionKind::Soundscape
                                  ? !draft_.soundscapeAnswer.empty()
                                  : draft_.ratings.count(s.scale->id);
        if (!answered) open.push_back(static_cast<int>(i));
    }
    return open;
}

FlowResult TrialFlow::pause() {
    if (!inTrial()) return {Refusal::NotInTrial, "no trial is current"};
    if (held_) return {Refusal::NotAllowed, "the session is paused already"};
    held_ = true; // held even when the journal cannot be written
    try {
        store_.journal(JournalEvent::Paused, session_.participant().code, session_.current().index,
                       "{}");
    } catch (const std::exception& e) {
        return {Refusal::Failed, std::string("paused, but not journaled: ") + e.what()};
    }
    return {};
}

FlowResult TrialFlow::resume() {
    if (!held_) return {Refusal::NotAllowed, "the session is not paused"};
    held_ = false;
    try {
        store_.journal(JournalEvent::Resumed, session_.participant().code,
                       inTrial() ? std::optional<int>(session_.current().index) : std::nullopt,
                       "{}");
    } catch (const std::exception& e) {
        return {Refusal::Failed, std::string("resumed, but not journaled: ") + e.what()};
    }
    return {};
}

FlowResult TrialFlow::start() {
    if (!inTrial()) return {Refusal::NotInTrial, "no trial is current"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (revising_)
        return {Refusal::Locked, "store or cancel the change of the previous answer first"};
    if (session_.playing()) {
        if (protocol().clips.enabled) return replay();
        return {Refusal::AlreadyStarted, "the stimulus is already playing"};
    }
    try {
        session_.play();
    } catch (const std::exception& e) {
        return {Refusal::Failed, e.what()};
    }
    return {};
}

FlowResult TrialFlow::replay() {
    if (!inTrial() || !protocol().clips.enabled)
        return {Refusal::NotAllowed, "only clips of a listening test are replayed"};
    if (!session_.playing()) return start();
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (!protocol().clips.replay)
        return {Refusal::NotAllowed, "This protocol does not allow replaying a clip."};
    try {
        session_.presentClip();
    } catch (const std::exception& e) {
        return {Refusal::Failed, e.what()};
    }
    return {};
}

FlowResult TrialFlow::completeLap() {
    if (!inTrial()) return {Refusal::NotInTrial, "no trial is current"};
    const int total = session_.lapCount();
    if (total == 0) return {Refusal::NotAllowed, "this protocol has no laps"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (!session_.playing())
        return {Refusal::NotStarted, "Start the condition first, then complete each lap."};
    if (session_.lapsDone() >= total)
        return {Refusal::NotAllowed,
                fmt::format("All {} laps are done; enter the answers and commit them.", total)};
    try {
        session_.completeLap();
    } catch (const std::exception& e) {
        return {Refusal::Failed, e.what()};
    }
    return {};
}

FlowResult TrialFlow::commit() {
    if (revising_) return commitRevision();
    if (!inTrial()) return {Refusal::NotInTrial, "no trial is current"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (!session_.playing())
        return {Refusal::NotStarted,
                "Start the stimulus first; the answer belongs to what was heard."};
    if (session_.lapCount() > 0 && session_.lapsDone() < session_.lapCount())
        return {Refusal::LapsPending,
                fmt::format("Lap {} of {} is being walked: the questions come after the last lap.",
                            session_.lapsDone() + 1, session_.lapCount())};
    const auto missing = problems();
    if (!missing.empty()) {
        std::string list;
        for (const auto& p : missing) list += (list.empty() ? "" : "; ") + p;
        refusedDone_ = Refusal::Incomplete;
        return {Refusal::Incomplete, list};
    }
    try {
        session_.answer(draft_);
    } catch (const std::exception& e) {
        if (session_.paused()) return {Refusal::Paused, e.what()};
        refusedDone_ = Refusal::Failed;
        return {Refusal::Failed, e.what()};
    }
    reset();
    return {};
}

FlowResult TrialFlow::submit(const TrialAnswer& answer) {
    if (revising_)
        return {Refusal::Locked, "store or cancel the change of the previous answer first"};
    draft_ = answer;
    pendingDigit_ = -1;
    return commit();
}

bool TrialFlow::laterTrialStarted(int index) const {
    if (session_.playing()) return true;
    for (const auto& t : store_.trials(session_.participant().code))
        if (t.index > index && !t.startedAt.empty()) return true; // this session's or earlier
    return false;
}

FlowResult TrialFlow::revisePrevious() {
    if (!inTrial()) return {Refusal::NotInTrial, "no trial is current"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (const std::string why = lockRefusal(protocol(), session_.playing()); !why.empty())
        return {Refusal::Locked, why};
    const int current = session_.current().index;
    std::optional<TrialRecord> previous;
    for (auto& t : store_.trials(session_.participant().code))
        if (t.answered && t.index < current && (!previous || t.index > previous->index))
            previous = std::move(t);
    if (!previous) return {Refusal::NoPrevious, "No earlier answer in this session to change."};
    if (const std::string why = lockRefusal(protocol(), laterTrialStarted(previous->index));
        !why.empty())
        return {Refusal::Locked, why};
    draft_ = previous->answer;
    pendingDigit_ = -1;
    revising_ = previous->index;
    revisedTrial_ = previous;
    buildSections(*revisedTrial_);
    setActive(0);
    return {};
}

FlowResult TrialFlow::commitRevision() {
    if (!revising_) return {Refusal::NotAllowed, "no answer is being changed"};
    if (const FlowResult hold = holdRefusal(); !hold) return hold;
    if (const std::string why = lockRefusal(protocol(), laterTrialStarted(*revising_));
        !why.empty())
        return {Refusal::Locked, why};
    if (const auto missing = problems(); !missing.empty()) {
        std::string list;
        for (const auto& p : missing) list += (list.empty() ? "" : "; ") + p;
        return {Refusal::Incomplete, list};
    }
    try {
        store_.commitAnswer(session_.participant().code, *revising_, draft_,
                            revisedTrial_->responseTimeS);
    } catch (const AnswerSavedButNotCopied& e) {
        reset(); // the change is stored; only the copy into the study file failed
        return {Refusal::Failed, e.what()};
    } catch (const std::exception& e) {
        return {Refusal::Failed, e.what()};
    }
    reset();
    return {};
}

void TrialFlow::cancelRevision() {
    reset();
}

std::optional<int> TrialFlow::exclusionTarget(bool previous, std::string* why) const {
    if (previous) {
        int index = -1;
        for (const auto& t : store_.trials(session_.participant().code))
            if (t.answered) index = std::max(index, t.index);
        if (index < 0) {
            if (why) *why = "No trial has been answered yet in this session.";
            return std::nullopt;
        }
        return index;
    }
    if (!inTrial()) {
        if (why) *why = "No trial is current.";
        return std::nullopt;
    }
    return session_.current().index;
}

std::vector<std::string> TrialFlow::experimenterStatus() const {
    std::vector<std::string> lines;
    if (!inTrial()) return lines;
    const Protocol& p = protocol();
    if (p.clips.enabled) {
        if (!session_.playing())
            lines.push_back("Clip not presented yet — Space plays it.");
        else
            lines.push_back(p.clips.replay ? fmt::format("Clip presented · replays: {}  (Space or "
                                                         "R replays)",
                                                         session_.replayCount())
                                           : "Clip presented · replay not allowed by the protocol");
    }
    if (session_.lapCount() > 0) {
        const int done = session_.lapsDone();
        const int total = session_.lapCount();
        if (!session_.playing())
            lines.push_back(
                fmt::format("Laps: 0 of {} · press Space when the participant sets off", total));
        else if (done >= total)
            lines.push_back(fmt::format("Laps: {0} of {0} done · ask the questions now", total));
        else
            lines.push_back(
                fmt::format("Lap {} of {} · {}  (L completes the lap)", done + 1, total,
                            session_.currentLapSilent() ? "SILENT baseline" : "WITH SOUND"));
    }
    return lines;
}

bool TrialFlow::silentLapNow() const {
    return inTrial() && session_.lapCount() > 0 && session_.playing() &&
           session_.lapsDone() < session_.lapCount() && session_.currentLapSilent();
}

std::string TrialFlow::participantBriefing() const {
    const Protocol& p = protocol();
    const Questions& q = p.questions;
    int practice = 0;
    int total = 0;
    for (const auto& t : store_.trials(session_.participant().code)) {
        ++total;
        practice += t.practice ? 1 : 0;
    }
    std::string text;
    if (!p.briefing.empty()) text += p.briefing + "\n\n";
    if (p.clips.enabled)
        text += fmt::format("You will hear {} sound clips{}.", total,
                            practice ? fmt::format(" ({} for practice first)", practice) : "");
    else if (p.laps.total() > 0)
        text += fmt::format(
            "You will walk {} conditions{}. In each one you walk {} laps{}; the questions come "
            "after the last lap.",
            total, practice ? fmt::format(" ({} for practice first)", practice) : "",
            p.laps.total(),
            p.laps.baseline > 0 ? fmt::format(": the first {} without sound, then {} with sound",
                                              p.laps.baseline, p.laps.feedback)
                                : "");
    else
        text += fmt::format("There {} {}{}.", total == 1 ? "is" : "are", counted(total, "trial"),
                            practice ? fmt::format(" ({} for practice first)", practice) : "");
    std::vector<std::string> asked;
    if (q.asksSurface()) asked.push_back(q.surfacePrompt);
    for (const auto& s : q.scales) asked.push_back(s.prompt);
    if (q.asksSoundscape(session_.participant().groupId)) asked.push_back(q.soundscapePrompt);
    if (!asked.empty()) {
        text += "\n\nAfter each one you will be asked:";
        for (const auto& a : asked) text += "\n  • " + a;
    }
    if (p.clips.enabled && p.clips.replay) text += "\n\nYou may listen to a clip again.";
    if (p.ordering.breakEvery > 0)
        text +=
            p.ordering.breakEvery == 1
                ? std::string("\n\nThere is a break after every trial.")
                : fmt::format("\n\nThere is a break after every {} trials.", p.ordering.breakEvery);
    text += "\n\nThere are no right or wrong answers: answer what you perceive.";
    return text;
}

ParticipantScreen TrialFlow::participantScreen() const {
    ParticipantScreen s;
    s.total = session_.trialCount();
    s.answered = session_.answeredCount();
    switch (session_.phase()) {
    case SessionPhase::Briefing:
        s.page = ParticipantScreen::Page::Briefing;
        s.heading = "Welcome";
        s.text = participantBriefing();
        return s;
    case SessionPhase::Break:
        s.page = ParticipantScreen::Page::Break;
        s.heading = "Break";
        s.text = fmt::format("{} of {} done. Please rest; the experimenter will continue.",
                             s.answered, counted(s.total, "trial"));
        return s;
    case SessionPhase::Finished:
        s.page = ParticipantScreen::Page::Finished;
        s.heading = "Thank you";
        s.text = "The session is over. Thank you for taking part.";
        return s;
    case SessionPhase::Practice:
    case SessionPhase::Trial:
        break;
    }
    const TrialRecord& t = session_.current();
    s.page = ParticipantScreen::Page::Trial;
    s.heading = trialLabel(t.index, s.total, t.practice);
    if (protocol().ordering.blocks == BlockKind::Scale && !t.practice) {
        const auto asked = askedScales(protocol(), t.stimulus, t.block);
        if (!asked.empty())
            s.part = fmt::format("Part {} of {}: {}", t.block, protocol().questions.scales.size(),
                                 asked.front()->prompt);
    }
    s.sections = sections_;
    s.activeSection = active_;
    s.draft = draft_;
    const Protocol& p = protocol();
    if (!holdRefusal()) {
        s.text = "Please wait a moment.";
    } else if (!session_.playing()) {
        s.text = p.laps.total() > 0 ? "Please wait: the experimenter starts the condition."
                                    : "Please wait for the sound.";
    } else if (session_.lapCount() > 0 && session_.lapsDone() < session_.lapCount()) {
        s.text =
            fmt::format("Lap {} of {}: please walk.", session_.lapsDone() + 1, session_.lapCount());
    } else {
        s.answering = true;
        s.replayOffered = p.clips.enabled && p.clips.replay;
        s.text = s.replayOffered ? "Please answer. You may listen again." : "Please answer.";
    }
    if (refusedDone_ == Refusal::Incomplete) {
        s.unanswered = unansweredSections();
        if (s.unanswered.size() == 1)
            s.notice = "Please answer this question first: " +
                       sections_[static_cast<std::size_t>(s.unanswered.front())].prompt;
        else if (!s.unanswered.empty())
            s.notice = fmt::format("Please answer the {} questions still open first.",
                                   s.unanswered.size());
    } else if (refusedDone_ == Refusal::Failed) {
        s.notice = "Your answer could not be saved yet. Please wait for the experimenter.";
    }
    return s;
}

} // namespace underfoot::experiment
