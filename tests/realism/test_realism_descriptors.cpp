// SPDX-License-Identifier: GPL-3.0-or-later
// Descriptors, segmentation and the distance on synthetic signals whose answers are known.
#include "realism/Descriptors.h"
#include "realism/Distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace underfoot::realism;

namespace {
constexpr double kFs = 48000;

std::vector<float> decayingSine(double f, double t60, double seconds, double amp = 0.5) {
    std::vector<float> x(static_cast<std::size_t>(seconds * kFs));
    const double tau = t60 / std::log(1000.0); // amplitude falls 60 dB in t60
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double t = double(i) / kFs;
        x[i] =
            static_cast<float>(amp * std::sin(2 * std::numbers::pi * f * t) * std::exp(-t / tau));
    }
    return x;
}

std::vector<float> whiteNoise(double seconds, unsigned seed, double amp = 0.3) {
    std::mt19937 g(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    std::vector<float> x(static_cast<std::size_t>(seconds * kFs));
    for (auto& v : x) v = static_cast<float>(amp * n(g));
    return x;
}

// Noise made of random-phase sinusoids every 2 Hz between lo and hi (an ideal band-pass).
std::vector<float> bandNoise(double lo, double hi, double seconds, unsigned seed) {
    std::mt19937 g(seed);
    std::uniform_real_distribution<double> ph(0, 2 * std::numbers::pi);
    std::vector<double> acc(static_cast<std::size_t>(seconds * kFs), 0.0);
    for (double f = lo; f <= hi; f += 2.0) {
        const double p = ph(g), w = 2 * std::numbers::pi * f / kFs;
        for (std::size_t i = 0; i < acc.size(); ++i) acc[i] += std::sin(w * double(i) + p);
    }
    double peak = 0;
    for (double v : acc) peak = std::max(peak, std::fabs(v));
    std::vector<float> x(acc.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<float>(0.5 * acc[i] / peak);
    return x;
}

StepDescriptors whole(const std::vector<float>& x, AnalysisOptions o = {}) {
    return describeStep(x, kFs, {0, x.size()}, o);
}
} // namespace

TEST(RealismDescriptors, DecayTimeOfADecayingSinusoidIsAThirdOfItsT60) {
    for (double t60 : {0.15, 0.3, 1.2}) {
        const auto d = whole(decayingSine(1000, t60, 1.5 * t60 + 0.1));
        // -20 dB is a third of the way to -60 dB; the 2 ms envelope window adds at most ~2 ms.
        EXPECT_NEAR(d.value[kDecay20], t60 / 3, 0.05 * t60 / 3 + 0.002) << "t60 " << t60;
        EXPECT_NEAR(d.value[kCentroid], 1000, 60);
        EXPECT_GT(d.value[kPeakiness], 20.0); // one tone: a very peaky spectrum
        EXPECT_LT(d.value[kFlatness], -20.0);
    }
}

TEST(RealismDescriptors, WhiteNoiseIsFlatAndItsBandsFollowTheirWidths) {
    const auto d = whole(whiteNoise(0.5, 3));
    EXPECT_GT(d.value[kFlatness], -3.0); // averaged periodograms of white noise: near 0 dB
    EXPECT_LT(d.value[kPeakiness], 12.0);
    // Band energies of white noise are proportional to the band widths within 20 Hz..16 kHz.
    const double total = 16000 - 20;
    EXPECT_NEAR(d.value[kBandLow], 10 * std::log10(230 / total), 1.0);
    EXPECT_NEAR(d.value[kBandMid], 10 * std::log10(3000 / total), 0.5);
    EXPECT_NEAR(d.value[kBandHigh], 10 * std::log10(12000 / total), 0.5);
    EXPECT_NEAR(d.value[kCentroid], (20 + 16000) / 2.0, 400);
}

TEST(RealismDescriptors, BandEnergiesOfBandLimitedNoise) {
    const auto d = whole(bandNoise(1200, 3800, 0.4, 5));
    EXPECT_GT(d.value[kBandMid], -0.5);
    EXPECT_LT(d.value[kBandLow], -40.0);
    EXPECT_LT(d.value[kBandHigh], -25.0);
    const auto low = whole(bandNoise(40, 200, 0.4, 6));
    EXPECT_GT(low.value[kBandLow], -0.5);
    EXPECT_LT(low.value[kBandHigh], -40.0);
    EXPECT_LT(low.value[kCentroid], 250.0);
}

TEST(RealismDescriptors, LevelInvariant) {
    auto x = decayingSine(700, 0.2, 0.4);
    const auto noise = whiteNoise(0.4, 9, 0.05);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += noise[i];
    auto quiet = x;
    for (auto& v : quiet) v *= 0.01f;
    const auto a = whole(x), b = whole(quiet);
    for (int k = 0; k < kDescriptorCount; ++k)
        EXPECT_NEAR(a.value[std::size_t(k)], b.value[std::size_t(k)],
                    1e-3 * std::max(1.0, std::fabs(a.value[std::size_t(k)])))
            << descriptorInfo(k).key;
}

TEST(RealismDescriptors, BandwidthAwareComparisonIgnoresWhatOneSideCannotHold) {
    // The same noise at 22.05 kHz (nothing above 11 kHz) and at 48 kHz: with the shared band
    // limit the band balance agrees; without it the 48 kHz one has far more above 4 kHz.
    underfoot::engine::AudioBuffer wide;
    wide.sampleRateHz = kFs;
    wide.channels = 1;
    wide.samples = whiteNoise(0.5, 11);
    const auto narrow = underfoot::engine::resample(wide, 22050);
    AnalysisOptions o;
    o.maxHz = 0.95 * 11025;
    const auto a = describeStep(analysisSignal(wide, o), kFs, {0, 23000}, o);
    const auto b = describeStep(analysisSignal(narrow, o), kFs, {0, 23000}, o);
    EXPECT_NEAR(a.value[kBandHigh], b.value[kBandHigh], 0.7);
    EXPECT_NEAR(a.value[kCentroid], b.value[kCentroid], 300);
    EXPECT_EQ(a.thirdOctaveDb.size(), b.thirdOctaveDb.size());
}

TEST(RealismDescriptors, TheNoiseFloorSitsSixtyDbBelowTheLoudestTwoMilliseconds) {
    // A ping followed by digital silence, as a render ends: the floor added by analysisSignal
    // is white noise of RMS 1e-3 x the RMS of the loudest 2 ms, the same on every call, and it
    // follows the signal's level (so the descriptors stay level-invariant).
    auto ping = decayingSine(1200, 0.05, 0.3);
    double loudest = 0;
    for (std::size_t s = 0; s + 96 <= ping.size(); s += 48) {
        double e = 0;
        for (std::size_t i = s; i < s + 96; ++i) e += double(ping[i]) * ping[i];
        loudest = std::max(loudest, e / 96);
    }
    auto floored = ping;
    const AnalysisOptions o;
    const double rms = addNoiseFloor(floored, kFs, o);
    EXPECT_NEAR(rms, std::sqrt(loudest) * 1e-3, 1e-9);
    double added = 0;
    for (std::size_t i = 0; i < ping.size(); ++i)
        added += std::pow(double(floored[i]) - double(ping[i]), 2);
    EXPECT_NEAR(std::sqrt(added / double(ping.size())), rms, 0.03 * rms);
    auto again = ping;
    addNoiseFloor(again, kFs, o);
    EXPECT_EQ(again, floored);
    AnalysisOptions none;
    none.noiseFloorDb = 0;
    auto untouched = ping;
    EXPECT_EQ(addNoiseFloor(untouched, kFs, none), 0.0);
    EXPECT_EQ(untouched, ping);
    // Without a floor the silent tail leaves most of the band empty: flatness far below any
    // recording's; with it the flatness is that of a tone over a floor 60 dB down.
    const auto bare = whole(ping), withFloor = whole(floored);
    EXPECT_LT(bare.value[kFlatness], withFloor.value[kFlatness] - 10.0);
    auto quiet = ping;
    for (auto& v : quiet) v *= 0.01f;
    addNoiseFloor(quiet, kFs, o);
    const auto quietD = whole(quiet);
    for (int k = 0; k < kDescriptorCount; ++k)
        EXPECT_NEAR(withFloor.value[std::size_t(k)], quietD.value[std::size_t(k)],
                    1e-3 * std::max(1.0, std::fabs(withFloor.value[std::size_t(k)])))
            << descriptorInfo(k).key;
}

TEST(RealismDescriptors, GrainRateCountsClicks) {
    // 40 clicks (decaying 6 kHz bursts of 1 ms) per second over 0.5 s, on a faint noise floor.
    auto x = whiteNoise(0.5, 2, 1e-4);
    for (int c = 0; c < 20; ++c) {
        const auto start = static_cast<std::size_t>((0.0125 + c * 0.025) * kFs);
        for (std::size_t i = 0; i < 96 && start + i < x.size(); ++i)
            x[start + i] +=
                static_cast<float>(0.5 * std::exp(-double(i) / 12.0) *
                                   std::sin(2 * std::numbers::pi * 6000 * double(i) / kFs));
    }
    const auto d = whole(x);
    EXPECT_NEAR(d.value[kGrainRate], 40.0, 8.0);
    const auto tone = whole(decayingSine(400, 0.3, 0.3));
    EXPECT_LT(tone.value[kGrainRate], 8.0); // one event
}

TEST(RealismDescriptors, SegmentationFindsEveryStep) {
    std::vector<float> x(static_cast<std::size_t>(3.5 * kFs), 0.0f);
    const auto burst = decayingSine(500, 0.1, 0.15);
    for (int s = 0; s < 5; ++s) {
        const auto at = static_cast<std::size_t>((0.2 + 0.6 * s) * kFs);
        for (std::size_t i = 0; i < burst.size(); ++i)
            x[at + i] += burst[i] * (s % 2 ? 0.3f : 1.0f);
    }
    const auto steps = segmentSteps(x, kFs, {});
    ASSERT_EQ(steps.size(), 5u);
    for (int s = 0; s < 5; ++s)
        EXPECT_NEAR(double(steps[std::size_t(s)].begin) / kFs, 0.2 + 0.6 * s, 0.012);
    EXPECT_TRUE(segmentSteps(std::vector<float>(1000, 0.0f), kFs, {}).empty());
    EXPECT_THROW(describeStep(x, kFs, {10, 10}, {}), std::invalid_argument);
    EXPECT_THROW(describeStep(std::vector<float>(4800, 0.0f), kFs, {0, 4800}, {}),
                 std::invalid_argument);
}

TEST(RealismDistance, ZeroForTheSameStepsAndTheBoundedRobustZOtherwise) {
    std::vector<StepDescriptors> a;
    for (int i = 0; i < 9; ++i) {
        StepDescriptors s;
        for (auto& v : s.value) v = 1.0;
        s.value[kFlatness] = -10.0 + i; // IQR 4 dB -> spread 4 / 1.349
        s.value[kCentroid] = 1000;
        a.push_back(s);
    }
    EXPECT_NEAR(compareSteps(a, a).distance, 0.0, 1e-12);
    auto b = a;
    for (auto& s : b) s.value[kFlatness] += 6.0;
    const auto c = compareSteps(b, a);
    // IQR 4 dB -> spread 2.97 dB, below the 3 dB scale: z = 6 / 3
    EXPECT_NEAR(c.d[kFlatness].z, 2.0, 1e-9);
    EXPECT_NEAR(c.distance, c.d[kFlatness].z / double(kDescriptorCount), 1e-12);
    for (auto& s : b) s.value[kCentroid] = 2000; // one octave, scale 0.5 octave -> z = 2
    EXPECT_NEAR(compareSteps(b, a).d[kCentroid].z, 2.0, 1e-9);
    // A very wide recorded spread counts as at most twice the scale (6 dB here).
    auto wide = a;
    for (std::size_t i = 0; i < wide.size(); ++i)
        wide[i].value[kFlatness] = -40.0 + 10.0 * double(i);
    auto mid = wide;
    for (auto& s : mid)
        s.value[kFlatness] = quantile({-40, -30, -20, -10, 0, 10, 20, 30, 40}, 0.5) + 12;
    EXPECT_NEAR(compareSteps(mid, wide).d[kFlatness].z, 2.0, 1e-9);
    EXPECT_THROW(compareSteps({}, a), std::invalid_argument);
    EXPECT_NEAR(quantile({1, 2, 3, 4}, 0.25), 1.75, 1e-12); // R type 7
}
