// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The live rig of a session: the audio device (LiveEngine), the sensors (FSR shoes on a serial
/// port with their step detector, OSC gyroscopes) and the player that the session drives
/// (LivePlayer for footsteps and wading, ClipAudio for listening-test clips). One rig for the
/// terminal session and the console; every part it was not asked for stays null.
///
/// Torn down sensors first (their reader threads push steps into the player's step queues), then
/// the player, then the engine.
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "engine/control/StepInput.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/scene/LiveEngine.h"

#include <cstdint>
#include <memory>
#include <string>

namespace underfoot::wiring {

struct SessionRigOptions {
    std::string settingsFile; ///< audio settings TOML (`underfoot devices --save`); "" = default
    std::string studyFile;    ///< recordings go to recordings/ beside it unless `recordings`
    std::string recordings;
    std::string serial; ///< FSR shoes' port ("" = none)
    int baud = 500000;
    std::string thresholds; ///< the participant's step thresholds ("" = defaults)
    std::uint64_t stepSeed = 1;
    int oscPort = -1; ///< gyroscopes (OSC/UDP; < 0 = none)
};

class SessionRig {
  public:
    /// The device and a clip player (listening tests; no sensors, no footstep player). Throws
    /// with the reason when no sound can be played.
    static std::unique_ptr<SessionRig> openForClips(const SessionRigOptions& options);
    /// The device, the sensors asked for and a LivePlayer recording next to the study. Throws
    /// with the reason when a part cannot be opened.
    static std::unique_ptr<SessionRig> openLive(const SessionRigOptions& options);
    ~SessionRig();
    SessionRig(const SessionRig&) = delete;
    SessionRig& operator=(const SessionRig&) = delete;

    /// "jack / system at 48000 Hz, block 64, FSR shoes on /dev/ttyACM0".
    std::string summary() const;

    std::unique_ptr<ClipAudio> clipAudio;
    std::shared_ptr<engine::SerialSource> shoes;
    std::shared_ptr<engine::StepInput> steps;
    std::shared_ptr<engine::OscGyroReceiver> gyros;
    std::unique_ptr<engine::LiveEngine> engine;
    std::unique_ptr<LivePlayer> player;

  private:
    SessionRig() = default;
    std::string serialPort_;
};

} // namespace underfoot::wiring
