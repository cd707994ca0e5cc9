// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/scene/TestTone.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace underfoot::engine {

namespace {
/// No force: the scene's surface voices stay asleep.
class SilentGrf final : public GrfSource {
  public:
    int channelCount() const noexcept override { return 1; }
    void prepare(const ProcessSpec&) override {}
    void reset(std::uint64_t) noexcept override {}
    void process(float* const* grf, int n) noexcept override {
        std::fill(grf[0], grf[0] + n, 0.0f);
    }
};
} // namespace

TestTone::TestTone(double frequencyHz, double levelDbfs)
    : frequencyHz_(frequencyHz), levelDbfs_(levelDbfs) {
    if (!std::isfinite(frequencyHz) || frequencyHz <= 0.0)
        throw std::invalid_argument(
            fmt::format("test tone: frequency {} Hz; expected a positive number", frequencyHz));
    if (!std::isfinite(levelDbfs) || levelDbfs > 0.0)
        throw std::invalid_argument(
            fmt::format("test tone: level {} dBFS; expected a number <= 0", levelDbfs));
    amplitude_ = std::pow(10.0, levelDbfs / 20.0);
}

void TestTone::prepare(const ProcessSpec& spec) {
    if (!(frequencyHz_ < spec.sampleRateHz / 2.0))
        throw std::invalid_argument(
            fmt::format("test tone: {} Hz is not below half the sample rate ({} Hz)", frequencyHz_,
                        spec.sampleRateHz));
    increment_ = 2.0 * std::numbers::pi * frequencyHz_ / spec.sampleRateHz;
    phase_ = 0.0;
}

void TestTone::reset(std::uint64_t) noexcept {
    phase_ = 0.0;
}

void TestTone::process(float* left, float* right, int n) noexcept {
    constexpr double twoPi = 2.0 * std::numbers::pi;
    for (int i = 0; i < n; ++i) {
        left[i] = static_cast<float>(amplitude_ * std::sin(phase_));
        right[i] = 0.0f;
        phase_ += increment_;
        if (phase_ >= twoPi) phase_ -= twoPi;
    }
}

std::string TestTone::name() const {
    return fmt::format("test tone {:g} Hz {:g} dBFS", frequencyHz_, levelDbfs_);
}

std::unique_ptr<LiveScene> makeTestToneScene(int outputChannel, const TestToneSettings& tone,
                                             const ProcessSpec& spec) {
    if (outputChannel < 0)
        throw std::invalid_argument(
            fmt::format("test tone: output channel {}; expected 0 or more", outputChannel));
    LiveSceneDescription d;
    d.dryEvenIfPresetHasReverb = true;
    d.control = ControlKind::External;
    d.external = std::make_shared<SilentGrf>();
    d.ambience = std::make_unique<TestTone>(tone.frequencyHz, tone.levelDbfs);
    // Only the chosen output: both headphone sides on it (the right side is silent), no
    // actuators.
    ChannelMap channels;
    channels.headphonesLeft = outputChannel;
    channels.headphonesRight = outputChannel;
    return LiveScene::create(std::move(d), spec, channels);
}

} // namespace underfoot::engine
