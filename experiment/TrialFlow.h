// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The trial core: what a participant sees and may answer in one trial, on top of
/// experiment::Session, for every front end (the terminal session, the console's Run view and
/// participant window, the web API and simulated participants):
///
/// - the answer being entered for the current trial: its sections (surface question, the scales
///   asked in this trial's block, soundscape question), the active section, letters, digits
///   (two-digit values on 0–10 scales), Left/Right adjustments;
/// - its validation before commit (stimulus started, every lap walked, answerProblems) and the
///   commit itself: the only check of an answer against the protocol (the store checks only its
///   schema), which every writer of answers goes through (terminal, console, participant window,
///   web API, simulated participants);
/// - the lock rule (changing the previous answer only under lock = "next_trial" and before the
///   next stimulus starts), replay counts of listening-test clips and laps;
/// - what the participant may see (ParticipantScreen: a neutral briefing made from the
///   questions, the question, the answer list, the scales with their anchors, progress and
///   breaks, why Done was refused) as opposed to what only the experimenter sees (stimulus,
///   order, notes);
/// - the experimenter's pause (journaled), which holds the draft, the stimulus and commits.
///
/// Trial numbers for people are 1-based ("Trial 3 of 40" is the trial stored with index 2).
/// No Qt, no engine: the front ends map their keys to the calls below.
#include "experiment/Session.h"

#include <optional>
#include <string>
#include <vector>

namespace underfoot::experiment {

enum class SectionKind { Surface, Scale, Soundscape };

/// One question of the current trial as shown to whoever answers it.
struct AnswerSection {
    SectionKind kind = SectionKind::Surface;
    /// The protocol's prompt ("Which surface are you walking on?", the scale's prompt).
    std::string prompt;
    /// Answer list (Surface / Soundscape sections), with their letters.
    std::vector<AnswerOption> options;
    /// The scale (Scale sections; points into the protocol, which outlives the flow).
    const Scale* scale = nullptr;
};

/// Why an action was refused (None: done).
enum class Refusal {
    None,
    NotInTrial,     ///< no trial is current (briefing, break, finished, no session)
    Paused,         ///< paused by a sensor fault
    NotStarted,     ///< the stimulus has not started
    AlreadyStarted, ///< the stimulus is already playing
    LapsPending,    ///< laps still to walk before the questions
    Incomplete,     ///< the answer is missing something (answerProblems)
    Locked,         ///< the protocol's lock rule forbids the change
    NoPrevious,     ///< no earlier answer to change
    NotAllowed,     ///< the protocol does not allow it (replay = false, no laps, no such letter)
    OutOfRange,     ///< a rating outside its scale
    Failed,         ///< the store or the player failed (message says why)
};

struct FlowResult {
    Refusal refusal = Refusal::None;
    std::string message;
    explicit operator bool() const { return refusal == Refusal::None; }
};

// The trial core's rules, as free functions for every front end (one copy each). The store does
// not call them: it keeps only its schema's constraints.

/// What is wrong with `answer` to a trial of `stimulus` in `block` for a participant of
/// `groupId` (empty: valid): the surface answer from the answer list, exactly the scales asked
/// after that stimulus in that block, each within its range, the soundscape answer when the
/// group is asked, a comment only when the protocol takes one.
std::vector<std::string> answerProblems(const Protocol& protocol, const std::string& groupId,
                                        const TrialAnswer& answer, const Stimulus& stimulus,
                                        int block);
/// The same against every scale of the protocol (an answer without its trial).
std::vector<std::string> answerProblems(const Protocol& protocol, const std::string& groupId,
                                        const TrialAnswer& answer);
/// Whether `value` lies on `scale` (min..max inclusive).
bool ratingInRange(const Scale& scale, int value);
/// "12 is outside the scale 0–10." (empty when it lies on the scale).
std::string ratingRangeProblem(const Scale& scale, int value);
/// Why `participant` cannot have a person's session (a simulated participant of `session
/// --simulate` never gets one), or "" when it can.
std::string personSessionRefusal(const ParticipantInfo& participant);
/// The lock rule: why an answer already given may not be changed now ("" when it may). Under
/// lock = "answer" never; under lock = "next_trial" until a later trial's stimulus starts.
/// TrialFlow asks it before it offers the change and again before it stores it.
std::string lockRefusal(const Protocol& protocol, bool laterTrialStarted);
/// "12 of 40 trials answered" (the progress line of every front end).
std::string progressText(int answered, int total);

/// Every anchor of a scale as "value = wording" (min and max labels when it has no anchors).
std::vector<std::string> anchorTexts(const Scale& scale);

/// "Trial 3 of 40" / "Practice trial 1 of 40" (1-based; `index` is the stored 0-based index).
std::string trialLabel(int index, int count, bool practice);

/// The title participants see: the protocol's participant_title, else "Listening study" for
/// listening tests and "Study" otherwise (never the study's own title, which may name the design).
std::string participantTitle(const Protocol& protocol);

/// What a participant reads before registering (the web consent page): the protocol's briefing,
/// else a neutral sentence made from the kind of test.
std::string consentBriefing(const Protocol& protocol);

/// What the participant's screen may show. Built only from the protocol's questions, the
/// session's progress and the participant's own draft: never the stimulus (its id, surface,
/// soundscape, input), the order of the plan, the group or the experimenter's notes.
struct ParticipantScreen {
    enum class Page { Waiting, Briefing, Trial, Break, Finished };
    Page page = Page::Waiting;
    /// "Trial 3 of 40", "Break", "Thank you".
    std::string heading;
    /// Briefing / break / end text, or what to do now in a trial ("Listen.", "Lap 2 of 6").
    std::string text;
    /// The questions of the current trial (Trial page).
    std::vector<AnswerSection> sections;
    int activeSection = 0;
    /// The participant's answer so far (highlights).
    TrialAnswer draft;
    /// Whether answers can be given now (stimulus started, laps walked, not paused).
    bool answering = false;
    /// Answered and planned trials of this participant (progress bar).
    int answered = 0;
    int total = 0;
    /// Why the last Done was refused, in words the participant may read (made only from the
    /// protocol's prompts: the open question's, or how many are open); empty when nothing was
    /// refused or the answer has been completed since.
    std::string notice;
    /// The sections still without an answer after a refused Done (indices into `sections`).
    std::vector<int> unanswered;
    /// Whether the participant may ask to hear the clip again now.
    bool replayOffered = false;
    /// The part of the session this trial belongs to when the protocol asks one scale per
    /// block ("Part 2 of 4: How deep is the water?"); empty otherwise. Front ends show it when
    /// it changes.
    std::string part;
};

class TrialFlow {
  public:
    /// `store` must be the store `session` writes to; both outlive the flow.
    TrialFlow(StudyStore& store, Session& session);

    Session& session() const { return session_; }
    const Protocol& protocol() const { return store_.protocol(); }

    /// Starts a fresh draft for the session's current trial (call after every phase change;
    /// answer() does it itself). Outside a trial the draft has no sections.
    void reset();

    // The draft.
    const std::vector<AnswerSection>& sections() const { return sections_; }
    int activeSection() const { return active_; }
    /// Activates section `index` (clamped) and forgets a pending first digit.
    void setActive(int index);
    const TrialAnswer& draft() const { return draft_; }
    void setComment(const std::string& comment) { draft_.comment = comment; }
    /// A letter typed by whoever answers: the soundscape option when the soundscape section is
    /// active, else the surface option. Moves on to the next section.
    FlowResult chooseLetter(char letter);
    /// The option with `letter` in the first section of `kind` (pointer clicks).
    FlowResult choose(SectionKind kind, char letter);
    /// A digit for the active scale (or the first scale without a rating): "1" then "0" gives
    /// 10 on a 0–10 scale; a complete value moves on to the next section.
    FlowResult typeDigit(int digit);
    /// Lowers (-1) or raises (+1) the active scale's rating (starts in its middle).
    void adjust(int delta);
    /// Sets a rating directly (pointer clicks); refuses scales not asked here or out of range.
    FlowResult setRating(const std::string& scaleId, int value);
    /// What is still missing before the draft can be committed (empty: it can).
    std::vector<std::string> problems() const;
    /// The sections of the draft without an answer yet (indices into sections()).
    std::vector<int> unansweredSections() const;

    // The experimenter's pause: while held (as while a sensor fault pauses the session), the
    // draft, the stimulus, laps and commits are refused (Refusal::Paused) and the participant
    // reads "Please wait a moment."; both ends are journaled ("paused", "resumed") with the
    // current trial. It outlives reset().

    /// Holds the session (refused outside a trial or when already held). When the journal
    /// cannot be written the session is held all the same and Refusal::Failed says so.
    FlowResult pause();
    /// Releases it (refused when not held; released all the same when not journaled).
    FlowResult resume();
    bool held() const { return held_; }

    // The session's actions, refused with a reason instead of throwing.

    /// Starts the stimulus; for listening tests a second call replays the clip (counted).
    FlowResult start();
    /// Replays the current clip (listening tests, [clips] replay = true).
    FlowResult replay();
    /// Completes the lap being walked ([laps]).
    FlowResult completeLap();
    /// Validates and commits the draft (durably) and moves on; a fresh draft follows.
    FlowResult commit();
    /// Takes `answer` as the whole draft and commits it like commit() (the same checks): the
    /// path of answerers that give every question at once (simulated participants).
    FlowResult submit(const TrialAnswer& answer);

    // Changing the previous answer (lock rule).

    /// Loads the previous answered trial's answer as the draft (only under lock = "next_trial"
    /// and before the current stimulus starts).
    FlowResult revisePrevious();
    /// The stored index of the trial being changed, or nullopt.
    std::optional<int> revising() const { return revising_; }
    /// Stores the changed answer (validated against that trial) and returns to the current trial.
    FlowResult commitRevision();
    /// Drops the change and returns to the current trial's fresh draft.
    void cancelRevision();

    /// The stored index of the trial to exclude: the current one, or with `previous` the last
    /// answered one (nullopt with the reason in `why`).
    std::optional<int> exclusionTarget(bool previous, std::string* why = nullptr) const;

    /// The experimenter's clip / lap lines ("Clip presented · replays: 2", "Lap 2 of 6 · SILENT
    /// baseline"); empty outside listening tests and lap protocols.
    std::vector<std::string> experimenterStatus() const;
    /// Whether the current lap is a silent baseline lap being walked.
    bool silentLapNow() const;

    // A text front end (the terminal): what it prints and asks, and how a typed line is read
    // (TrialFlowText.cpp). The terminal prints these and forwards the lines typed.

    /// "Press Enter to play the clip. " / "Press Enter to start the stimulus. " while the current
    /// trial's stimulus has not started; "" otherwise.
    std::string startPrompt() const;
    /// "Lap 2 of 6 (silent baseline). Press Enter when it is walked. " while a lap of the current
    /// condition is being walked; "" when none is (no laps, not started, every lap walked).
    std::string lapPrompt() const;
    /// The lines printed before section `index` is asked: an answer list's prompt and options
    /// ("  a. Wood"); none for a scale (its prompt is the input prompt).
    std::vector<std::string> sectionLines(int index) const;
    /// The input prompt of section `index` ("Realism [1 not at all .. 7 completely]> ",
    /// "letter> ", "letter (r: listen again)> ").
    std::string sectionInputPrompt(int index) const;
    /// One typed line for section `index`: a letter of its answer list, a whole number on its
    /// scale, or "r" to hear a listening-test clip again. Refused with what was expected.
    FlowResult typeLine(int index, const std::string& line);
    /// Whether section `index` of the draft has its answer.
    bool sectionAnswered(int index) const;
    /// "comment (Enter for none)> " when the protocol takes a comment, else "".
    std::string commentPrompt() const;
    /// "Briefing done? Press Enter to start. " on the briefing page, "Press Enter to continue. "
    /// on a break; "" otherwise.
    std::string continuePrompt() const;
    /// "PAUSED — <why>\nThe trial will be presented again. Fix the sensor, then press Enter to
    /// resume. " while a sensor fault pauses the session; "" otherwise.
    std::string pausePrompt() const;
    /// What a session that plays nothing says at its start: "NO SOUND: this session plays
    /// nothing (data entry: the answers are typed in as given; stored with the session)."
    static std::string noSoundNotice();

    /// What the participant's screen shows now.
    ParticipantScreen participantScreen() const;
    /// The briefing for the participant, made from the protocol's questions and ordering.
    std::string participantBriefing() const;

  private:
    bool inTrial() const;
    /// Refusal::Paused while a sensor fault or the experimenter holds the session.
    FlowResult holdRefusal() const;
    void buildSections(const TrialRecord& trial);
    int firstSection(SectionKind kind) const;
    /// Whether a trial after stored index `index` has started (the lock rule's "next trial"):
    /// the current stimulus, or any later trial started in this or an earlier session.
    bool laterTrialStarted(int index) const;

    StudyStore& store_;
    Session& session_;
    std::vector<AnswerSection> sections_;
    int active_ = 0;
    int pendingDigit_ = -1;
    TrialAnswer draft_;
    std::optional<int> revising_;
    std::optional<TrialRecord> revisedTrial_; ///< the trial being changed (its stimulus, block)
    bool held_ = false;
    /// The last commit was refused: Incomplete (the screen lists the open questions) or Failed.
    Refusal refusedDone_ = Refusal::None;
};

} // namespace underfoot::experiment
