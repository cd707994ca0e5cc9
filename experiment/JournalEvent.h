// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The study journal's events: every kind of row the program appends to the `events` table (the
/// append-only journal of experiment/Store.h), with the name stored in its `kind` column, what it
/// means and the fields of its JSON `detail`. Writers name an event only through this enum
/// (StudyStore::journal); StudyStore::events() maps stored names back strictly (a name outside
/// this list is refused, naming the file and the row). docs/reference/store-schema.md lists the
/// same events (tests/experiment/test_journal_events.cpp compares the two); the decision is
/// docs/decisions/journal-event-enum.md.
#include <array>
#include <optional>
#include <string_view>

namespace underfoot::experiment {

enum class JournalEvent {
    StudyCreated,
    SchemaMigrated,
    ParticipantRegistered,
    ParticipantDropped,
    ParticipantCompleted,
    SessionStarted,
    SessionResumed,
    SessionEnded,
    LeaseRecovered,
    LeaseTakenOver,
    BriefingDone,
    TrialStarted,
    TrialRestarted,
    Answered,
    AnswerChanged,
    ClipReplayed,
    LapCompleted,
    TrialInterrupted,
    TrialExcluded,
    TrialIncluded,
    BreakStarted,
    BreakEnded,
    SensorFault,
    SensorRestored,
    Paused,
    Resumed,
    OnlineInvited,
    OnlineRefused,
    OnlineUnavailable,
    OnlineScreeningStarted,
    OnlineScreeningAnswer,
    OnlineScreeningPassed,
    OnlineScreeningFailed,
};

/// One event: its stored name, a one-line meaning and the fields of its detail ("" = `{}`).
struct JournalEventInfo {
    JournalEvent event;
    std::string_view name;
    std::string_view meaning;
    std::string_view fields;
};

/// Every event, in the order of the enum.
inline constexpr std::array<JournalEventInfo, 33> kJournalEvents{{
    {JournalEvent::StudyCreated, "study_created", "the study file was created",
     "code, site, seed, protocol, hash"},
    {JournalEvent::SchemaMigrated, "schema_migrated", "the file was migrated one schema version up",
     "from, to"},
    {JournalEvent::ParticipantRegistered, "participant_registered",
     "a participant was registered, its group assigned and its plan stored",
     "code, index, group, assignment, reason, fields, simulated, trials"},
    {JournalEvent::ParticipantDropped, "participant_dropped",
     "the participant dropped out (its group slot is free again)", "reason"},
    {JournalEvent::ParticipantCompleted, "participant_completed",
     "every trial was answered but the session had not been closed (recovered)", "note"},
    {JournalEvent::SessionStarted, "session_started", "a session of the participant opened",
     "session, experimenter, audio, sensor, sound, app_version"},
    {JournalEvent::SessionResumed, "session_resumed",
     "the session resumed at the first unanswered trial", "session"},
    {JournalEvent::SessionEnded, "session_ended", "the session closed",
     "session, outcome (completed / interrupted)"},
    {JournalEvent::LeaseRecovered, "lease_recovered",
     "the lease of a process that no longer runs was taken back",
     "pid, host, holder, experimenter, since, session"},
    {JournalEvent::LeaseTakenOver, "lease_taken_over",
     "a live or foreign process's lease was taken over on request",
     "pid, host, holder, experimenter, since, session"},
    {JournalEvent::BriefingDone, "briefing_done", "the briefing was finished", "session"},
    {JournalEvent::TrialStarted, "trial_started", "a trial's stimulus started",
     "session, render_seed, grf, clip, clip_sha256"},
    {JournalEvent::TrialRestarted, "trial_restarted",
     "an unanswered trial's stimulus started again",
     "session, render_seed, grf, clip, clip_sha256"},
    {JournalEvent::Answered, "answered", "a trial's answer was committed",
     "answer, ratings, soundscape, comment, response_time_s"},
    {JournalEvent::AnswerChanged, "answer_changed", "a committed answer was replaced",
     "answer, ratings, soundscape, comment, response_time_s"},
    {JournalEvent::ClipReplayed, "clip_replayed", "a listening-test clip was played again",
     "replays"},
    {JournalEvent::LapCompleted, "lap_completed", "a lap of a condition was walked",
     "lap, sound (silent baseline / feedback)"},
    {JournalEvent::TrialInterrupted, "trial_interrupted",
     "a sensor fault interrupted the trial's presentation (it stays unanswered)", "reason"},
    {JournalEvent::TrialExcluded, "trial_excluded", "the experimenter excluded the trial",
     "reason"},
    {JournalEvent::TrialIncluded, "trial_included", "an excluded trial was included again",
     "reason"},
    {JournalEvent::BreakStarted, "break_started", "a break began after the trial", ""},
    {JournalEvent::BreakEnded, "break_ended", "the break ended", ""},
    {JournalEvent::SensorFault, "sensor_fault",
     "a sensor failed between presentations; the session paused", "reason"},
    {JournalEvent::SensorRestored, "sensor_restored", "the sensor is back; the session resumed",
     "fault"},
    {JournalEvent::Paused, "paused", "the experimenter paused the session", ""},
    {JournalEvent::Resumed, "resumed", "the experimenter resumed the session", ""},
    {JournalEvent::OnlineInvited, "online_invited", "invitations to the online test were made",
     "count, first, last, group"},
    {JournalEvent::OnlineRefused, "online_refused", "the web server refused a request",
     "participant, request, status, reason"},
    {JournalEvent::OnlineUnavailable, "online_unavailable",
     "the web server could not open the participant's session (retryable)", "participant, reason"},
    {JournalEvent::OnlineScreeningStarted, "online_screening_started",
     "the server laid out the headphone check from a seed",
     "test, seed, triplets, passMark, minResponseS"},
    {JournalEvent::OnlineScreeningAnswer, "online_screening_answer",
     "one triplet of the headphone check was answered and scored by the server",
     "triplet, choice, correct, secondsSinceTones"},
    {JournalEvent::OnlineScreeningPassed, "online_screening_passed",
     "the participant passed the headphone screening",
     "test, seed, layout, choices, correct, total, passMark"},
    {JournalEvent::OnlineScreeningFailed, "online_screening_failed",
     "the participant failed the headphone screening",
     "test, seed, layout, choices, correct, total, passMark"},
}};

/// The name stored for `event`.
constexpr std::string_view journalEventName(JournalEvent event) {
    return kJournalEvents[static_cast<std::size_t>(event)].name;
}

/// The event stored as `name`, or nullopt for a name outside the list.
constexpr std::optional<JournalEvent> journalEventFromName(std::string_view name) {
    for (const auto& e : kJournalEvents)
        if (e.name == name) return e.event;
    return std::nullopt;
}

// The table is in enum order (journalEventName indexes it).
static_assert([] {
    for (std::size_t i = 0; i < kJournalEvents.size(); ++i)
        if (static_cast<std::size_t>(kJournalEvents[i].event) != i) return false;
    return true;
}());
static_assert(static_cast<std::size_t>(JournalEvent::OnlineScreeningFailed) + 1 ==
              kJournalEvents.size());

} // namespace underfoot::experiment
