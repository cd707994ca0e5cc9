// SPDX-License-Identifier: GPL-3.0-or-later
// The bubbles layer's splash_rise_ms (engine/surfaces/LiquidLayers.h), added for the re-voiced
// water (docs/decisions/realism-revoicing.md, "Heard in their category"): absent or 0 it changes
// nothing (same samples as before the knob); set, the splash noise develops after the landing: its
// loudest moment comes later, and the layer still ends in silence and sleeps.
#include "engine/control/VirtualWalker.h"
#include "engine/surfaces/Surface.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

std::vector<float> splash(const std::string& extra, bool* sleepsAfter = nullptr) {
    // Splash noise only (no bubbles, no slosh, no wake): the envelope under test.
    const auto text = fmt::format(R"(id = "splash_test"
category = "liquid"
description = "splash noise only"
[[layer]]
type = "bubbles"
purpose = "splash noise of the landing, nothing else"
splash_noise_db = 0.0
splash_hz = 600.0
splash_decay_ms = 120.0
{}
)",
                                  extra);
    auto s = loadSurfaceFromString(text, "splash_test.toml");
    s->prepare({kFs, 512});
    s->reset(3);
    WalkerParameters p;
    VirtualWalker w(p);
    w.prepare({kFs, 512});
    w.reset(7);
    // 3 s of the left foot, then 3 s without load (the splash noise decays 120 dB in 1.7 s).
    std::vector<float> left(static_cast<std::size_t>(3 * kFs)), right(left.size());
    w.process(left.data(), right.data(), static_cast<int>(left.size()));
    left.resize(static_cast<std::size_t>(6 * kFs), 0.0f);
    std::vector<float> out(left.size(), 0.0f);
    for (std::size_t done = 0; done < left.size(); done += 512) {
        const int n = static_cast<int>(std::min<std::size_t>(512, left.size() - done));
        s->process(left.data() + done, out.data() + done, n);
    }
    if (sleepsAfter) *sleepsAfter = s->isSleeping();
    return out;
}

// Time (s) of the loudest 5 ms frame.
double loudestFrameSeconds(const std::vector<float>& x) {
    const std::size_t frame = static_cast<std::size_t>(0.005 * kFs);
    double best = -1, at = 0;
    for (std::size_t s = 0; s + frame <= x.size(); s += frame) {
        double e = 0;
        for (std::size_t i = 0; i < frame; ++i) e += static_cast<double>(x[s + i]) * x[s + i];
        if (e > best) {
            best = e;
            at = static_cast<double>(s) / kFs;
        }
    }
    return at;
}
} // namespace

TEST(SplashRise, ZeroIsTheFormerBehaviourAndARiseDelaysTheSplash) {
    const auto absent = splash("");
    const auto zero = splash("splash_rise_ms = 0.0");
    EXPECT_EQ(absent, zero) << "splash_rise_ms = 0 must give the samples of a preset without it";
    bool sleeps = false;
    const auto risen = splash("splash_rise_ms = 60.0", &sleeps);
    EXPECT_TRUE(sleeps) << "the layer sleeps again after the step";
    double peakA = 0, peakR = 0;
    for (float v : absent) peakA = std::max(peakA, std::fabs(static_cast<double>(v)));
    for (float v : risen) {
        ASSERT_TRUE(std::isfinite(v));
        peakR = std::max(peakR, std::fabs(static_cast<double>(v)));
    }
    ASSERT_GT(peakA, 0.0);
    ASSERT_GT(peakR, 0.0);
    const double tA = loudestFrameSeconds(absent), tR = loudestFrameSeconds(risen);
    std::printf("loudest 5 ms frame: rise 0 at %.3f s (peak %.3f), rise 60 ms at %.3f s (peak "
                "%.3f)\n",
                tA, peakA, tR, peakR);
    EXPECT_GT(tR, tA + 0.01) << "the splash peaks later when it develops";
    EXPECT_LT(peakR, peakA) << "the rise follows the drive, never overshoots it";
}
