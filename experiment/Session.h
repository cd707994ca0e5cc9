// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The session state machine: briefing -> practice -> trials (with breaks) -> end.
///
/// It drives a StimulusPlayer (the app wires it to the engine; tests use a fake) and stores
/// every step in the StudyStore: a trial's start (render seed, GRF recording reference) as soon
/// as the player has started the stimulus (which is stopped again if that write fails), and its
/// answer in a durable transaction before the next trial.
/// A session of a participant with answered trials resumes at the first unanswered trial.
#include "experiment/Store.h"

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

namespace underfoot::experiment {

/// What the player reports when a stimulus starts.
struct StimulusStart {
    /// The seed the renderer actually uses (replay re-renders with it).
    std::uint64_t renderSeed = 0;
    /// Reference of the recorded ground-reaction-force stream, when the input is recorded.
    std::optional<std::string> grfRecording;
    /// Reference of the trial's sensor log (frames, step events, GRFs), when one is written.
    std::optional<std::string> sensorLog = std::nullopt;
    /// The clip presented (listening tests): stored with the trial for replay.
    std::optional<PlayedClip> clip = std::nullopt;
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
    /// Mutes or unmutes the running stimulus (silent baseline laps keep the simulation running
    /// without sound). The default does nothing (players without a live output).
    virtual void setMuted(bool muted) { (void)muted; }
    /// The audio figures of the stimulus stopped last (valid after stop()); players without a
    /// live output report none (the default).
    virtual std::optional<TrialAudioStats> stoppedTrialStats() const { return std::nullopt; }
    /// Why the sensors driving the running stimulus cannot be recorded now (unplugged, silent,
    /// garbage...), or nullopt when they can or the stimulus uses no sensor (the default). Any
    /// thread may call it.
    virtual std::optional<std::string> sensorFault() const { return std::nullopt; }
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
    /// Starts the current trial's stimulus and stores the start (the player reports the render
    /// seed and recording it used); if storing fails the stimulus is stopped and the error thrown.
    void play();
    /// Commits the answer (durably), stops the stimulus and advances. It does not check the
    /// answer against the protocol: TrialFlow::commit() does, before it calls this (every front
    /// end and the simulation answer through TrialFlow). Throws StoreError when the store
    /// refuses the write; the trial then stays current and keeps playing. When the answer was
    /// stored but the checkpoint after it failed, it advances first and then throws
    /// AnswerSavedButNotCopied, so that the view shows the warning and never asks again.
    void answer(const TrialAnswer& answer);
    /// Break -> next trial.
    void finishBreak();
    /// Stops the stimulus and closes the session as interrupted (resume later).
    void interrupt();

    // Sensor faults: the session pauses instead of recording a broken trial.

    /// A sensor driving the current trial failed: the stimulus stops, its presentation is stored
    /// as interrupted with `reason` (the trial stays unanswered) and the session pauses. No-op
    /// when not in a trial or already paused.
    void sensorFault(const std::string& reason);
    /// Asks the player whether its sensors failed (StimulusPlayer::sensorFault) and pauses if so;
    /// returns paused(). Call it periodically (the GUI's timer) while a trial plays.
    bool checkSensors();
    /// Whether the session is paused by a sensor fault (play() and answers are refused).
    bool paused() const { return paused_; }
    /// The fault that paused the session ("" when not paused).
    const std::string& pauseReason() const { return pauseReason_; }
    /// The sensor is back: unpauses (journaled); the participant restarts the same trial with
    /// play(). Throws std::logic_error when the player still reports a fault.
    void resumeAfterFault();

    // Listening-test mode: clips played on demand and rated scale by scale.

    /// The scales asked after the current trial (one per block with per-scale blocks).
    std::vector<const Scale*> askedScales() const;
    /// Presents the current trial's clip: the first call starts it (as play()); every later call
    /// replays it from the start, counted and journaled (whether the protocol allows replays is
    /// TrialFlow::replay()'s rule).
    void presentClip();
    /// Replays of the current trial's clip so far.
    int replayCount() const;

    // Interactive tests with laps ([laps]): silent baseline laps, then laps with sound.

    /// Laps per condition (0: no lap structure).
    int lapCount() const;
    /// Laps completed in the current trial.
    int lapsDone() const;
    /// Whether the lap being walked now is a silent baseline lap.
    bool currentLapSilent() const;
    /// Completes the current lap (stored and journaled); the next lap starts, with sound once
    /// the baseline laps are done. The questions can be answered after the last lap.
    void completeLap();

  private:
    void advance();
    void stopPlayer();

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
    bool paused_ = false;
    std::string pauseReason_;
    double startedAtS_ = 0.0;
};

} // namespace underfoot::experiment
