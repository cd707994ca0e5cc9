// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/SessionRig.h"

#include "app/wiring/Adapters.h"
#include "engine/control/StepCalibration.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/io/AudioDevice.h"

#include <fmt/format.h>

#include <filesystem>

namespace underfoot::wiring {

namespace eng = underfoot::engine;

namespace {
eng::AudioSettings settingsOf(const SessionRigOptions& o) {
    return o.settingsFile.empty() ? eng::AudioSettings{} : eng::loadAudioSettings(o.settingsFile);
}
} // namespace

SessionRig::~SessionRig() {
    if (shoes) shoes->stop();
    if (gyros) gyros->stop();
    clipAudio.reset();
    player.reset();
    if (engine) engine->close();
}

std::unique_ptr<SessionRig> SessionRig::openForClips(const SessionRigOptions& o) {
    std::unique_ptr<SessionRig> rig(new SessionRig);
    const auto settings = settingsOf(o);
    rig->engine = std::make_unique<eng::LiveEngine>();
    rig->engine->open(settings);
    rig->engine->start();
    rig->clipAudio = std::make_unique<ClipAudio>(*rig->engine);
    return rig;
}

std::unique_ptr<SessionRig> SessionRig::openLive(const SessionRigOptions& o) {
    std::unique_ptr<SessionRig> rig(new SessionRig);
    const auto settings = settingsOf(o);
    const std::filesystem::path studyFolder = std::filesystem::absolute(o.studyFile).parent_path();
    LivePlayerOptions options;
    options.studyFolder = studyFolder.string();
    options.recordingFolder =
        o.recordings.empty() ? (studyFolder / "recordings").string() : o.recordings;
    if (!o.serial.empty()) {
        eng::SerialConfig config;
        config.path = o.serial;
        config.baud = o.baud;
        rig->shoes = std::make_shared<eng::SerialSource>(config);
        eng::StepGrfPlayerConfig playerConfig;
        playerConfig.seed = o.stepSeed;
        auto stepPlayer = std::make_shared<eng::StepGrfPlayer>(
            eng::StepGrfPlayer::loadDefaultBank(settings.sampleRateHz), playerConfig);
        rig->steps = std::make_shared<eng::StepInput>(
            o.thresholds.empty() ? eng::StepThresholds{} : eng::loadStepThresholds(o.thresholds));
        rig->steps->attach(*rig->shoes, stepPlayer.get());
        rig->shoes->start();
        options.scene.fsrSource = std::make_shared<StepGrfSource>(stepPlayer);
        options.shoes = rig->shoes;
        options.shoeSteps = rig->steps;
        rig->serialPort_ = o.serial;
    }
    if (o.oscPort >= 0) {
        eng::OscGyroConfig config;
        config.port = o.oscPort;
        rig->gyros = std::make_shared<eng::OscGyroReceiver>(config);
        rig->gyros->start();
        options.scene.gyroReceiver = rig->gyros;
    }
    rig->engine = std::make_unique<eng::LiveEngine>();
    rig->engine->open(settings);
    rig->engine->start();
    rig->player = std::make_unique<LivePlayer>(*rig->engine, std::move(options));
    return rig;
}

std::string SessionRig::summary() const {
    if (!engine) return "no audio device";
    return fmt::format("{} / {} at {} Hz, block {}{}{}", engine->openedApi(),
                       engine->openedDevice(), engine->settings().sampleRateHz,
                       engine->settings().blockSize,
                       shoes ? fmt::format(", FSR shoes on {}", serialPort_) : "",
                       gyros ? fmt::format(", gyroscopes on UDP {}", gyros->port()) : "");
}

} // namespace underfoot::wiring
