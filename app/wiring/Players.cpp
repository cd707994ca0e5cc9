// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/Players.h"

#include "app/wiring/Adapters.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SensorClock.h"
#include "engine/io/sensors/SensorLog.h"
#include "engine/render/Renderer.h"
#include "engine/render/SafetyLimiter.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace underfoot::wiring {

namespace fs = std::filesystem;
namespace exp = underfoot::experiment;
namespace eng = underfoot::engine;

eng::WalkerParameters walkerFromStimulus(const exp::Parameters& p) {
    std::string spec;
    for (const auto& [key, value] : p) {
        if (!(key == "cadence" || key == "mass" || key == "shoe" || key == "variability"))
            throw std::invalid_argument(
                fmt::format("walker parameter `{}` is not one the engine's virtual walker knows "
                            "(cadence, mass, shoe, variability)",
                            key));
        const double* v = std::get_if<double>(&value);
        if (!v)
            throw std::invalid_argument(fmt::format("walker parameter `{}` must be a number", key));
        spec += fmt::format("{}{}={}", spec.empty() ? "" : ",", key, *v);
    }
    return spec.empty() ? eng::WalkerParameters{} : eng::WalkerParameters::parse(spec);
}

eng::LiveSceneDescription describeStimulus(const exp::Stimulus& s, std::uint64_t seed,
                                           const StimulusSceneOptions& o) {
    eng::LiveSceneDescription d;
    d.surface = s.surface;
    d.seed = seed;
    if (s.reverb) d.impulseResponse = *s.reverb;
    switch (s.modalities) {
    case exp::Modalities::Audio:
        d.modality = eng::OutputModality::Audio;
        break;
    case exp::Modalities::Haptic:
        d.modality = eng::OutputModality::Haptic;
        break;
    case exp::Modalities::AudioHaptic:
        d.modality = eng::OutputModality::AudioHaptic;
        break;
    }
    if (s.soundscape && d.modality != eng::OutputModality::Haptic)
        d.ambience = makeSoundscapeAmbience(*s.soundscape);
    d.hapticPairs = o.hapticPairs;
    d.hapticGainDb = o.hapticGainDb;
    if (isWadingStimulus(s)) { // the wading node replaces the GRF control and the voices
        d.wading = makeWadingNode(s, seed, o.gyroReceiver);
        return d;
    }
    if (s.input.kind == exp::InputKind::Walker) {
        d.control = eng::ControlKind::Walker;
        d.walker = walkerFromStimulus(s.input.walker);
        return d;
    }
    switch (s.input.sensor) {
    case exp::SensorKind::Microphones:
        d.control = eng::ControlKind::Microphones;
        d.microphones.gain = o.microphoneNewtonsPerFullScale;
        break;
    case exp::SensorKind::Fsr:
        if (!o.fsrSource)
            throw std::invalid_argument(fmt::format(
                "stimulus `{}` is driven by the FSR shoes, but no shoe source is connected", s.id));
        d.control = eng::ControlKind::External;
        d.external = o.fsrSource;
        break;
    case exp::SensorKind::Gyro:
        if (!o.gyroSource)
            throw std::invalid_argument(fmt::format(
                "stimulus `{}` is driven by gyroscopes, but no gyroscope source is connected",
                s.id));
        d.control = eng::ControlKind::External;
        d.external = o.gyroSource;
        break;
    case exp::SensorKind::None:
        throw std::invalid_argument(
            fmt::format("stimulus `{}` has a sensor input without a sensor kind", s.id));
    }
    return d;
}

LivePlayer::LivePlayer(eng::LiveEngine& engine, LivePlayerOptions options)
    : engine_(engine), options_(std::move(options)) {}

LivePlayer::~LivePlayer() {
    try {
        stop();
    } catch (...) {
    }
    stopSensorLog(); // when stop() failed before it
}

namespace {
std::string safeName(const std::string& id) {
    std::string out;
    for (char c : id)
        out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    return out.empty() ? "stimulus" : out;
}
} // namespace

std::string LivePlayer::reference(const std::string& path) const {
    std::string ref = path;
    if (!options_.studyFolder.empty()) {
        const auto rel = fs::path(path).lexically_relative(options_.studyFolder);
        if (!rel.empty() && *rel.begin() != "..") ref = rel.string();
    }
    return ref;
}

std::string LivePlayer::reservePath(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) {
    if (options_.recordingFolder.empty()) return {};
    const bool wading = isWadingStimulus(stimulus);
    fs::create_directories(options_.recordingFolder);
    std::string path;
    for (int attempt = 0;; ++attempt) {
        path = (fs::path(options_.recordingFolder) /
                fmt::format("{}_{}_{:03d}_seed{}{}.{}", wading ? "gait" : "grf",
                            safeName(stimulus.id), ++counter_, plannedSeed,
                            attempt ? fmt::format("_{}", attempt) : "", wading ? "csv" : "wav"))
                   .string();
        if (!fs::exists(path)) break;
    }
    return path;
}

void LivePlayer::setMuted(bool muted) {
    muted_ = muted;
    if (muted || !deferred_) return;
    const Deferred d = std::move(*deferred_);
    deferred_.reset();
    begin(d.stimulus, d.seed, d.path);
}

exp::StimulusStart LivePlayer::start(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) {
    if (!engine_.isOpen()) throw std::runtime_error("live player: the audio engine is not open");
    stop();
    // Fail now, not when the sound comes on, for a stimulus that cannot be described.
    if (muted_) (void)describeStimulus(stimulus, plannedSeed, options_.scene);
    const std::string path = reservePath(stimulus, plannedSeed);
    if (!muted_) return begin(stimulus, plannedSeed, path);
    // Silent baseline laps: the scene starts when the sound comes on (setMuted(false)); the
    // recording then holds what was heard, under the name reserved now.
    deferred_ = Deferred{stimulus, plannedSeed, path};
    exp::StimulusStart result;
    result.renderSeed = plannedSeed;
    if (!path.empty()) result.grfRecording = reference(path);
    sensor_ = stimulus.input.kind == exp::InputKind::Sensor &&
                      stimulus.input.sensor == exp::SensorKind::Gyro && options_.scene.gyroReceiver
                  ? TrialSensor::Gyro
                  : TrialSensor::None;
    return result;
}

exp::StimulusStart LivePlayer::begin(const exp::Stimulus& stimulus, std::uint64_t plannedSeed,
                                     const std::string& path) {
    auto d = describeStimulus(stimulus, plannedSeed, options_.scene);
    const bool wading = d.wading != nullptr;
    const int grfChannels = wading                                  ? 0
                            : d.control == eng::ControlKind::Walker ? 2
                            : d.control == eng::ControlKind::Microphones
                                ? 1
                                : d.external->channelCount();
    exp::StimulusStart result;
    result.renderSeed = plannedSeed;
    if (!path.empty() && !wading)
        d.grfRecorder = eng::makeGrfRecorder(path, grfChannels, engine_.processSpec().sampleRateHz);
    auto recorder = d.grfRecorder;
    std::unique_ptr<eng::LiveScene> scene;
    try {
        scene = eng::LiveScene::create(std::move(d), engine_.processSpec(),
                                       engine_.settings().channels);
    } catch (...) {
        if (recorder) {
            recorder->finish();
            std::error_code ec;
            fs::remove(path, ec);
        }
        throw;
    }
    summary_ = scene->summary();
    if (!engine_.submit(std::move(scene))) {
        if (recorder) {
            recorder->finish();
            std::error_code ec;
            fs::remove(path, ec);
        }
        throw std::runtime_error("live player: the audio thread did not take the scene (command "
                                 "queue full: is the stream running?)");
    }
    recorder_ = recorder;
    recordingPath_ = path;
    playing_ = true;
    wading_ = wading;
    engine_.resetPeaks();
    startMeters_ = engine_.meters();
    if (!path.empty()) result.grfRecording = reference(path);
    TrialSensor sensor = TrialSensor::None;
    if (stimulus.input.kind == exp::InputKind::Sensor &&
        stimulus.input.sensor == exp::SensorKind::Fsr && options_.shoes)
        sensor = TrialSensor::Shoes;
    else if (stimulus.input.kind == exp::InputKind::Sensor &&
             stimulus.input.sensor == exp::SensorKind::Gyro && options_.scene.gyroReceiver)
        sensor = TrialSensor::Gyro;
    sensorLogPath_.clear();
    if (sensor == TrialSensor::Shoes && options_.shoeSteps && !path.empty()) {
        sensorLogPath_ =
            (fs::path(path).parent_path() / (fs::path(path).stem().string() + ".sensors.csv"))
                .string();
        try {
            startSensorLog(sensorLogPath_);
        } catch (...) {
            sensor_ = sensor; // stop() releases the scene and the recording
            try {
                stop();
            } catch (...) {
            }
            throw;
        }
        result.sensorLog = reference(sensorLogPath_);
    }
    sensor_ = sensor;
    return result;
}

void LivePlayer::startSensorLog(const std::string& path) {
    auto log = std::make_shared<eng::SensorLogWriter>(path, eng::sensorClockSeconds());
    auto* grfSource = dynamic_cast<StepGrfSource*>(options_.scene.fsrSource.get());
    eng::StepGrfPlayer* stepPlayer = grfSource ? &grfSource->player() : nullptr;
    const auto drain = [this, stepPlayer](eng::SensorLogWriter* to) {
        eng::ShoeFrame f;
        while (options_.shoes->popFrame(f))
            if (to) to->write(f);
        eng::StepEvent e;
        while (options_.shoeSteps->popEvent(e))
            if (to) to->write(e);
        eng::StepPlayback p;
        if (stepPlayer)
            while (stepPlayer->popPlayback(p))
                if (to) to->write(p);
    };
    drain(nullptr); // what queued up between trials belongs to no trial
    sensorLogError_.clear();
    sensorLogRows_ = 0;
    sensorLogRunning_ = true;
    sensorLogThread_ = std::thread([this, log, drain] {
        try {
            while (sensorLogRunning_.load()) {
                drain(log.get());
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            }
            drain(log.get());
            log->flush();
        } catch (const std::exception& e) {
            sensorLogError_ = e.what();
        }
        sensorLogRows_ = static_cast<std::size_t>(log->rows());
    });
}

void LivePlayer::stopSensorLog() {
    if (!sensorLogThread_.joinable()) return;
    sensorLogRunning_ = false;
    sensorLogThread_.join();
}

std::optional<std::string> LivePlayer::sensorFault() const {
    const TrialSensor sensor = sensor_.load();
    if (sensor == TrialSensor::None) return std::nullopt;
    const eng::SensorStatus status = sensor == TrialSensor::Shoes
                                         ? options_.shoes->status()
                                         : options_.scene.gyroReceiver->status();
    if (status.state == eng::SensorState::Running) return std::nullopt;
    return fmt::format("{} {}{}{}", sensor == TrialSensor::Shoes ? "FSR shoes" : "gyroscopes",
                       eng::sensorStateName(status.state), status.message.empty() ? "" : ": ",
                       status.message);
}

void LivePlayer::stop() {
    deferred_.reset(); // a trial stopped during its silent laps: nothing was heard or recorded
    if (!playing_) return;
    playing_ = false; // sensor_ stays: the session asks whether that sensor came back
    engine_.submit(nullptr);
    // Crossfade plus a margin; a stopped stream hands nothing back (then nothing pushes).
    engine_.waitIdle(engine_.settings().crossfadeMs * 1e-3 + 2.0);
    std::string gaitError;
    bool wroteGait = false;
    if (wading_) {
        // The retired water scene still holds its gait recording: write it before releasing.
        bool written = recordingPath_.empty();
        for (const auto& scene : engine_.takeRetired())
            if (scene->wading() && !written) {
                try {
                    scene->wading()->writeRecording(recordingPath_);
                    // What reproduces the node exactly: each frame at the sample where it took
                    // effect (`underfoot replay` renders from it when present).
                    scene->wading()->writeArrivals(recordingPath_ + ".arrivals.csv");
                    written = true;
                    wroteGait = true;
                    if (scene->wading()->unrecordedFrames() > 0)
                        gaitError = fmt::format("{} gait frames did not fit the recording",
                                                scene->wading()->unrecordedFrames());
                } catch (const std::exception& e) {
                    gaitError = e.what();
                    written = true;
                }
            }
        if (!written)
            gaitError = "the water scene was not handed back by the audio thread (stream stopped?)";
        wading_ = false;
    } else {
        engine_.collectRetired();
    }
    stopSensorLog();
    const auto m = engine_.meters();
    stats_ = {};
    stats_.frames = m.frames - startMeters_.frames;
    stats_.xruns = m.xruns - startMeters_.xruns;
    const double rate = engine_.settings().sampleRateHz;
    const double busyBefore = startMeters_.averageLoadPercent * double(startMeters_.frames) / rate;
    const double busyNow = m.averageLoadPercent * double(m.frames) / rate;
    stats_.averageLoadPercent =
        stats_.frames > 0 ? (busyNow - busyBefore) / (double(stats_.frames) / rate) : 0.0;
    stats_.maxLoadPercent = m.maxLoadPercent;
    stats_.maxBlockSeconds = m.maxBlockSeconds;
    stopped_ = true;
    const auto writeMeters = [&](const std::string& recording) {
        std::ofstream side(recording + ".meters.toml");
        side << fmt::format(
            "# Measured by the live engine while this trial played "
            "(docs/explanation/live-audio.md)\n"
            "scene = \"{}\"\nsample_rate = {}\nblock_size = {}\nframes = {}\nxruns = {}\n"
            "average_load_percent = {:.3f}\n"
            "max_load_percent = {:.3f}\nmax_block_ms = {:.4f}\ndropped_grf_frames = {}\n",
            summary_, engine_.settings().sampleRateHz, engine_.settings().blockSize, stats_.frames,
            stats_.xruns, stats_.averageLoadPercent, stats_.maxLoadPercent,
            stats_.maxBlockSeconds * 1e3, stats_.droppedGrfFrames);
    };
    if (wroteGait) writeMeters(recordingPath_); // the replay reads the live block size there
    if (recorder_) {
        recorder_->finish();
        lastDropped_ = recorder_->droppedFrames();
        stats_.droppedGrfFrames = lastDropped_;
        writeMeters(recorder_->path());
        const std::string error = recorder_->error();
        recorder_.reset();
        if (!error.empty()) throw std::runtime_error("live player: GRF recording: " + error);
    }
    if (!gaitError.empty())
        throw std::runtime_error(
            fmt::format("live player: gait recording {}: {}", recordingPath_, gaitError));
    if (!sensorLogError_.empty())
        throw std::runtime_error(fmt::format("live player: sensor log: {}", sensorLogError_));
}

std::optional<exp::TrialAudioStats> LivePlayer::stoppedTrialStats() const {
    if (!stopped_) return std::nullopt;
    exp::TrialAudioStats a;
    a.sampleRateHz = engine_.settings().sampleRateHz;
    a.blockSize = engine_.settings().blockSize;
    a.frames = stats_.frames;
    a.xruns = stats_.xruns;
    a.averageLoadPercent = stats_.averageLoadPercent;
    a.maxLoadPercent = stats_.maxLoadPercent;
    a.maxBlockMs = stats_.maxBlockSeconds * 1e3;
    a.droppedGrfFrames = stats_.droppedGrfFrames;
    return a;
}

eng::AudioBuffer renderStimulusFromGrf(const exp::Stimulus& stimulus, const eng::GrfSignal& grf,
                                       std::uint64_t seed, double rate, int blockSize) {
    eng::RenderOptions options;
    options.sampleRateHz = rate;
    options.blockSize = blockSize;
    options.seed = seed;
    options.tailSeconds = 1.0;
    if (stimulus.reverb) options.scene.impulseResponse = *stimulus.reverb;
    // The live engine limits each output after the soundscape is mixed in: so does the replay.
    options.limit = false;
    auto r = eng::renderSurface(stimulus.surface, grf, options);
    if (stimulus.soundscape && stimulus.modalities != exp::Modalities::Haptic) {
        // As the live scene mixes it: same seed, unity gain.
        soundscapes::SoundscapeRenderer ambience(soundscapes::loadSoundscape(*stimulus.soundscape));
        ambience.prepare({rate, 1024});
        ambience.reset(seed);
        const std::size_t n = r.audio.frames();
        std::vector<float> l(n), rr(n);
        ambience.process(l.data(), rr.data(), static_cast<int>(n));
        for (std::size_t i = 0; i < n; ++i) {
            r.audio.samples[2 * i] += l[i];
            r.audio.samples[2 * i + 1] += rr[i];
        }
    }
    const std::size_t n = r.audio.frames();
    std::vector<float> l(n), rr(n);
    for (std::size_t i = 0; i < n; ++i) {
        l[i] = r.audio.samples[2 * i];
        rr[i] = r.audio.samples[2 * i + 1];
    }
    eng::StereoSafetyLimiter limiter;
    limiter.prepare(rate);
    limiter.process(l.data(), rr.data(), static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) {
        r.audio.samples[2 * i] = l[i];
        r.audio.samples[2 * i + 1] = rr[i];
    }
    return std::move(r.audio);
}

eng::AudioBuffer renderStimulus(const exp::Stimulus& stimulus, std::uint64_t seed, double seconds,
                                double rate, int blockSize) {
    const auto walker = stimulus.input.kind == exp::InputKind::Walker
                            ? walkerFromStimulus(stimulus.input.walker)
                            : eng::WalkerParameters{};
    return renderStimulusFromGrf(stimulus, eng::walkerGrf(walker, seconds, rate, seed), seed, rate,
                                 blockSize);
}

exp::StimulusStart OfflinePlayer::start(const exp::Stimulus& stimulus, std::uint64_t plannedSeed) {
    last_ = renderStimulus(stimulus, plannedSeed, seconds_, rate_);
    return {plannedSeed, std::nullopt};
}

} // namespace underfoot::wiring
