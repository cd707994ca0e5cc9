// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/wading/WadingScene.h"

#include "base/DataDir.h"
#include "base/TomlReader.h"
#include "engine/dsp/Denormals.h"
#include "engine/dsp/ProcessSpec.h"
#include "engine/io/AudioFile.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace underfoot::engine {

namespace fs = std::filesystem;

namespace {
constexpr int kChunk = WadingScene::kChunkSamples; // control/EQ update granularity, samples
} // namespace

// ---------------------------------------------------------------------------------------------
// Presets

std::string wadingPresetDirectory() {
    return base::dataDirectory(base::DataKind::WadingPresets);
}

WadingPreset parseWadingPreset(const std::string& text, const std::string& file) {
    const toml::table root =
        base::rethrowTomlAs<PresetError>([&] { return base::parseToml(text, file); });
    WadingPreset p;
    p.file = file;
    PresetReader top(file, root, "", &p.params);
    p.id = top.string("id", "", {}, "the preset id (required)");
    if (p.id.empty()) top.fail("id", "expected a preset id (a string)");
    p.name = top.string("name", p.id, {}, "the name shown (default: the id)");
    p.description = top.string("description", "", {}, "one line: what it sounds like");
    p.outputGainDb =
        top.number("output_gain_db", 0, -60, 24, "dB", "gain of the stereo sum (calibration)");

    auto& m = p.mapping;
    if (auto r = top.table("mapping", "how the legs' rotation drives the three sounds")) {
        m.normaliseRangeDps = r->number("normalise_range_dps", m.normaliseRangeDps, 10, 1000,
                                        "deg/s", "forward rotation mapped to 1 (paper: 100)");
        m.thighWeight = r->number("thigh_weight", m.thighWeight, 0, 4, "",
                                  "weight of each thigh in the C1 sum");
        m.shankWeight = r->number("shank_weight", m.shankWeight, 0, 4, "",
                                  "weight of each shank in the C2/C3 sums");
        m.attackMs = r->number("attack_ms", m.attackMs, 0, 1000, "ms", "follower attack (paper 0)");
        m.c1ReleaseMs =
            r->number("c1_release_ms", m.c1ReleaseMs, 0, 10000, "ms", "C1 release (paper 890)");
        m.c2ReleaseMs =
            r->number("c2_release_ms", m.c2ReleaseMs, 0, 10000, "ms", "C2 release (paper 2230)");
        m.c3ReleaseMs =
            r->number("c3_release_ms", m.c3ReleaseMs, 0, 10000, "ms", "C3 release (paper 890)");
        m.c1Exponent = r->number("c1_exponent", m.c1Exponent, 0.35, 6, "", "C1 k (paper 1.93)");
        m.c2Exponent = r->number("c2_exponent", m.c2Exponent, 0.35, 6, "", "C2 k (paper 2.56)");
        m.c3Exponent = r->number("c3_exponent", m.c3Exponent, 0.35, 6, "", "C3 k (paper 1)");
        m.splashDelayMs = r->number("splash_delay_ms", m.splashDelayMs, 0, 1000, "ms",
                                    "delay of the shank sum for C3 (paper 150)");
        m.flowingMinDb = r->number("flowing_min_db", m.flowingMinDb, -80, 0, "dB",
                                   "flowing fader at C1 = 0 (paper -33)");
        m.flowingMaxDb = r->number("flowing_max_db", m.flowingMaxDb, -60, 12, "dB",
                                   "flowing fader at C1 = 1 (paper 0)");
        m.eqMaxDb = r->number("eq_max_db", m.eqMaxDb, 0, 18, "dB", "EQ band gain at C1 = 1");
        m.eqLowHz = r->number("eq_low_hz", m.eqLowHz, 40, 2000, "Hz", "bubbling band (260)");
        m.eqHighHz = r->number("eq_high_hz", m.eqHighHz, 2000, 16000, "Hz", "splash band (9250)");
        m.eqQ = r->number("eq_q", m.eqQ, 0.2, 8, "", "Q of both EQ bands");
        m.bubblingMinDb = r->number("bubbling_min_db", m.bubblingMinDb, -80, 0, "dB",
                                    "bubbling fader at C2 = 0 (paper -38)");
        m.bubblingMaxDb = r->number("bubbling_max_db", m.bubblingMaxDb, -60, 12, "dB",
                                    "bubbling fader at C2 = 1 (paper -5)");
        m.splashMinDb = r->number("splash_min_db", m.splashMinDb, -80, 0, "dB",
                                  "splash fader at C3 = 0 (paper -40)");
        m.splashMaxDb = r->number("splash_max_db", m.splashMaxDb, -60, 12, "dB",
                                  "splash fader at C3 = 1 (paper +5)");
        m.restFade = r->number("rest_fade", m.restFade, 0, 0.5, "",
                               "controls below this fade the layer to silence");
        m.v1GainDb = r->number("v1_gain_db", m.v1GainDb, -60, 12, "dB", "v1 gain at c = 1");
        m.v1BubbleRateHz = r->number("v1_bubble_rate_hz", m.v1BubbleRateHz, 0, 4000, "1/s",
                                     "v1 bubble rate at c = 1", true);
        m.pan = r->number("pan", m.pan, 0, 1, "", "limb voices at -pan / +pan (paper 0.5)");
        r->finish();
        for (auto [lo, hi, name] : {std::tuple{m.flowingMinDb, m.flowingMaxDb, "flowing"},
                                    std::tuple{m.bubblingMinDb, m.bubblingMaxDb, "bubbling"},
                                    std::tuple{m.splashMinDb, m.splashMaxDb, "splash"}})
            if (!(hi > lo))
                r->fail(fmt::format("{}_max_db", name),
                        fmt::format("expected {}_max_db above {}_min_db", name, name));
    }
    const fs::path base = fs::path(file).parent_path();
    auto recording = [&](PresetReader& r) {
        std::string path =
            r.string("recording", "", {},
                     "a .wav file (relative to the preset) played instead of synthesis");
        if (!path.empty() && fs::path(path).is_relative()) path = (base / path).string();
        return path;
    };
    auto& f = p.flowing;
    if (auto r =
            top.table("flowing", "noise and small bubbles of the water moving past the legs")) {
        f.levelDb = r->number("level_db", f.levelDb, -80, 12, "dB", "level at fader 0 dB");
        f.noiseLowHz =
            r->number("noise_low_hz", f.noiseLowHz, 20, 5000, "Hz", "noise band low", true);
        f.noiseHighHz =
            r->number("noise_high_hz", f.noiseHighHz, 200, 20000, "Hz", "noise band high", true);
        f.noiseDb = r->number("noise_db", f.noiseDb, -120, 12, "dB", "noise part");
        f.gurgleHz = r->number("gurgle_hz", f.gurgleHz, 0.1, 30, "Hz", "level wander rate");
        f.gurgleDepthDb =
            r->number("gurgle_depth_db", f.gurgleDepthDb, 0, 24, "dB", "level wander depth");
        f.bubbleRateHz = r->number("bubble_rate_hz", f.bubbleRateHz, 0, 4000, "1/s",
                                   "small bubbles per second", true);
        f.radiusMinMm = r->number("radius_min_mm", f.radiusMinMm, 0.1, 20, "mm", "", true);
        f.radiusMaxMm = r->number("radius_max_mm", f.radiusMaxMm, 0.1, 30, "mm", "", true);
        f.radiusExponent = r->number("radius_exponent", f.radiusExponent, -6, 2, "", "p(r)~r^b");
        f.bubbleDb = r->number("bubble_db", f.bubbleDb, -120, 12, "dB", "bubble part");
        f.recording = recording(*r);
        r->finish();
        if (!(f.noiseHighHz > f.noiseLowHz))
            r->fail("noise_high_hz", "expected noise_high_hz above noise_low_hz");
        if (!(f.radiusMaxMm > f.radiusMinMm))
            r->fail("radius_max_mm", "expected radius_max_mm above radius_min_mm");
    }
    auto& b = p.bubbling;
    if (auto r = top.table("bubbling", "the steady bubble stream around the legs")) {
        b.levelDb = r->number("level_db", b.levelDb, -80, 12, "dB", "level at fader 0 dB");
        b.rateHz = r->number("rate_hz", b.rateHz, 0, 4000, "1/s", "bubbles per second", true);
        b.radiusMinMm = r->number("radius_min_mm", b.radiusMinMm, 0.1, 20, "mm", "", true);
        b.radiusMaxMm = r->number("radius_max_mm", b.radiusMaxMm, 0.1, 30, "mm", "", true);
        b.radiusExponent = r->number("radius_exponent", b.radiusExponent, -6, 2, "", "p(r)~r^b");
        b.xi = r->number("xi", b.xi, 0, 1, "", "pitch rise factor");
        b.recording = recording(*r);
        r->finish();
        if (!(b.radiusMaxMm > b.radiusMinMm))
            r->fail("radius_max_mm", "expected radius_max_mm above radius_min_mm");
    }
    auto& s = p.splash;
    if (auto r = top.table("splash", "light splashes: bursts of larger bubbles and noise")) {
        s.levelDb = r->number("level_db", s.levelDb, -80, 12, "dB", "level at fader 0 dB");
        s.rateHz =
            r->number("rate_hz", s.rateHz, 0.1, 200, "1/s", "splash events per second", true);
        s.bubblesPerSplash =
            r->number("bubbles_per_splash", s.bubblesPerSplash, 0, 200, "", "mean per event");
        s.radiusMinMm = r->number("radius_min_mm", s.radiusMinMm, 0.1, 20, "mm", "", true);
        s.radiusMaxMm = r->number("radius_max_mm", s.radiusMaxMm, 0.1, 30, "mm", "", true);
        s.noiseHz = r->number("noise_hz", s.noiseHz, 100, 15000, "Hz", "burst high-pass", true);
        s.noiseHighHz =
            r->number("noise_high_hz", s.noiseHighHz, 500, 20000, "Hz", "burst low-pass", true);
        s.noiseDecayMs =
            r->number("noise_decay_ms", s.noiseDecayMs, 2, 1000, "ms", "burst time constant");
        s.noiseDb = r->number("noise_db", s.noiseDb, -120, 12, "dB", "noise part");
        s.bubbleDb = r->number("bubble_db", s.bubbleDb, -120, 12, "dB", "bubble part");
        s.recording = recording(*r);
        r->finish();
        if (!(s.radiusMaxMm > s.radiusMinMm))
            r->fail("radius_max_mm", "expected radius_max_mm above radius_min_mm");
    }
    top.finish();
    return p;
}

WadingPreset loadWadingPreset(const std::string& nameOrPath) {
    std::string file = nameOrPath;
    const bool isName = !nameOrPath.empty() && nameOrPath.find('/') == std::string::npos &&
                        nameOrPath.find('.') == std::string::npos;
    if (isName) file = wadingPresetDirectory() + "/" + nameOrPath + ".toml";
    if (!fs::exists(file)) {
        if (isName)
            throw PresetError(fmt::format("{}: no wading preset \"{}\" (expected shallow, deep or "
                                          "a path to a .toml file)",
                                          file, nameOrPath));
        throw PresetError(file + ": no such wading preset file");
    }
    return parseWadingPreset(base::rethrowTomlAs<PresetError>([&] {
                                 return base::readTomlFile(file, "a wading preset (TOML)");
                             }),
                             file);
}

// ---------------------------------------------------------------------------------------------
// Scene

void WadingScene::configure(const WadingPreset& preset, WadingAlgorithm algorithm,
                            GyroFilter filter) {
    preset_ = preset;
    algorithm_ = algorithm;
    filter_ = filter;
    control_.configure(algorithm, filter, preset.mapping, 100.0);
}

void WadingScene::loadRecording(int layer, const std::string& path) {
    const AudioBuffer audio = readAudioFile(path, sampleRateHz_);
    const std::size_t frames = audio.frames();
    if (frames < 16)
        throw FileError(fmt::format("{}: expected a recording of at least 16 samples", path));
    const std::size_t fade =
        std::min<std::size_t>(static_cast<std::size_t>(0.05 * sampleRateHz_), frames / 4);
    for (int s = 0; s < 2; ++s) {
        const int ch = std::min(s, audio.channels - 1);
        std::vector<float> x = audio.channel(ch);
        // Loop with a crossfaded seam: the last `fade` samples fade into the first ones.
        std::vector<float> loop(frames - fade);
        for (std::size_t i = 0; i < loop.size(); ++i) {
            if (i < fade) {
                const float w = static_cast<float>(i) / static_cast<float>(fade);
                loop[i] = w * x[i] + (1.0f - w) * x[frames - fade + i];
            } else {
                loop[i] = x[i];
            }
        }
        Loop& l = voices_[static_cast<std::size_t>(s)].recording[layer];
        l.samples = std::move(loop);
        // A mono file: the right voice starts half-way through (decorrelated sides).
        l.pos = (s == 1 && audio.channels == 1) ? l.samples.size() / 2 : 0;
    }
}

void WadingScene::prepare(const ProcessSpec& spec) {
    if (!(spec.sampleRateHz >= 8000 && spec.sampleRateHz <= 384000))
        throw std::invalid_argument(
            fmt::format("wading: sample rate {} Hz outside [8000, 384000]", spec.sampleRateHz));
    sampleRateHz_ = spec.sampleRateHz;
    maxBlock_ = spec.maxBlockSize;
    const double fsr = sampleRateHz_;
    const auto& f = preset_.flowing;
    const auto& b = preset_.bubbling;
    const auto& s = preset_.splash;
    const double nyq = 0.45 * fsr;
    for (auto& v : voices_) {
        v.flowHp.setCoefficients(
            BiquadCoefficients::highpass(fsr, std::min(f.noiseLowHz, nyq), std::sqrt(0.5)));
        v.flowLp.setCoefficients(
            BiquadCoefficients::lowpass(fsr, std::min(f.noiseHighHz, nyq), std::sqrt(0.5)));
        BubbleStreamParameters fp;
        fp.radiusMinM = f.radiusMinMm * 1e-3;
        fp.radiusMaxM = f.radiusMaxMm * 1e-3;
        fp.radiusExponent = f.radiusExponent;
        fp.voices = 64;
        v.flowBubbles.configure(fp);
        v.flowBubbles.prepare(fsr, 4000);
        BubbleStreamParameters bp;
        bp.radiusMinM = b.radiusMinMm * 1e-3;
        bp.radiusMaxM = b.radiusMaxMm * 1e-3;
        bp.radiusExponent = b.radiusExponent;
        bp.xi = b.xi;
        bp.voices = 48;
        v.bubbles.configure(bp);
        v.bubbles.prepare(fsr, 4000);
        BubbleStreamParameters sp;
        sp.radiusMinM = s.radiusMinMm * 1e-3;
        sp.radiusMaxM = s.radiusMaxMm * 1e-3;
        sp.radiusExponent = -1.5;
        sp.voices = 64;
        v.splashBubbles.configure(sp);
        v.splashBubbles.prepare(fsr, 4000);
        v.splashHp.setCoefficients(
            BiquadCoefficients::highpass(fsr, std::min(s.noiseHz, nyq), std::sqrt(0.5)));
        v.splashLp.setCoefficients(
            BiquadCoefficients::lowpass(fsr, std::min(s.noiseHighHz, nyq), std::sqrt(0.5)));
        for (auto& g : v.gain) g.setRampSamples(static_cast<int>(std::lround(fsr / 100.0)));
        for (auto& r : v.recording) r = Loop{};
    }
    if (!f.recording.empty()) loadRecording(0, f.recording);
    if (!b.recording.empty()) loadRecording(1, b.recording);
    if (!s.recording.empty()) loadRecording(2, s.recording);
    eqDb_.setRampSamples(static_cast<int>(std::lround(fsr / 100.0)));
    rateScale_.setRampSamples(static_cast<int>(std::lround(fsr / 100.0)));
    scratchA_.assign(kChunk, 0.0f);
    scratchB_.assign(kChunk, 0.0f);
    scratchC_.assign(kChunk, 0.0f);
    rate_.assign(kChunk, 0.0f);
    ones_.assign(kChunk, 1.0f);
    zeros_.assign(kChunk, 0.0f);
    flowNoiseGain_ = dbToGain(f.noiseDb);
    flowBubbleGain_ = dbToGain(f.bubbleDb);
    splashNoiseGain_ = dbToGain(s.noiseDb);
    splashBubbleGain_ = dbToGain(s.bubbleDb);
    splashDecayG_ = std::exp(-1.0 / (s.noiseDecayMs * 1e-3 * fsr));
    gurgleG_ = std::exp(-1.0 / (0.5 / f.gurgleHz * fsr));
    layerLevel_[0] = dbToGain(f.levelDb);
    layerLevel_[1] = dbToGain(b.levelDb);
    layerLevel_[2] = dbToGain(s.levelDb);
    const double pan = preset_.mapping.pan;
    for (int v = 0; v < 2; ++v) {
        const double pos = v == 0 ? -pan : pan;
        const double theta = (pos + 1.0) * kPi / 4.0;
        panGain_[v][0] = std::cos(theta);
        panGain_[v][1] = std::sin(theta);
    }
    outputGain_ = dbToGain(preset_.outputGainDb);
    reset(1);
}

void WadingScene::reset(std::uint64_t seed) noexcept {
    control_.reset();
    for (std::size_t s = 0; s < 2; ++s) {
        Voice& v = voices_[s];
        v.flowHp.reset();
        v.flowLp.reset();
        v.splashHp.reset();
        v.splashLp.reset();
        v.eqLow.reset();
        v.eqHigh.reset();
        v.flowBubbles.reset(Random::deriveSeed(seed, 10 + s));
        v.bubbles.reset(Random::deriveSeed(seed, 20 + s));
        v.splashBubbles.reset(Random::deriveSeed(seed, 30 + s));
        v.random.setSeed(Random::deriveSeed(seed, 40 + s));
        v.gurgle = v.gurgleTarget = 0;
        v.gurgleCountdown = 0;
        v.splashEnv = 0;
        v.splashWait = v.random.exponential(preset_.splash.rateHz) * sampleRateHz_;
        for (auto& g : v.gain) g.reset(0.0);
        for (auto& r : v.recording)
            if (!r.samples.empty()) r.pos = (s == 1) ? r.samples.size() / 2 : 0;
    }
    eqDb_.reset(0.0);
    rateScale_.reset(algorithm_ == WadingAlgorithm::V1 ? 0.0 : 1.0);
    currentEqDb_ = -1;
    pending_ = false;
    sample_ = 0;
}

void WadingScene::pushFrame(const GaitFrame& frame) noexcept {
    if (pending_) applyFrame(pendingFrame_); // two frames in one block: keep both in the chain
    pendingFrame_ = frame;
    pending_ = true;
}

void WadingScene::applyFrame(const GaitFrame& frame) noexcept {
    const WadingControls& c = control_.push(frame);
    for (std::size_t s = 0; s < 2; ++s)
        for (std::size_t k = 0; k < kWadingLayerCount; ++k)
            voices_[s].gain[k].setTarget(c.gain[k][s]);
    eqDb_.setTarget(c.eqDb);
    rateScale_.setTarget(c.bubbleRateScale);
}

void WadingScene::process(const TimedGaitFrame* frames, int frameCount, float* left, float* right,
                          int n) noexcept {
    ScopedFlushDenormals ftz;
    if (pending_) {
        applyFrame(pendingFrame_);
        pending_ = false;
    }
    int fi = 0;
    int pos = 0;
    while (pos < n) {
        while (fi < frameCount && frames[fi].offset <= pos) applyFrame(frames[fi++].frame);
        int end = n;
        if (fi < frameCount) end = std::min(n, std::max(pos + 1, frames[fi].offset));
        // The chunk controls are decided on a fixed grid of kChunk samples counted from reset,
        // never where a host block starts, so the output does not depend on the block size;
        // a frame still takes effect at its own sample (the per-sample ramps).
        const int phase = static_cast<int>((sample_ + pos) % kChunk);
        if (phase == 0) chunkControls();
        const int len = std::min(end - pos, kChunk - phase);
        renderChunk(left + pos, right + pos, len, phase);
        pos += len;
    }
    while (fi < frameCount) applyFrame(frames[fi++].frame); // offsets >= n: at the block's end
    sample_ += n;
}

void WadingScene::chunkControls() noexcept {
    // EQ gain of the next kChunk samples (the C1 bands): the ramp's value at the chunk's end,
    // as far as the frames known now take it.
    ControlRamp ahead = eqDb_;
    double eq = ahead.value();
    for (int i = 0; i < kChunk; ++i) eq = ahead.next();
    const auto& m = preset_.mapping;
    const bool eqChanged = std::fabs(eq - currentEqDb_) > 0.01;
    if (eqChanged) currentEqDb_ = eq;
    const auto& f = preset_.flowing;
    for (std::size_t s = 0; s < 2; ++s) {
        Voice& v = voices_[s];
        if (eqChanged) {
            v.eqLow.setCoefficients(BiquadCoefficients::peaking(
                sampleRateHz_, std::min(m.eqLowHz, 0.45 * sampleRateHz_), m.eqQ, eq));
            v.eqHigh.setCoefficients(BiquadCoefficients::peaking(
                sampleRateHz_, std::min(m.eqHighHz, 0.45 * sampleRateHz_), m.eqQ, eq));
        }
        if (v.recording[0].samples.empty()) { // the flow's gurgle, per chunk
            if (--v.gurgleCountdown <= 0) {
                v.gurgleTarget = f.gurgleDepthDb * (v.random.uniform() - 0.5);
                v.gurgleCountdown = std::max(
                    1, static_cast<int>(v.random.exponential(f.gurgleHz) * sampleRateHz_ / kChunk));
            }
            v.gurgle = v.gurgleTarget + std::pow(gurgleG_, kChunk) * (v.gurgle - v.gurgleTarget);
            for (auto& w : v.flowNoise) w = v.random.bipolar();
        }
    }
}

void WadingScene::renderChunk(float* left, float* right, int n, int phase) noexcept {
    // Rate scale per sample; the EQ ramp advances here, its coefficients change per chunk.
    for (int i = 0; i < n; ++i) eqDb_.next();
    const auto& m = preset_.mapping;
    const double bubbleRate =
        algorithm_ == WadingAlgorithm::V1 ? m.v1BubbleRateHz : preset_.bubbling.rateHz;
    for (int i = 0; i < n; ++i)
        rate_[static_cast<std::size_t>(i)] = static_cast<float>(bubbleRate * rateScale_.next());
    const auto& f = preset_.flowing;
    const auto& sp = preset_.splash;
    const float flowRate = static_cast<float>(f.bubbleRateHz);
    const double splashBubbleRate = sp.bubblesPerSplash / (sp.noiseDecayMs * 1e-3);
    const bool splashOn = algorithm_ == WadingAlgorithm::V2;
    float* a = scratchA_.data();
    float* b = scratchB_.data();
    float* c = scratchC_.data();
    std::fill(left, left + n, 0.0f);
    std::fill(right, right + n, 0.0f);
    float flowRates[kChunk];
    float splashRates[kChunk];
    std::fill(flowRates, flowRates + n, flowRate);
    for (std::size_t s = 0; s < 2; ++s) {
        Voice& v = voices_[s];
        // Flowing.
        if (!v.recording[0].samples.empty()) {
            for (int i = 0; i < n; ++i) a[i] = v.recording[0].next();
        } else {
            const double noiseGain = flowNoiseGain_ * dbToGain(v.gurgle);
            for (int i = 0; i < n; ++i)
                a[i] = static_cast<float>(noiseGain * v.flowLp.processSample(v.flowHp.processSample(
                                                          v.flowNoise[phase + i])));
            std::fill(b, b + n, 0.0f);
            v.flowBubbles.process(flowRates, ones_.data(), b, n);
            for (int i = 0; i < n; ++i) a[i] += static_cast<float>(flowBubbleGain_ * b[i]);
        }
        for (int i = 0; i < n; ++i)
            a[i] = static_cast<float>(v.eqHigh.processSample(v.eqLow.processSample(a[i])));
        // Bubbling.
        std::fill(b, b + n, 0.0f);
        if (!v.recording[1].samples.empty()) {
            for (int i = 0; i < n; ++i) b[i] = v.recording[1].next();
        } else {
            v.bubbles.process(rate_.data(), ones_.data(), b, n);
        }
        // Splash.
        std::fill(c, c + n, 0.0f);
        if (splashOn) {
            if (!v.recording[2].samples.empty()) {
                for (int i = 0; i < n; ++i) c[i] = v.recording[2].next();
            } else {
                for (int i = 0; i < n; ++i) {
                    v.splashWait -= 1.0;
                    while (v.splashWait <= 0.0) {
                        v.splashEnv += v.random.uniform(0.5, 1.0);
                        v.splashWait += v.random.exponential(sp.rateHz) * sampleRateHz_;
                    }
                    v.splashEnv = snapToZero(v.splashEnv * splashDecayG_);
                    splashRates[i] = static_cast<float>(splashBubbleRate * v.splashEnv);
                    c[i] = static_cast<float>(
                        splashNoiseGain_ * v.splashEnv *
                        v.splashLp.processSample(v.splashHp.processSample(v.random.bipolar())));
                }
                float tmp[kChunk];
                std::fill(tmp, tmp + n, 0.0f);
                v.splashBubbles.process(splashRates, ones_.data(), tmp, n);
                for (int i = 0; i < n; ++i) c[i] += static_cast<float>(splashBubbleGain_ * tmp[i]);
            }
        }
        const double l0 = layerLevel_[0] * outputGain_, l1 = layerLevel_[1] * outputGain_,
                     l2 = layerLevel_[2] * outputGain_;
        const double pl = panGain_[s][0], pr = panGain_[s][1];
        for (int i = 0; i < n; ++i) {
            const double mono = l0 * v.gain[0].next() * a[i] + l1 * v.gain[1].next() * b[i] +
                                l2 * v.gain[2].next() * c[i];
            left[i] += static_cast<float>(pl * mono);
            right[i] += static_cast<float>(pr * mono);
        }
    }
}

} // namespace underfoot::engine
