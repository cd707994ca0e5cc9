// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Session.h"

#include "experiment/TrialFlow.h"

#include <fmt/format.h>

#include <chrono>

namespace underfoot::experiment {

const char* toString(SessionPhase phase) {
    switch (phase) {
    case SessionPhase::Briefing:
        return "briefing";
    case SessionPhase::Practice:
        return "practice";
    case SessionPhase::Trial:
        return "trial";
    case SessionPhase::Break:
        return "break";
    case SessionPhase::Finished:
        return "finished";
    }
    return "finished";
}

Session::Session(StudyStore& store, std::string participantCode, StimulusPlayer& player,
                 SessionSettings settings, SecondsClock clock)
    : store_(store), player_(player), clock_(std::move(clock)) {
    if (!clock_) {
        clock_ = [] {
            return std::chrono::duration<double>(
                       std::chrono::steady_clock::now().time_since_epoch())
                .count();
        };
    }
    participant_ = store_.participant(participantCode);
    trials_ = store_.trials(participantCode);
    const auto first = store_.firstUnanswered(participantCode);
    if (!first) {
        if (participant_.status == ParticipantStatus::Active ||
            participant_.status == ParticipantStatus::Registered)
            store_.markCompleted(participantCode);
        throw StoreError(fmt::format("participant '{}' has answered every trial", participantCode));
    }
    sessionNumber_ = store_.startSession(participantCode, settings);
    participant_ = store_.participant(participantCode);
    position_ = static_cast<std::size_t>(*first);
    resumed_ = *first > 0;
    if (resumed_) {
        store_.journal(JournalEvent::SessionResumed, participantCode, *first,
                       jsonObject({{"session", std::to_string(sessionNumber_)}}));
        phase_ = trials_[position_].practice ? SessionPhase::Practice : SessionPhase::Trial;
    }
}

Session::~Session() {
    if (playing_) player_.stop();
}

const TrialRecord& Session::current() const {
    if (phase_ != SessionPhase::Practice && phase_ != SessionPhase::Trial)
        throw std::logic_error(fmt::format("no current trial in phase {}", toString(phase_)));
    return trials_[position_];
}

int Session::answeredCount() const {
    int n = 0;
    for (const auto& t : trials_) n += t.answered ? 1 : 0;
    return n;
}

void Session::finishBriefing() {
    if (phase_ != SessionPhase::Briefing)
        throw std::logic_error(fmt::format("finishBriefing() in phase {}", toString(phase_)));
    store_.journal(JournalEvent::BriefingDone, participant_.code, std::nullopt,
                   jsonObject({{"session", std::to_string(sessionNumber_)}}));
    phase_ = trials_[position_].practice ? SessionPhase::Practice : SessionPhase::Trial;
}

void Session::play() {
    const TrialRecord& t = current();
    if (playing_) throw std::logic_error("play() while the stimulus is already playing");
    if (paused_)
        throw std::logic_error(
            fmt::format("play() while paused by a sensor fault ({})", pauseReason_));
    if (closed_) throw std::logic_error("play() on a closed session");
    const Protocol& protocol = store_.protocol();
    if (protocol.laps.total() > 0) player_.setMuted(protocol.laps.silent(t.lapsDone + 1));
    const StimulusStart started = player_.start(t.stimulus, t.plannedSeed);
    playing_ = true;
    try {
        store_.markTrialStarted(participant_.code, t.index, sessionNumber_, started.renderSeed,
                                started.grfRecording, started.clip);
    } catch (...) {
        player_.stop();
        playing_ = false;
        throw;
    }
    if (started.sensorLog) {
        try {
            store_.setSensorLog(participant_.code, t.index, *started.sensorLog);
        } catch (...) {
            player_.stop();
            playing_ = false;
            throw;
        }
    }
    trials_[position_].sensorLog = started.sensorLog;
    trials_[position_].audio.reset();
    trials_[position_].renderSeed = started.renderSeed;
    trials_[position_].grfRecording = started.grfRecording;
    trials_[position_].sessionNumber = sessionNumber_;
    startedAtS_ = clock_();
}

void Session::answer(const TrialAnswer& answer) {
    const TrialRecord& t = current();
    if (!playing_)
        throw std::logic_error(
            fmt::format("answer() for trial {} before its stimulus played", t.index + 1));
    const double rt = clock_() - startedAtS_;
    // A sensor that failed since the last check makes the presentation broken: pause instead.
    if (const auto fault = player_.sensorFault()) {
        sensorFault(*fault);
        throw StoreError(fmt::format("participant '{}' trial {}: not recorded, the sensor "
                                     "failed ({}); the session is paused",
                                     participant_.code, t.index + 1, *fault));
    }
    const auto recorded = [&] {
        stopPlayer();
        trials_[position_].answered = true;
        trials_[position_].answer = answer;
        trials_[position_].responseTimeS = rt;
        advance();
    };
    try {
        store_.commitAnswer(participant_.code, t.index, answer, rt >= 0.0 ? rt : 0.0);
    } catch (const AnswerSavedButNotCopied&) {
        recorded(); // stored: move on, then let the view show the warning
        throw;
    }
    recorded();
}

void Session::advance() {
    const bool breakNow = trials_[position_].breakAfter;
    ++position_;
    while (position_ < trials_.size() && trials_[position_].answered) ++position_;
    if (position_ >= trials_.size()) {
        phase_ = SessionPhase::Finished;
        store_.endSession(participant_.code, sessionNumber_, true);
        closed_ = true;
        return;
    }
    if (breakNow) {
        phase_ = SessionPhase::Break;
        store_.journal(JournalEvent::BreakStarted, participant_.code, trials_[position_ - 1].index,
                       "{}");
        return;
    }
    phase_ = trials_[position_].practice ? SessionPhase::Practice : SessionPhase::Trial;
}

void Session::finishBreak() {
    if (phase_ != SessionPhase::Break)
        throw std::logic_error(fmt::format("finishBreak() in phase {}", toString(phase_)));
    store_.journal(JournalEvent::BreakEnded, participant_.code, std::nullopt, "{}");
    phase_ = trials_[position_].practice ? SessionPhase::Practice : SessionPhase::Trial;
}

void Session::stopPlayer() {
    if (!playing_) return;
    playing_ = false;
    player_.stop();
    if (const auto stats = player_.stoppedTrialStats()) {
        store_.recordTrialAudio(participant_.code, trials_[position_].index, *stats);
        trials_[position_].audio = stats;
    }
}

void Session::sensorFault(const std::string& reason) {
    if (paused_ || closed_) return;
    if (phase_ != SessionPhase::Practice && phase_ != SessionPhase::Trial) return;
    const TrialRecord& t = trials_[position_];
    const bool wasPlaying = playing_;
    try {
        stopPlayer();
    } catch (...) {
        playing_ = false; // a failed recording is part of the broken presentation
    }
    paused_ = true;
    pauseReason_ = reason.empty() ? "sensor fault" : reason;
    if (wasPlaying) {
        store_.markTrialInterrupted(participant_.code, t.index, pauseReason_);
        ++trials_[position_].interruptions;
        trials_[position_].interruptionReason = pauseReason_;
    } else {
        store_.journal(JournalEvent::SensorFault, participant_.code, t.index,
                       jsonObject({{"reason", pauseReason_}}));
    }
}

bool Session::checkSensors() {
    if (!paused_ && playing_)
        if (const auto fault = player_.sensorFault()) sensorFault(*fault);
    return paused_;
}

void Session::resumeAfterFault() {
    if (!paused_) return;
    if (const auto fault = player_.sensorFault())
        throw std::logic_error(fmt::format("the sensor still fails: {}", *fault));
    store_.journal(JournalEvent::SensorRestored, participant_.code, trials_[position_].index,
                   jsonObject({{"fault", pauseReason_}}));
    paused_ = false;
    pauseReason_.clear();
}

void Session::interrupt() {
    if (closed_) return;
    try {
        stopPlayer();
    } catch (...) {
        playing_ = false;
    }
    store_.endSession(participant_.code, sessionNumber_, false);
    closed_ = true;
    phase_ = SessionPhase::Finished;
}

} // namespace underfoot::experiment

namespace underfoot::experiment {

std::vector<const Scale*> Session::askedScales() const {
    const TrialRecord& t = current();
    return experiment::askedScales(store_.protocol(), t.stimulus, t.block);
}

void Session::presentClip() {
    const TrialRecord& t = current();
    if (!playing_) {
        play();
        return;
    }
    store_.recordReplay(participant_.code, t.index);
    player_.stop();
    player_.start(t.stimulus, t.renderSeed.value_or(t.plannedSeed));
    ++trials_[position_].replays;
}

int Session::replayCount() const {
    return current().replays;
}

int Session::lapCount() const {
    return store_.protocol().laps.total();
}

int Session::lapsDone() const {
    return current().lapsDone;
}

bool Session::currentLapSilent() const {
    return store_.protocol().laps.silent(current().lapsDone + 1);
}

void Session::completeLap() {
    const TrialRecord& t = current();
    const Laps& laps = store_.protocol().laps;
    if (laps.total() == 0) throw std::logic_error("completeLap() in a protocol without [laps]");
    if (!playing_)
        throw std::logic_error(
            fmt::format("completeLap() for trial {} before its condition started", t.index + 1));
    if (t.lapsDone >= laps.total())
        throw std::logic_error(fmt::format("completeLap(): all {} laps of trial {} are done",
                                           laps.total(), t.index + 1));
    store_.recordLap(participant_.code, t.index, t.lapsDone + 1);
    const int done = ++trials_[position_].lapsDone;
    if (done < laps.total() && laps.silent(done) != laps.silent(done + 1))
        player_.setMuted(laps.silent(done + 1)); // baseline over: the sound comes on
}

} // namespace underfoot::experiment
