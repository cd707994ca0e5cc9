// SPDX-License-Identifier: GPL-3.0-or-later
// Every shipped protocol runs live and replays: one trial of each shipped protocol
// runs through the real live path and is then replayed offline, and the samples are compared.
//
// The live path is the one `underfoot session --live` builds:
//  - the sound card is a JACK server with the dummy driver (`jackd --no-realtime -S -d dummy -r
//    48000 -p 64 -C 4 -P 6`), RtAudio's JACK API runs the LiveEngine at 64 frames;
//  - two JACK clients of this test stand beside it: "ears" records the engine's headphone
//    outputs (what the participant heard), "mics" plays footstep noise bursts into the engine's
//    microphone inputs (the dummy driver's own capture ports are silent);
//  - FSR shoes: ShoeScript lines at 1 kHz written into a socat pseudo-terminal pair, read by the
//    SerialSource (termios), StepInput and StepGrfPlayer;
//  - gyroscopes: liblo sends four limbs at 100 Hz over loopback UDP to an OscGyroReceiver;
//  - listening tests: the rendered clip folder played through ClipAudio (experiment::ClipPlayer);
//  - LivePlayer, Session and StudyStore store the trial as a session does; then
//    renderTrialReplay (`underfoot replay`) re-renders it from the store.
// The replay is aligned on the first audible sample and compared:
//  - footsteps (microphones, FSR) and wading with live gyroscopes: bit for bit after the live
//    scene's 10 ms fade-in (the wading node records each gyroscope frame with the sample at which
//    it took effect, its gait arrivals file, and the replay applies them there at the live block
//    size);
//  - clips: within 2^-23, the step of the clip file's 24-bit PCM (the replay renders in float).
//    wading_realism's lab-supplied real recordings are not bundled: seeded noise stands in for
//    them so that the protocol can start, and its first rendered clip is compared.
// The JACK server runs synchronously (-S) so that the ears client never reads a period the
// engine has not finished; a capture period still missing or damaged after an overrun is
// skipped, counted and bounded (docs/decisions/jack-synchronous-tests.md).
// Skipped when jackd or socat is missing.
#include "app/wiring/Adapters.h"
#include "app/wiring/ClipPlayer.h"
#include "app/wiring/Players.h"
#include "app/wiring/Replay.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/control/StepInput.h"
#include "engine/dsp/Random.h"
#include "engine/io/AudioFile.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SerialSource.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Clips.h"
#include "experiment/Session.h"
#include "experiment/Store.h"
#include "tests/common/ScratchDir.h"
#include "tests/common/SocatHelpers.h"
#include "tests/live/audio/JackDummyServer.h"

#include <gtest/gtest.h>
#include <jack/jack.h>
#include <lo/lo.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>

namespace eng = underfoot::engine;
namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

constexpr int kPeriod = 64;
constexpr double kRate = 48000.0;

/// A JACK client of this test: "ears" (two inputs, recorded into a preallocated buffer while
/// capturing) or "mics" (two outputs: a decaying noise burst every 0.55 s, the second channel at
/// half the first).
class JackTap {
  public:
    enum class Kind { Ears, Mics };
    JackTap(const std::string& name, Kind kind, std::size_t capacityFrames = 0)
        : kind_(kind), noise_(42) {
        // On a loaded machine a client can fail to open for a moment on a running server (the
        // same transient as RtAudio's probe, see openJackDevice): retried for up to 5 s.
        for (int i = 0; i < 50 && !client_; ++i) {
            if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
            jack_status_t status{};
            client_ = jack_client_open(name.c_str(), JackNoStartServer, &status);
        }
        if (!client_) return;
        for (int c = 0; c < 2; ++c) {
            const std::string port = (kind == Kind::Ears ? "in_" : "out_") + std::to_string(c);
            ports_[c] =
                jack_port_register(client_, port.c_str(), JACK_DEFAULT_AUDIO_TYPE,
                                   kind == Kind::Ears ? JackPortIsInput : JackPortIsOutput, 0);
            recorded_[c].assign(capacityFrames, 0.0f);
        }
        jack_set_process_callback(client_, &JackTap::process, this);
        jack_set_xrun_callback(
            client_,
            [](void* arg) {
                auto* self = static_cast<JackTap*>(arg);
                if (self->capturing_.load(std::memory_order_relaxed))
                    self->xruns_.fetch_add(1, std::memory_order_relaxed);
                return 0;
            },
            this);
        if (jack_activate(client_) != 0) {
            jack_client_close(client_);
            client_ = nullptr;
        }
    }
    ~JackTap() {
        if (client_) {
            jack_deactivate(client_);
            jack_client_close(client_);
        }
    }
    JackTap(const JackTap&) = delete;
    JackTap& operator=(const JackTap&) = delete;
    bool ok() const { return client_ != nullptr; }
    /// Connects our ports to the engine client's ("outport N" / "inport N").
    bool connect(const std::string& engineClient) {
        for (int c = 0; c < 2; ++c) {
            const std::string mine = std::string(jack_port_name(ports_[c]));
            const std::string theirs =
                engineClient + (kind_ == Kind::Ears ? ":outport " : ":inport ") + std::to_string(c);
            const int rc = kind_ == Kind::Ears
                               ? jack_connect(client_, theirs.c_str(), mine.c_str())
                               : jack_connect(client_, mine.c_str(), theirs.c_str());
            if (rc != 0) return false;
        }
        return true;
    }
    void capture(bool on) { capturing_.store(on, std::memory_order_release); }
    std::size_t frames() const { return frames_.load(std::memory_order_acquire); }
    /// Overruns JACK reported to this client while capturing.
    std::uint64_t xruns() const { return xruns_.load(std::memory_order_relaxed); }
    const std::vector<float>& channel(int c) const { return recorded_[c]; }

  private:
    static int process(jack_nframes_t n, void* arg) {
        auto* self = static_cast<JackTap*>(arg);
        if (self->kind_ == Kind::Ears) {
            if (!self->capturing_.load(std::memory_order_acquire)) return 0;
            const std::size_t at = self->frames_.load(std::memory_order_relaxed);
            if (at + n > self->recorded_[0].size()) return 0;
            for (int c = 0; c < 2; ++c) {
                const auto* in =
                    static_cast<const float*>(jack_port_get_buffer(self->ports_[c], n));
                std::copy(in, in + n, self->recorded_[c].begin() + static_cast<std::ptrdiff_t>(at));
            }
            self->frames_.store(at + n, std::memory_order_release);
            return 0;
        }
        auto* a = static_cast<float*>(jack_port_get_buffer(self->ports_[0], n));
        auto* b = static_cast<float*>(jack_port_get_buffer(self->ports_[1], n));
        for (jack_nframes_t i = 0; i < n; ++i, ++self->t_) {
            const double phase = std::fmod(static_cast<double>(self->t_) / kRate, 0.55);
            const float env = static_cast<float>(0.6 * std::exp(-phase / 0.04));
            a[i] = env * static_cast<float>(self->noise_.bipolar());
            b[i] = 0.5f * a[i];
        }
        return 0;
    }

    Kind kind_;
    jack_client_t* client_ = nullptr;
    jack_port_t* ports_[2]{};
    std::vector<float> recorded_[2];
    std::atomic<bool> capturing_{false};
    std::atomic<std::size_t> frames_{0};
    std::atomic<std::uint64_t> xruns_{0};
    eng::Random noise_;
    std::uint64_t t_ = 0;
};

/// Sends the four limbs at 100 Hz: a walk at 0.9 strides/s, thighs and shanks swinging in
/// opposite phase left and right, for `seconds`.
void sendGait(lo_address to, double seconds) {
    static const char* paths[4] = {"/underfoot/gyro/left_thigh", "/underfoot/gyro/right_thigh",
                                   "/underfoot/gyro/left_shank", "/underfoot/gyro/right_shank"};
    auto next = std::chrono::steady_clock::now();
    const int periods = static_cast<int>(seconds * 100);
    for (int k = 0; k < periods; ++k) {
        const double t = k / 100.0;
        const double s = std::sin(2 * M_PI * 0.9 * t);
        const float v[4] = {static_cast<float>(150 * s), static_cast<float>(-150 * s),
                            static_cast<float>(220 * s), static_cast<float>(-220 * s)};
        for (int l = 0; l < 4; ++l) lo_send(to, paths[l], "fi", v[l], k);
        next += 10ms;
        std::this_thread::sleep_until(next);
    }
}

class LiveProtocols : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        server_ = new underfoot::test::JackDummyServer(
            "underfoot_protocols", underfoot::test::scratchDir("live_protocols") / "jackd.log",
            kPeriod, /*synchronous=*/true);
    }
    static void TearDownTestSuite() {
        delete server_;
        server_ = nullptr;
    }
    void SetUp() override {
        if (!server_->installed()) GTEST_SKIP() << "jackd is not installed (Debian package jackd2)";
        ASSERT_TRUE(server_->ready()) << "jackd did not come up within 10 s";
    }

    /// BitForBit; Clip24: within one step of the clip file's 24-bit PCM (2^-23), since the
    /// listener heard the file and the replay renders in float.
    enum class Compare { BitForBit, Clip24 };

    /// Runs the first heard trial of a shipped protocol live, stores it, replays it and compares.
    void run(const std::string& protocolId, Compare compare);

    static underfoot::test::JackDummyServer* server_;
};

underfoot::test::JackDummyServer* LiveProtocols::server_ = nullptr;

void LiveProtocols::run(const std::string& id, Compare compare) {
    SCOPED_TRACE(id);
    const auto dir = underfoot::test::scratchDir("live_protocols") / id;
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string studyPath = (dir / "study.db").string();
    auto store = xp::StudyStore::create(
        studyPath, xp::loadProtocol(xp::shippedProtocolDir() + "/" + id + ".toml"),
        {"LP", "ci", 17, "t"});
    const auto& protocol = store.protocol();
    std::string code;
    for (int i = 1; i <= 6 && code.empty(); ++i) {
        const std::string c = "P" + std::to_string(i);
        std::map<std::string, std::string> fields;
        for (const auto& f : protocol.participantFields)
            fields[f.id] = f.options.empty() ? "x" : f.options.front();
        store.registerParticipant({c, 30, "", "", "", {}, ""}, fields);
        const xp::Stimulus s = store.trials(c).front().stimulus; // trials() returns a copy
        // Heard (not haptics only) and rendered (a lab-supplied clip is not re-rendered).
        if (s.modalities != xp::Modalities::Haptic && !s.clip) code = c;
    }
    ASSERT_FALSE(code.empty());
    const xp::Stimulus first = store.trials(code).front().stimulus;
    const bool clips = protocol.clips.enabled;
    const bool mics = !clips && first.input.kind == xp::InputKind::Sensor &&
                      first.input.sensor == xp::SensorKind::Microphones;
    const bool fsr = !clips && first.input.kind == xp::InputKind::Sensor &&
                     first.input.sensor == xp::SensorKind::Fsr;
    const bool gyro = !clips && first.input.kind == xp::InputKind::Sensor &&
                      first.input.sensor == xp::SensorKind::Gyro;

    // The sound card.
    const std::string client = "uf_" + id;
    eng::AudioSettings settings;
    settings.api = "jack";
    settings.device = "system";
    settings.sampleRateHz = 48000;
    settings.blockSize = kPeriod;
    settings.clientName = client;
    settings.portConnection = eng::AudioSettings::PortConnection::Manual;
    if (mics) settings.channels.microphones = {0, 1};
    eng::LiveEngine engine;
    underfoot::test::openJackDevice(engine, settings);
    engine.start();
    JackTap ears(client + "_ears", JackTap::Kind::Ears, static_cast<std::size_t>(kRate * 12));
    ASSERT_TRUE(ears.ok());
    ASSERT_TRUE(ears.connect(client));
    std::unique_ptr<JackTap> micTap;
    if (mics) {
        micTap = std::make_unique<JackTap>(client + "_mics", JackTap::Kind::Mics);
        ASSERT_TRUE(micTap->ok());
        ASSERT_TRUE(micTap->connect(client));
    }

    // The sensors.
    std::unique_ptr<underfoot::test::SocatPair> pty;
    std::shared_ptr<eng::SerialSource> shoes;
    std::shared_ptr<eng::StepInput> steps;
    std::unique_ptr<eng::ShoeScript> script;
    int shoeFd = -1;
    std::unique_ptr<underfoot::test::ShoeLineWriter> writer;
    std::shared_ptr<eng::OscGyroReceiver> gyros;
    wir::LivePlayerOptions options;
    options.studyFolder = dir.string();
    options.recordingFolder = (dir / "recordings").string();
    if (fsr) {
        if (!underfoot::test::socatInstalled()) GTEST_SKIP() << "socat is not installed";
        pty = std::make_unique<underfoot::test::SocatPair>(id);
        ASSERT_TRUE(pty->ready());
        eng::SerialConfig config;
        config.path = pty->app;
        // The emulated shoes are a thread of this process: on a loaded machine it can be
        // descheduled for longer than the 400 ms a real shoe's silence is allowed (844 ms seen),
        // and the session would rightly pause. This test compares the replay with what was
        // heard; the silence watchdog is tested by SerialSocat.SilenceIsDetected* and
        // test_app_session_sensors.
        config.faults.silenceMs = 5000;
        shoes = std::make_shared<eng::SerialSource>(config);
        eng::StepGrfPlayerConfig playerConfig;
        playerConfig.seed = 5;
        auto stepPlayer = std::make_shared<eng::StepGrfPlayer>(
            eng::StepGrfPlayer::loadDefaultBank(48000), playerConfig);
        steps = std::make_shared<eng::StepInput>(eng::StepThresholds{});
        steps->attach(*shoes, stepPlayer.get());
        shoes->start();
        options.scene.fsrSource = std::make_shared<wir::StepGrfSource>(stepPlayer);
        options.shoes = shoes;
        options.shoeSteps = steps;
        script = std::make_unique<eng::ShoeScript>(eng::ShoeWalkOptions{}, 8);
        script->stand(300);
        script->walk(40);
        shoeFd = underfoot::test::openWriter(pty->shoes);
        ASSERT_GE(shoeFd, 0);
        writer = std::make_unique<underfoot::test::ShoeLineWriter>(shoeFd, *script);
        const auto until = std::chrono::steady_clock::now() + 5s;
        while (!shoes->recordable() && std::chrono::steady_clock::now() < until)
            std::this_thread::sleep_for(10ms);
        ASSERT_TRUE(shoes->recordable()) << shoes->status().message;
    }
    if (gyro) {
        eng::OscGyroConfig config;
        config.port = 0;
        gyros = std::make_shared<eng::OscGyroReceiver>(config);
        gyros->start();
        options.scene.gyroReceiver = gyros;
    }

    // The player, as `session --live` wires it.
    std::unique_ptr<wir::LivePlayer> livePlayer;
    std::unique_ptr<wir::ClipAudio> clipAudio;
    std::unique_ptr<xp::ClipPlayer> clipPlayer;
    const std::string clipDir = (dir / "clips").string();
    if (clips) {
        // wading_realism's real recordings are the lab's (not bundled): seeded noise bursts
        // stand in for them, so that the protocol's folder is complete and its rendered clips
        // run through the live path like any other protocol's.
        for (const auto& s : protocol.stimuli) {
            if (!s.clip) continue;
            const fs::path file = fs::path(clipDir) / *s.clip;
            fs::create_directories(file.parent_path());
            eng::AudioBuffer standIn;
            standIn.sampleRateHz = kRate;
            standIn.channels = 2;
            const auto frames = static_cast<std::size_t>(kRate * protocol.clips.seconds);
            standIn.samples.resize(2 * frames);
            eng::Random noise(11);
            for (std::size_t i = 0; i < frames; ++i) {
                const double phase = std::fmod(static_cast<double>(i) / kRate, 0.8);
                standIn.samples[2 * i] = standIn.samples[2 * i + 1] =
                    static_cast<float>(0.3 * std::exp(-phase / 0.1) * noise.bipolar());
            }
            eng::writeAudioFile(file.string(), standIn);
        }
        try {
            wir::renderClipFolder(protocol, clipDir);
        } catch (const std::exception& e) {
            const bool labClips = std::any_of(protocol.stimuli.begin(), protocol.stimuli.end(),
                                              [](const xp::Stimulus& s) { return s.clip; });
            if (labClips)
                GTEST_SKIP() << "the protocol's lab-supplied recordings are not here (" << e.what()
                             << "); its rendered clips play through the same path as "
                                "wading_listening's";
            FAIL() << e.what();
        }
        clipAudio = std::make_unique<wir::ClipAudio>(engine);
        wir::ClipAudio* audio = clipAudio.get();
        clipPlayer = std::make_unique<xp::ClipPlayer>(
            protocol, clipDir, [audio](const std::string& p) { audio->play(p); },
            [audio] { audio->stop(); });
    } else {
        livePlayer = std::make_unique<wir::LivePlayer>(engine, options);
    }
    xp::StimulusPlayer& player =
        clips ? static_cast<xp::StimulusPlayer&>(*clipPlayer) : *livePlayer;
    xp::Session session(store, code, player, {"test", "jack dummy", id, "t", true});
    session.finishBriefing();
    const xp::TrialRecord trial = session.current();

    ears.capture(true);
    double seconds = 3.0;
    if (clips) {
        session.presentClip();
        seconds = protocol.clips.seconds + 0.3;
        std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    } else if (gyro) {
        session.play();
        const std::string port = std::to_string(gyros->port());
        lo_address to = lo_address_new("127.0.0.1", port.c_str());
        // Baseline laps: silent, nothing is submitted. Then the sound comes on and the
        // participant walks.
        for (int lap = 0; session.currentLapSilent(); ++lap) session.completeLap();
        sendGait(to, 4.0);
        lo_address_free(to);
        while (session.lapsDone() < session.lapCount()) session.completeLap();
    } else {
        session.play();
        std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
        // Under load the dummy driver skips cycles (xruns): wait, up to 30 s more, until the
        // ears have heard 2.5 s, so that the comparison below has more than a second.
        const auto until = std::chrono::steady_clock::now() + 30s;
        while (ears.frames() < static_cast<std::size_t>(2.5 * kRate) &&
               std::chrono::steady_clock::now() < until)
            std::this_thread::sleep_for(50ms);
    }
    ears.capture(false);
    xp::TrialAnswer answer;
    const auto& q = protocol.questions;
    if (!q.surfaceOptions.empty()) answer.answer = q.surfaceOptions.front().id;
    for (const xp::Scale* s : session.askedScales()) answer.ratings[s->id] = s->min;
    if (q.asksSoundscape(session.participant().groupId))
        answer.soundscapeAnswer = q.soundscapeOptions.front().id;
    session.answer(answer);
    writer.reset();
    if (shoeFd >= 0) ::close(shoeFd);
    const auto meters = engine.meters();
    engine.close();
    if (shoes) shoes->stop();
    if (gyros) gyros->stop();

    const xp::TrialRecord stored = store.trial(code, trial.index);
    ASSERT_TRUE(stored.answered);
    if (!clips) {
        ASSERT_TRUE(stored.grfRecording.has_value()) << "no control stream stored";
        ASSERT_TRUE(stored.audio.has_value());
        EXPECT_EQ(stored.audio->blockSize, kPeriod);
    }

    wir::ReplayRequest request;
    request.study = studyPath;
    request.participant = code;
    request.trial = trial.index;
    if (clips) request.walkSeconds = protocol.clips.seconds;
    const auto replay = wir::renderTrialReplay(request);
    std::printf("%s: %s\n", id.c_str(), replay.description.c_str());

    const std::size_t heard = ears.frames();
    const std::vector<float>& hl = ears.channel(0);
    const std::vector<float>& hr = ears.channel(1);
    const std::size_t rn = replay.audio.frames();
    // What the live scene played for replay frame i: the replay under the scene's fade-in.
    const auto expected = [&](std::size_t i, int c) {
        return eng::LiveScene::fadeGain(static_cast<std::int64_t>(i), 480) *
               replay.audio.samples[2 * i + static_cast<std::size_t>(c)];
    };
    std::size_t pf = 0, rf = 0;
    while (pf < heard && std::fabs(hl[pf]) + std::fabs(hr[pf]) < 1e-5f) ++pf;
    while (rf < rn && std::fabs(expected(rf, 0)) + std::fabs(expected(rf, 1)) < 1e-5f) ++rf;
    ASSERT_LT(pf, heard) << "nothing was heard";
    ASSERT_LT(rf, rn) << "the replay is silent";
    // The live frame of the replay's frame 0: the first-audible estimate, refined by the most
    // exact matches over 0.1 s from the first audible frame.
    long offset = static_cast<long>(pf) - static_cast<long>(rf);
    {
        std::size_t bestMatches = 0;
        long best = offset;
        for (long o = offset - 256; o <= offset + 256; ++o) {
            std::size_t matches = 0;
            for (std::size_t i = rf; i < rf + 4800 && i < rn; ++i) {
                const long j = o + static_cast<long>(i);
                if (j < 0 || j >= static_cast<long>(heard)) continue;
                const auto k = static_cast<std::size_t>(j);
                matches += hl[k] == expected(i, 0) && hr[k] == expected(i, 1);
            }
            if (matches > bestMatches) bestMatches = matches, best = o;
        }
        offset = best;
    }
    ASSERT_GE(offset, 0);
    const auto off = static_cast<std::size_t>(offset);
    const std::size_t n = std::min(heard - off, rn);
    std::printf("%s: %zu frames heard through JACK (%llu xruns during the test), replay %zu "
                "frames, compared %zu (%.2f s) from live frame %zu\n",
                id.c_str(), heard, static_cast<unsigned long long>(meters.xruns), rn, n,
                static_cast<double>(n) / kRate, off);
    ASSERT_GT(n, static_cast<std::size_t>(kRate)) << "less than a second to compare";

    {
        const double tolerance = compare == Compare::Clip24 ? std::ldexp(1.0, -23) : 0.0;
        const auto same = [&](std::size_t live, std::size_t i) {
            return std::fabs(double(expected(i, 0)) - hl[live]) <= tolerance &&
                   std::fabs(double(expected(i, 1)) - hr[live]) <= tolerance;
        };
        // Walk the replay frame by frame against what the ears heard. Under load the dummy
        // driver overruns (--no-realtime); in an overrun cycle JACK may run the ears client
        // without the engine's fresh output or not at all, so a whole period is missing from
        // the capture or held twice (never altered inside a period). Such a gap shows as a
        // mismatch at a period boundary after which the rest matches exactly a whole number of
        // periods earlier or later: it is skipped and counted, and the count must not exceed
        // the overruns JACK reported to the ears client.
        std::size_t compared = 0, mismatches = 0, firstMismatch = 0, gapFrames = 0;
        std::size_t damagedFrames = 0;
        int gaps = 0, damaged = 0;
        double maxDiff = 0;       // over the frames that match (within the tolerance)
        double worstMismatch = 0; // over those that do not
        long shift = 0;           // live position - (off + i)
        for (std::size_t i = 0; i < rn; ++i) {
            const long j = static_cast<long>(off + i) + shift;
            if (j < 0 || j >= static_cast<long>(heard)) break;
            if (same(static_cast<std::size_t>(j), i)) {
                ++compared;
                const auto k = static_cast<std::size_t>(j);
                maxDiff = std::max({maxDiff, std::fabs(double(expected(i, 0)) - hl[k]),
                                    std::fabs(double(expected(i, 1)) - hr[k])});
                continue;
            }
            // A period missing from the capture: the live stream resumes k periods earlier.
            bool resynced = false;
            for (long k = -8; k <= 8 && !resynced; ++k) {
                if (k == 0) continue;
                const long s2 = shift + k * kPeriod;
                const long j0 = static_cast<long>(off + i) + s2;
                if (j0 < 0) continue;
                std::size_t ok = 0;
                for (std::size_t m = 0; m < 4 * kPeriod && i + m < rn; ++m) {
                    const long jj = j0 + static_cast<long>(m);
                    if (jj >= static_cast<long>(heard)) break;
                    ok += same(static_cast<std::size_t>(jj), i + m);
                }
                // The gap started at a period boundary of the capture and the next 4 periods
                // match exactly.
                if (ok == 4 * kPeriod && j % kPeriod == 0) {
                    shift = s2;
                    ++gaps;
                    gapFrames += static_cast<std::size_t>(std::labs(k) * kPeriod);
                    resynced = true;
                }
            }
            if (resynced) {
                --i; // compare frame i again at the new shift
                continue;
            }
            // A period damaged in the capture (the ears ran before the engine finished writing
            // it): one or two periods at a period boundary, after which the stream matches on
            // at the same position.
            if (j % kPeriod == 0) {
                for (long k = 1; k <= 2 && !resynced; ++k) {
                    std::size_t ok = 0;
                    const std::size_t from = i + static_cast<std::size_t>(k * kPeriod);
                    for (std::size_t m = 0; m < 4 * kPeriod && from + m < rn; ++m) {
                        const long jj = j + k * kPeriod + static_cast<long>(m);
                        if (jj >= static_cast<long>(heard)) break;
                        ok += same(static_cast<std::size_t>(jj), from + m);
                    }
                    if (ok == 4 * kPeriod) {
                        ++damaged;
                        damagedFrames += static_cast<std::size_t>(k * kPeriod);
                        i = from - 1;
                        resynced = true;
                    }
                }
                if (resynced) continue;
            }
            if (!mismatches) firstMismatch = i;
            ++mismatches;
            ++compared;
            worstMismatch = std::max({worstMismatch, std::fabs(double(expected(i, 0)) - hl[j]),
                                      std::fabs(double(expected(i, 1)) - hr[j])});
        }
        if (mismatches)
            for (std::size_t i = firstMismatch; i < firstMismatch + 4 && i < rn; ++i) {
                const auto j = static_cast<std::size_t>(static_cast<long>(off + i) + shift);
                if (j < heard)
                    std::printf("  frame %zu: live %.9g %.9g, replay %.9g %.9g\n", i, hl[j], hr[j],
                                expected(i, 0), expected(i, 1));
            }
        if (stored.audio)
            std::printf("%s: GRF frames dropped by the recording ring: %llu\n", id.c_str(),
                        static_cast<unsigned long long>(stored.audio->droppedGrfFrames));
        std::printf(
            "%s: %s: %zu frames compared (%.2f s), %zu mismatching (largest %g), largest "
            "difference of the others %g; %d capture gaps (%zu frames) and %d damaged capture "
            "periods (%zu frames) skipped, %llu overruns reported to the ears client\n",
            id.c_str(),
            compare == Compare::Clip24 ? "within 2^-23 (the clip's 24-bit step)" : "bit for bit",
            compared, static_cast<double>(compared) / kRate, mismatches, worstMismatch, maxDiff,
            gaps, gapFrames, damaged, damagedFrames, static_cast<unsigned long long>(ears.xruns()));
        EXPECT_GT(compared, static_cast<std::size_t>(kRate)) << "less than a second compared";
        EXPECT_EQ(mismatches, 0u) << "first at frame " << firstMismatch << ", largest difference "
                                  << worstMismatch;
        EXPECT_LE(static_cast<std::uint64_t>(gaps + damaged), ears.xruns())
            << "capture gaps without an overrun";
        EXPECT_LT(gapFrames + damagedFrames, compared / 20) << "more than 5 % skipped";
    }
}

} // namespace

TEST_F(LiveProtocols, Tvcg2011Exp1MicrophonesReplayBitForBit) {
    run("tvcg2011_exp1", Compare::BitForBit);
}

TEST_F(LiveProtocols, Tvcg2011Exp2MicrophonesReplayBitForBit) {
    run("tvcg2011_exp2", Compare::BitForBit);
}

TEST_F(LiveProtocols, Eurohaptics2010FsrShoesReplayBitForBit) {
    run("eurohaptics2010", Compare::BitForBit);
}

TEST_F(LiveProtocols, WadingInteractiveGyroscopesReplayBitForBit) {
    run("wading_interactive", Compare::BitForBit);
}

TEST_F(LiveProtocols, WadingListeningClipReplaysToTheClipsStep) {
    run("wading_listening", Compare::Clip24);
}

TEST_F(LiveProtocols, WadingRealismClipReplaysToTheClipsStep) {
    run("wading_realism", Compare::Clip24);
}
