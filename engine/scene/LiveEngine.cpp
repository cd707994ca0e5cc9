// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/scene/LiveEngine.h"

#include <RtAudio.h>
#include <boost/lockfree/spsc_queue.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace underfoot::engine {

namespace {

constexpr int kCommandCapacity = 32;
constexpr int kRetiredCapacity = 256;
constexpr float kProbeThreshold = 0.5f;

/// Publishes a double through an atomic (lock-free on every platform we build for).
void store(std::atomic<double>& a, double v) noexcept {
    a.store(v, std::memory_order_relaxed);
}

} // namespace

struct DeviceCallback {
    static int run(void* out, void* in, unsigned int frames, double, RtAudioStreamStatus status,
                   void* self) {
        auto* e = static_cast<LiveEngine*>(self);
        // Non-interleaved buffers: channel c starts at c * frames.
        const int n = static_cast<int>(frames);
        auto* o = static_cast<float*>(out);
        auto* i = static_cast<float*>(in);
        for (int c = 0; c < e->numOutputs_; ++c)
            e->callbackOut_[static_cast<std::size_t>(c)] = o + static_cast<std::ptrdiff_t>(c) * n;
        for (int c = 0; c < e->numInputs_; ++c)
            e->callbackIn_[static_cast<std::size_t>(c)] =
                i ? i + static_cast<std::ptrdiff_t>(c) * n : nullptr;
        e->processBlock(i ? e->callbackIn_.data() : nullptr, e->callbackOut_.data(), n,
                        status != 0);
        return 0;
    }
};

struct LiveEngine::Device {
    std::unique_ptr<RtAudio> audio;
    bool running = false;
};

struct LiveEngine::Command {
    enum class Type { Swap, Probe } type = Type::Swap;
    LiveScene* scene = nullptr;
    int out = -1, in = -1;
};

struct LiveEngine::Queues {
    boost::lockfree::spsc_queue<Command, boost::lockfree::capacity<kCommandCapacity>> commands;
    boost::lockfree::spsc_queue<LiveScene*, boost::lockfree::capacity<kRetiredCapacity>> retired;
};

struct LiveEngine::Published {
    std::array<std::atomic<float>, LiveMeters::kMaxChannels> outPeak{}, outRms{}, inPeak{};
    std::atomic<float> grfPeak{0};
    std::atomic<std::uint64_t> xruns{0}, blocks{0}, frames{0}, swapped{0}, retired{0}, dropped{0};
    std::atomic<double> lastBlock{0}, maxBlock{0}, totalBlock{0}, lastLoad{0}, maxLoad{0};
    std::atomic<long long> probe{-1};
    std::atomic<std::uint64_t> limited{0};
    std::atomic<double> limiterMaxDb{0};
    std::atomic<bool> busy{false}; ///< a scene is fading or waits to be handed back
};

LiveEngine::LiveEngine()
    : queues_(std::make_unique<Queues>()), pub_(std::make_unique<Published>()) {}

LiveEngine::~LiveEngine() {
    close();
}

void LiveEngine::openCommon(const AudioSettings& s) {
    s.validate();
    close();
    settings_ = s;
    numOutputs_ = s.channels.outputChannelCount();
    numInputs_ = s.channels.inputChannelCount();
    pub_ = std::make_unique<Published>();
    framesTotal_ = 0;
    probe_ = {};
    for (auto& l : limiters_) l.prepare(s.sampleRateHz);
}

void LiveEngine::openOffline(const AudioSettings& settings) {
    openCommon(settings);
    offline_ = true;
    openedApi_ = "offline";
    openedDevice_ = "none";
    crossfadeFrames_ =
        static_cast<int>(std::lround(settings_.crossfadeMs * 0.001 * settings_.sampleRateHz));
    silence_.assign(static_cast<std::size_t>(settings_.blockSize), 0.0f);
}

void LiveEngine::open(const AudioSettings& settings) {
    openCommon(settings);
    offline_ = false;
    auto dev = std::make_unique<Device>();
    RtAudio::Api api = RtAudio::UNSPECIFIED;
    if (!settings_.api.empty()) {
        api = RtAudio::getCompiledApiByName(settings_.api);
        if (api == RtAudio::UNSPECIFIED) {
            std::string list;
            for (const auto& a : compiledAudioApis()) list += (list.empty() ? "" : ", ") + a;
            throw AudioSettingsError(
                fmt::format("audio API \"{}\" is not compiled into RtAudio; expected one of: {}",
                            settings_.api, list));
        }
    }
    try {
        dev->audio = std::make_unique<RtAudio>(api);
    } catch (const RtAudioError& e) {
        throw AudioSettingsError(
            fmt::format("audio API \"{}\": {}", settings_.api, e.getMessage()));
    }
    dev->audio->showWarnings(false);
    auto& audio = *dev->audio;
    const std::string apiName = RtAudio::getApiName(audio.getCurrentApi());
    // What the open settled on, for the checks and the names after it.
    std::string outName;
    unsigned int frames = 0;
    for (int attempt = 0;; ++attempt) {
        const unsigned count = audio.getDeviceCount();
        std::vector<RtAudio::DeviceInfo> infos(count);
        for (unsigned i = 0; i < count; ++i) {
            try {
                infos[i] = audio.getDeviceInfo(i);
            } catch (const RtAudioError&) {
                infos[i].probed = false;
            }
        }
        auto describe = [&] {
            std::string list;
            for (const auto& info : infos)
                if (info.probed)
                    list += fmt::format("{}\"{}\" ({} in, {} out)", list.empty() ? "" : ", ",
                                        info.name, info.inputChannels, info.outputChannels);
            return list.empty() ? std::string("none") : list;
        };
        auto find = [&](const std::string& name, bool output) -> unsigned {
            if (name.empty()) {
                const unsigned d =
                    output ? audio.getDefaultOutputDevice() : audio.getDefaultInputDevice();
                if (d < count && infos[d].probed) return d;
                throw AudioSettingsError(fmt::format("audio API \"{}\" has no default {} device; "
                                                     "devices: {}",
                                                     apiName, output ? "output" : "input",
                                                     describe()));
            }
            for (unsigned i = 0; i < count; ++i)
                if (infos[i].probed && infos[i].name == name) return i;
            throw AudioSettingsError(fmt::format(
                "audio device \"{}\" not found on API \"{}\"; expected one of: {} (see `underfoot "
                "devices`)",
                name, apiName, describe()));
        };
        const unsigned outId = find(settings_.device, true);
        const unsigned inId =
            numInputs_ > 0
                ? find(settings_.inputDevice.empty() ? infos[outId].name : settings_.inputDevice,
                       false)
                : outId;
        if (static_cast<int>(infos[outId].outputChannels) < numOutputs_)
            throw AudioSettingsError(fmt::format(
                "audio device \"{}\" has {} output channels; the channel map uses {} (headphones "
                "{}/{}{})",
                infos[outId].name, infos[outId].outputChannels, numOutputs_,
                settings_.channels.headphonesLeft + 1, settings_.channels.headphonesRight + 1,
                settings_.channels.hasHaptics() ? " and haptic actuators" : ""));
        if (numInputs_ > 0 && static_cast<int>(infos[inId].inputChannels) < numInputs_)
            throw AudioSettingsError(
                fmt::format("audio device \"{}\" has {} input channels; the microphones need {}",
                            infos[inId].name, infos[inId].inputChannels, numInputs_));

        RtAudio::StreamParameters outParams, inParams;
        outParams.deviceId = outId;
        outParams.nChannels = static_cast<unsigned>(numOutputs_);
        inParams.deviceId = inId;
        inParams.nChannels = static_cast<unsigned>(numInputs_);
        RtAudio::StreamOptions options;
        options.flags = RTAUDIO_NONINTERLEAVED | RTAUDIO_MINIMIZE_LATENCY;
        if (settings_.portConnection == AudioSettings::PortConnection::Manual)
            options.flags |= RTAUDIO_JACK_DONT_CONNECT;
        options.streamName = settings_.clientName;
        frames = static_cast<unsigned>(settings_.blockSize);
        try {
            audio.openStream(&outParams, numInputs_ > 0 ? &inParams : nullptr, RTAUDIO_FLOAT32,
                             static_cast<unsigned>(settings_.sampleRateHz), &frames,
                             &DeviceCallback::run, this, &options);
        } catch (const RtAudioError& e) {
            // openStream lists the devices again and refuses an id that is no longer in the list:
            // the list changed between the lookup above and the open (a device went away, or the
            // JACK server did not answer openStream's own probe on a loaded machine). The names
            // are looked up again, once; a device that is really gone is then "not found".
            const std::string why = e.getMessage();
            if (attempt == 0 && why.find("device parameter value is invalid") != std::string::npos)
                continue;
            throw AudioSettingsError(fmt::format("audio device \"{}\" ({}) refused a {}-in/{}-out "
                                                 "stream at {} Hz, {} frames: {}",
                                                 infos[outId].name, apiName, numInputs_,
                                                 numOutputs_, settings_.sampleRateHz,
                                                 settings_.blockSize, why));
        }
        outName = infos[outId].name;
        break;
    }
    const unsigned rate = audio.getStreamSampleRate();
    if (rate != 0 && static_cast<int>(rate) != settings_.sampleRateHz) {
        audio.closeStream();
        throw AudioSettingsError(fmt::format(
            "audio device \"{}\" runs at {} Hz, the settings ask for {} Hz (change one of them)",
            outName, rate, settings_.sampleRateHz));
    }
    settings_.blockSize = static_cast<int>(frames);
    openedApi_ = apiName;
    openedDevice_ = outName;
    crossfadeFrames_ =
        static_cast<int>(std::lround(settings_.crossfadeMs * 0.001 * settings_.sampleRateHz));
    silence_.assign(static_cast<std::size_t>(settings_.blockSize), 0.0f);
    device_ = std::move(dev);
}

void LiveEngine::start() {
    if (!device_) throw AudioSettingsError("LiveEngine::start: no device is open");
    if (device_->running) return;
    try {
        device_->audio->startStream();
    } catch (const RtAudioError& e) {
        throw AudioSettingsError(
            fmt::format("starting the audio stream on \"{}\": {}", openedDevice_, e.getMessage()));
    }
    device_->running = true;
}

void LiveEngine::stop() {
    if (device_ && device_->running) {
        try {
            if (device_->audio->isStreamRunning()) device_->audio->stopStream();
        } catch (const RtAudioError&) {
            // A server that went away has stopped the stream already.
        }
        device_->running = false;
    }
    collectRetired();
}

void LiveEngine::close() {
    stop();
    if (device_) {
        try {
            if (device_->audio->isStreamOpen()) device_->audio->closeStream();
        } catch (const RtAudioError&) {
        }
        device_.reset();
    }
    releaseAll();
    offline_ = false;
}

bool LiveEngine::isOpen() const noexcept {
    return offline_ || device_ != nullptr;
}

bool LiveEngine::isRunning() const noexcept {
    return device_ && device_->running;
}

ProcessSpec LiveEngine::processSpec() const noexcept {
    return {static_cast<double>(settings_.sampleRateHz), settings_.blockSize};
}

long LiveEngine::deviceLatencyFrames() const {
    if (!device_) return 0;
    try {
        return device_->audio->getStreamLatency();
    } catch (const RtAudioError&) {
        return 0;
    }
}

void LiveEngine::releaseAll() {
    // Only when the callback cannot run (stream stopped or closed, or offline between blocks).
    Command c;
    while (queues_->commands.pop(c)) delete c.scene;
    submitted_ = taken_.load();
    collectRetired();
    delete current_;
    delete fading_;
    current_ = fading_ = nullptr;
    for (auto*& p : pending_) {
        delete p;
        p = nullptr;
    }
    pub_->busy = false;
}

bool LiveEngine::submit(std::unique_ptr<LiveScene> scene) {
    collectRetired();
    Command c;
    c.type = Command::Type::Swap;
    c.scene = scene.get();
    if (!queues_->commands.push(c)) {
        pub_->dropped.fetch_add(1, std::memory_order_relaxed);
        return false; // `scene` is released here, on the main thread
    }
    submitted_.fetch_add(1, std::memory_order_release);
    (void)scene.release(); // now owned by the audio thread until handed back
    return true;
}

int LiveEngine::collectRetired() {
    int n = 0;
    LiveScene* s = nullptr;
    while (queues_->retired.pop(s)) {
        delete s;
        ++n;
    }
    return n;
}

std::vector<std::unique_ptr<LiveScene>> LiveEngine::takeRetired() {
    std::vector<std::unique_ptr<LiveScene>> out;
    LiveScene* s = nullptr;
    while (queues_->retired.pop(s)) out.emplace_back(s);
    return out;
}

bool LiveEngine::idle() const noexcept {
    return taken_.load(std::memory_order_acquire) == submitted_.load(std::memory_order_acquire) &&
           !pub_->busy.load(std::memory_order_acquire);
}

bool LiveEngine::waitIdle(double timeoutSeconds) {
    const auto end =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
    while (!idle()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
}

bool LiveEngine::probeLatency(int outputChannel, int inputChannel) {
    if (outputChannel < 0 || outputChannel >= numOutputs_ || inputChannel < 0 ||
        inputChannel >= numInputs_)
        throw std::invalid_argument(
            fmt::format("latency probe: output {} / input {} are not open channels ({} out, {} in)",
                        outputChannel + 1, inputChannel + 1, numOutputs_, numInputs_));
    pub_->probe.store(-1);
    Command c;
    c.type = Command::Type::Probe;
    c.out = outputChannel;
    c.in = inputChannel;
    if (!queues_->commands.push(c)) return false;
    submitted_.fetch_add(1, std::memory_order_release);
    return true;
}

LiveMeters LiveEngine::meters() const noexcept {
    LiveMeters m;
    m.outputChannels = std::min(numOutputs_, LiveMeters::kMaxChannels);
    m.inputChannels = std::min(numInputs_, LiveMeters::kMaxChannels);
    for (int c = 0; c < LiveMeters::kMaxChannels; ++c) {
        const auto i = static_cast<std::size_t>(c);
        m.outputPeak[i] = pub_->outPeak[i].load(std::memory_order_relaxed);
        m.outputRms[i] = pub_->outRms[i].load(std::memory_order_relaxed);
        m.inputPeak[i] = pub_->inPeak[i].load(std::memory_order_relaxed);
    }
    m.grfPeakNewtons = pub_->grfPeak.load(std::memory_order_relaxed);
    m.xruns = pub_->xruns.load(std::memory_order_relaxed);
    m.blocks = pub_->blocks.load(std::memory_order_relaxed);
    m.frames = pub_->frames.load(std::memory_order_relaxed);
    m.lastBlockSeconds = pub_->lastBlock.load(std::memory_order_relaxed);
    m.maxBlockSeconds = pub_->maxBlock.load(std::memory_order_relaxed);
    m.loadPercent = pub_->lastLoad.load(std::memory_order_relaxed);
    m.maxLoadPercent = pub_->maxLoad.load(std::memory_order_relaxed);
    const double audioSeconds = static_cast<double>(m.frames) / std::max(1, settings_.sampleRateHz);
    m.averageLoadPercent =
        audioSeconds > 0 ? 100.0 * pub_->totalBlock.load(std::memory_order_relaxed) / audioSeconds
                         : 0.0;
    m.scenesSwapped = pub_->swapped.load(std::memory_order_relaxed);
    m.scenesRetired = pub_->retired.load(std::memory_order_relaxed);
    m.droppedCommands = pub_->dropped.load(std::memory_order_relaxed);
    m.probeLatencyFrames = pub_->probe.load(std::memory_order_relaxed);
    m.limitedSamples = pub_->limited.load(std::memory_order_relaxed);
    m.limiterMaxReductionDb = pub_->limiterMaxDb.load(std::memory_order_relaxed);
    return m;
}

void LiveEngine::resetPeaks() noexcept {
    store(pub_->maxBlock, 0.0);
    store(pub_->maxLoad, 0.0);
}

void LiveEngine::retire(LiveScene* scene) noexcept {
    if (!scene) return;
    pub_->retired.fetch_add(1, std::memory_order_relaxed);
    if (queues_->retired.push(scene)) return;
    for (auto*& p : pending_)
        if (!p) {
            p = scene;
            return;
        }
    // Cannot happen while the main thread calls submit()/collectRetired() (the retired queue
    // holds more scenes than can be in flight); keep the scene alive rather than free it here.
    leaked_.fetch_add(1, std::memory_order_relaxed);
}

void LiveEngine::processBlock(const float* const* inputs, float* const* outputs, int n,
                              bool xrun) noexcept {
    if (hooks_.enter) hooks_.enter();
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    if (xrun) pub_->xruns.fetch_add(1, std::memory_order_relaxed);

    // Hand back scenes that could not be returned earlier.
    for (auto*& p : pending_)
        if (p && queues_->retired.push(p)) p = nullptr;

    Command c;
    while (queues_->commands.pop(c)) {
        if (c.type == Command::Type::Swap) {
            if (fading_) retire(fading_); // a swap during a fade cuts the oldest scene
            fading_ = current_;
            if (fading_) fading_->startFadeOut(crossfadeFrames_);
            current_ = c.scene;
            if (current_) {
                current_->setFadeIn(crossfadeFrames_);
                pub_->swapped.fetch_add(1, std::memory_order_relaxed);
            }
        } else {
            probe_ = {c.out, c.in, -1, true};
        }
        taken_.fetch_add(1, std::memory_order_release);
    }

    for (int ch = 0; ch < numOutputs_; ++ch) std::fill(outputs[ch], outputs[ch] + n, 0.0f);
    // Blocks longer than the prepared size (a device that changed its period) run in pieces.
    const int maxBlock = std::max(1, settings_.blockSize);
    for (int start = 0; start < n; start += maxBlock) {
        const int m = std::min(maxBlock, n - start);
        std::array<const float*, 64> in{};
        std::array<float*, 64> out{};
        for (int ch = 0; ch < numInputs_ && ch < 64; ++ch)
            in[static_cast<std::size_t>(ch)] =
                inputs && inputs[ch] ? inputs[ch] + start : silence_.data();
        for (int ch = 0; ch < numOutputs_ && ch < 64; ++ch)
            out[static_cast<std::size_t>(ch)] = outputs[ch] + start;
        if (current_) current_->process(in.data(), numInputs_, out.data(), numOutputs_, m);
        if (fading_) fading_->process(in.data(), numInputs_, out.data(), numOutputs_, m);
    }
    // Output safety limiter: transparent below -0.3 dBFS, reported in the meters when it acts.
    {
        std::uint64_t limited = 0;
        double deepest = pub_->limiterMaxDb.load(std::memory_order_relaxed);
        for (int ch = 0; ch < numOutputs_ && ch < 64; ++ch) {
            auto& lim = limiters_[static_cast<std::size_t>(ch)];
            const auto before = lim.report().samplesLimited;
            lim.process(outputs[ch], nullptr, n);
            limited += static_cast<std::uint64_t>(lim.report().samplesLimited - before);
            deepest = std::max(deepest, lim.report().maxReductionDb);
        }
        if (limited > 0) {
            pub_->limited.fetch_add(limited, std::memory_order_relaxed);
            store(pub_->limiterMaxDb, deepest);
        }
    }
    if (fading_ && fading_->fadedOut()) {
        retire(fading_);
        fading_ = nullptr;
    }
    bool pendingAny = false;
    for (auto* p : pending_) pendingAny = pendingAny || p != nullptr;
    pub_->busy.store(fading_ != nullptr || pendingAny, std::memory_order_release);

    // Latency probe: one full-scale sample out, first sample above threshold in.
    if (probe_.active) {
        if (probe_.emittedAt >= 0 && inputs && inputs[probe_.in]) {
            for (int i = 0; i < n; ++i)
                if (std::fabs(inputs[probe_.in][i]) > kProbeThreshold) {
                    pub_->probe.store(static_cast<long long>(framesTotal_) + i - probe_.emittedAt,
                                      std::memory_order_relaxed);
                    probe_.active = false;
                    break;
                }
            if (probe_.active &&
                static_cast<long long>(framesTotal_) - probe_.emittedAt > settings_.sampleRateHz)
                probe_.active = false; // nothing came back within a second
        }
        if (probe_.active && probe_.emittedAt < 0) {
            outputs[probe_.out][0] = 1.0f;
            probe_.emittedAt = static_cast<long long>(framesTotal_);
        }
    }

    // Meters.
    for (int ch = 0; ch < numOutputs_ && ch < LiveMeters::kMaxChannels; ++ch) {
        float peak = 0.0f;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
            const float x = outputs[ch][i];
            peak = std::max(peak, std::fabs(x));
            sum += static_cast<double>(x) * x;
        }
        const auto k = static_cast<std::size_t>(ch);
        pub_->outPeak[k].store(peak, std::memory_order_relaxed);
        pub_->outRms[k].store(n > 0 ? static_cast<float>(std::sqrt(sum / n)) : 0.0f,
                              std::memory_order_relaxed);
    }
    for (int ch = 0; ch < numInputs_ && ch < LiveMeters::kMaxChannels; ++ch) {
        float peak = 0.0f;
        if (inputs && inputs[ch])
            for (int i = 0; i < n; ++i) peak = std::max(peak, std::fabs(inputs[ch][i]));
        pub_->inPeak[static_cast<std::size_t>(ch)].store(peak, std::memory_order_relaxed);
    }
    pub_->grfPeak.store(current_ ? current_->lastGrfPeakNewtons() : 0.0f,
                        std::memory_order_relaxed);
    framesTotal_ += static_cast<std::uint64_t>(n);
    pub_->frames.store(framesTotal_, std::memory_order_relaxed);
    pub_->blocks.fetch_add(1, std::memory_order_relaxed);

    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    const double load = n > 0 ? 100.0 * seconds * settings_.sampleRateHz / n : 0.0;
    store(pub_->lastBlock, seconds);
    store(pub_->lastLoad, load);
    store(pub_->totalBlock, pub_->totalBlock.load(std::memory_order_relaxed) + seconds);
    if (seconds > pub_->maxBlock.load(std::memory_order_relaxed)) store(pub_->maxBlock, seconds);
    if (load > pub_->maxLoad.load(std::memory_order_relaxed)) store(pub_->maxLoad, load);
    if (hooks_.leave) hooks_.leave();
}

} // namespace underfoot::engine
