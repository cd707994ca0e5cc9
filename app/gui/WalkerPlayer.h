// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The console's StimulusPlayer while no live audio engine is in the build: it runs the
/// stimulus's virtual walker in real time (driven by a Qt timer at the GRF control rate) and
/// publishes the ground reaction force under each foot and the steps, so the Run view's meters
/// and step indicator move as they will with the live engine. It reports the plan's seed as the
/// render seed, so replay re-renders exactly the walk that was shown. Sensor-driven stimuli have
/// no source here: the meters then say so.
#include "engine/control/VirtualWalker.h"
#include "experiment/Session.h"

#include <QElapsedTimer>
#include <QObject>
#include <QTimer>

#include <memory>
#include <vector>

namespace underfoot::gui {

/// GRF levels of the last meter period.
struct GrfMeter {
    double leftBw = 0;  ///< peak force under the left foot in body weights
    double rightBw = 0; ///< same for the right foot
    int steps = 0;      ///< heel strikes since the stimulus started
    bool leftStrike = false, rightStrike = false; ///< a heel strike in this period
};

class WalkerPlayer : public QObject, public experiment::StimulusPlayer {
    Q_OBJECT
  public:
    explicit WalkerPlayer(QObject* parent = nullptr);
    experiment::StimulusStart start(const experiment::Stimulus& stimulus,
                                    std::uint64_t plannedSeed) override;
    void stop() override;
    /// Pauses / resumes the walk (the meters freeze; the session's stimulus stays current).
    void setPaused(bool paused);
    bool playing() const { return playing_; }
    /// Whether the current stimulus has a source here (walker input).
    bool hasSource() const { return walker_ != nullptr; }

  signals:
    void meter(const underfoot::gui::GrfMeter& meter);
    void started(bool hasSource);
    void stopped();

  private:
    void tick();
    static constexpr double kControlRateHz = 1000.0;
    std::unique_ptr<engine::VirtualWalker> walker_;
    QTimer timer_;
    QElapsedTimer clock_;
    double samplesDone_ = 0;
    std::vector<float> left_, right_;
    bool leftDown_ = false, rightDown_ = false;
    bool primed_ = false;
    int steps_ = 0;
    bool playing_ = false;
};

/// The walker parameters of a stimulus's `walker = {...}` table (unknown keys ignored, values
/// outside the walker's ranges rejected with std::invalid_argument).
engine::WalkerParameters walkerParametersOf(const experiment::Stimulus& stimulus);

} // namespace underfoot::gui
