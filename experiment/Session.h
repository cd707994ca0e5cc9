// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The session state machine: briefing -> practice -> trials (with breaks) -> end.
///
/// It drives a StimulusPlayer (the app wires it to the engine; tests use a fake) and stores
/// every step in the StudyStore: a trial's start (render seed, GRF recording reference) before
/// the stimulus is presented, and its answer in a durable transaction before the next trial.
/// A session of a participant with answered trials resumes at the first unanswered trial.
#include "experiment/Store.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace underfoot::experiment {

/// What the player reports when a stimulus starts.
struct StimulusStart {
    /// The seed the renderer actually uses (replay re-renders with it).
    std::uint64_t renderSeed = 0;
    /// Reference of the recorded ground-reaction-force stream, when the input is recorded.
    std::optional<std::string> grfRecording;
};

/// Plays stimuli described as data. Implementations: the engine (app), a fake (tests), a
/// no-audio player (headless CLI).
class StimulusPlayer {
  public:
    virtual ~StimulusPlayer() = default;
    /// Starts presenting `stimulus`; `plannedSeed` is the plan's proposal for the render seed.
    virtual StimulusStart start(const Stimulus& stimulus, std::uint64_t plannedSeed) = 0;
    /// Stops the current stimulus (no-op when none plays).
    virtual void stop() = 0;
};

/// A player that renders nothing and reports the planned seed (headless runs, simulation).
class SilentPlayer final : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus&, std::uint64_t plannedSeed) override {
        return {plannedSeed, std::nullopt};
    }
    void stop() override {}
};

enum class SessionPhase { Briefing, Practice, Trial, Break, Finished };
const char* toString(SessionPhase phase);

class Session {
  public:
    /// Monotonic seconds (injectable; response times are differences of it).
    using SecondsClock = std::function<double()>;

    /// Opens a session for `participantCode` (a new session row in the store). Throws
    /// StoreError when the participant is unknown, dropped or already complete.
    Session(StudyStore& store, std::string participantCode, StimulusPlayer& player,
            SessionSettings settings, SecondsClock clock = {});
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    SessionPhase phase() const { return phase_; }
    /// Whether the participant already had answered trials when this session opened.
    bool resumed() const { return resumed_; }
    int sessionNumber() const { return sessionNumber_; }
    const ParticipantInfo& participant() const { return participant_; }
    /// The trial being run (Practice / Trial phases).
    const TrialRecord& current() const;
    /// Whether the current trial's stimulus is playing.
    bool playing() const { return playing_; }
    int trialCount() const { return static_cast<int>(trials_.size()); }
    int answeredCount() const;

    /// Briefing -> first trial (practice if any).
    void finishBriefing();
    /// Starts the current trial's stimulus (stored before the player starts).
    void play();
    /// Commits the answer (durably), stops the stimulus and advances. Throws StoreError for an
    /// invalid answer; the trial then stays current and keeps playing.
    void answer(const TrialAnswer& answer);
    /// Break -> next trial.
    void finishBreak();
    /// Stops the stimulus and closes the session as interrupted (resume later).
    void interrupt();

  private:
    void advance();

    StudyStore& store_;
    StimulusPlayer& player_;
    SecondsClock clock_;
    ParticipantInfo participant_;
    std::vector<TrialRecord> trials_;
    std::size_t position_ = 0;
    int sessionNumber_ = 0;
    SessionPhase phase_ = SessionPhase::Briefing;
    bool resumed_ = false;
    bool playing_ = false;
    bool closed_ = false;
    double startedAtS_ = 0.0;
};

} // namespace underfoot::experiment
