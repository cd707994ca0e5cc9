// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/ClipPlayer.h"

#include "app/wiring/StimulusRender.h"
#include "engine/scene/LiveScene.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace underfoot::wiring {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

namespace {

/// A whole clip held in memory, played once as the scene's stereo ambience.
class ClipAmbience final : public eng::AmbienceSource {
  public:
    explicit ClipAmbience(eng::AudioBuffer clip) : clip_(std::move(clip)) {}
    void prepare(const eng::ProcessSpec&) override {}
    void reset(std::uint64_t) noexcept override { position_ = 0; }
    void process(float* left, float* right, int n) noexcept override {
        const std::size_t frames = clip_.frames();
        const int ch = clip_.channels;
        for (int i = 0; i < n; ++i, ++position_) {
            if (position_ >= frames) {
                left[i] = right[i] = 0.0f;
                continue;
            }
            const float* f = clip_.samples.data() + position_ * static_cast<std::size_t>(ch);
            left[i] = f[0];
            right[i] = ch > 1 ? f[1] : f[0];
        }
    }
    std::string name() const override { return "clip"; }

  private:
    eng::AudioBuffer clip_;
    std::size_t position_ = 0;
};

/// No force at all: the scene's surface voices stay asleep.
class SilentGrf final : public eng::GrfSource {
  public:
    int channelCount() const noexcept override { return 1; }
    void prepare(const eng::ProcessSpec&) override {}
    void reset(std::uint64_t) noexcept override {}
    void process(float* const* grf, int n) noexcept override {
        std::fill(grf[0], grf[0] + n, 0.0f);
    }
};

} // namespace

std::vector<exp::ClipRecord>
renderClipFolder(const exp::Protocol& protocol, const std::string& clipDir, double sampleRateHz,
                 const std::function<bool(int, int, const std::string&)>& progress) {
    const auto jobs = exp::clipJobs(protocol, clipDir);
    if (const auto missing = exp::checkClipFiles(protocol, clipDir); !missing.empty()) {
        std::string all;
        for (const auto& p : missing) all += (all.empty() ? "" : "\n") + p.toString();
        throw std::runtime_error(all);
    }
    fs::create_directories(clipDir);
    std::vector<exp::ClipRecord> records;
    const int total = static_cast<int>(jobs.size());
    for (int i = 0; i < total; ++i) {
        const auto& job = jobs[static_cast<std::size_t>(i)];
        if (progress && !progress(i, total, job.stimulus.id)) return {};
        exp::ClipRecord r;
        r.stimulusId = job.stimulus.id;
        r.file = fs::path(job.path).lexically_relative(clipDir).generic_string();
        r.source = job.source;
        r.seed = job.seed;
        try {
            eng::AudioBuffer audio;
            if (job.source == exp::ClipSource::Lab) {
                audio = eng::readAudioFile(job.path);
            } else {
                // The whole stimulus (soundscape included) through the one renderer, exactly
                // job.seconds long, stored as float so that the file holds the rendered samples
                // and a replay of a trial that played it gives them back bit for bit.
                StimulusRender q;
                q.stimulus = job.stimulus;
                q.seed = job.seed;
                q.sampleRateHz = sampleRateHz;
                q.clipSeconds = job.seconds;
                audio = renderStimulus(q);
                eng::writeAudioFile(job.path, audio, eng::SampleFormat::Float32);
            }
            r.sampleRateHz = audio.sampleRateHz;
            r.frames = audio.frames();
            r.seconds = static_cast<double>(r.frames) / audio.sampleRateHz;
            r.samplesSha256 = samplesSha256(audio);
        } catch (const std::exception& e) {
            throw std::runtime_error(fmt::format("clip of stimulus '{}' ({}): {}", job.stimulus.id,
                                                 protocol.sourceName, e.what()));
        }
        r.sha256 = exp::fileSha256(job.path);
        records.push_back(std::move(r));
    }
    exp::writeClipManifest(clipDir, records);
    if (progress) progress(total, total, {});
    return records;
}

ClipAudio::~ClipAudio() {
    stop();
}

void ClipAudio::play(const std::string& path) {
    if (!engine_.isOpen()) throw std::runtime_error("clip audio: the audio engine is not open");
    auto clip = eng::readAudioFile(path, engine_.processSpec().sampleRateHz);
    lastFrames_ = clip.frames();
    eng::LiveSceneDescription d;
    d.dryEvenIfPresetHasReverb = true;
    d.control = eng::ControlKind::External;
    d.external = std::make_shared<SilentGrf>();
    d.ambience = std::make_unique<ClipAmbience>(std::move(clip));
    auto scene =
        eng::LiveScene::create(std::move(d), engine_.processSpec(), engine_.settings().channels);
    if (!engine_.submit(std::move(scene)))
        throw std::runtime_error("clip audio: the audio thread did not take the clip (command "
                                 "queue full: is the stream running?)");
    playing_ = true;
}

void ClipAudio::stop() {
    if (!playing_) return;
    playing_ = false;
    engine_.submit(nullptr);
    engine_.collectRetired();
}

} // namespace underfoot::wiring
