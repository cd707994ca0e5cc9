// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/Random.h"
#include "engine/reverb/Convolver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {

// A decaying-noise IR of `frames` samples, 1 or 2 channels, with a direct sound at tap `direct`.
AudioBuffer noiseIr(std::size_t frames, int channels, std::uint64_t seed, double rate = 48000,
                    std::size_t direct = 0) {
    AudioBuffer ir;
    ir.sampleRateHz = rate;
    ir.channels = channels;
    Random r(seed);
    for (std::size_t i = 0; i < frames; ++i)
        for (int c = 0; c < channels; ++c) {
            const double decay = std::exp(-6.9 * static_cast<double>(i) / double(frames));
            double v = 0.3 * decay * r.bipolar();
            if (i == direct) v += c == 0 ? 0.8 : 0.6;
            ir.samples.push_back(static_cast<float>(v));
        }
    return ir;
}

std::vector<float> noise(std::size_t n, std::uint64_t seed) {
    Random r(seed);
    std::vector<float> x(n);
    for (auto& v : x) v = static_cast<float>(0.5 * r.bipolar());
    return x;
}

// Reference: time-domain convolution in double precision.
std::vector<double> directConvolution(const std::vector<float>& x, const std::vector<float>& h,
                                      std::size_t outLength) {
    std::vector<double> y(outLength, 0.0);
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i] == 0.0f) continue;
        const std::size_t m = std::min(h.size(), outLength - std::min(outLength, i));
        for (std::size_t k = 0; k < m; ++k) y[i + k] += double(x[i]) * h[k];
    }
    return y;
}

struct Stereo {
    std::vector<float> l, r;
};

Stereo run(Convolver& c, const std::vector<float>& x, int block) {
    Stereo out{std::vector<float>(x.size()), std::vector<float>(x.size())};
    for (std::size_t pos = 0; pos < x.size(); pos += static_cast<std::size_t>(block)) {
        const int m = static_cast<int>(
            std::min<std::size_t>(static_cast<std::size_t>(block), x.size() - pos));
        c.process(x.data() + pos, out.l.data() + pos, out.r.data() + pos, m);
    }
    return out;
}

} // namespace

TEST(Convolver, MatchesDirectConvolutionForBlockSizesAndIrLengths) {
    for (std::size_t irLen : {1u, 10u, 64u, 65u, 200u, 1024u, 1025u, 1500u, 2100u, 5000u, 12000u}) {
        for (int channels : {1, 2}) {
            const AudioBuffer ir = noiseIr(irLen, channels, irLen * 3 + channels);
            // Input: noise followed by silence, so that the whole tail is compared.
            std::vector<float> x = noise(3000, 5);
            x.resize(3000 + irLen + 500, 0.0f);
            const auto refL = directConvolution(x, ir.channel(0), x.size());
            const auto refR = directConvolution(x, ir.channel(channels - 1), x.size());
            double peak = 0;
            for (double v : refL) peak = std::max(peak, std::fabs(v));
            Stereo first;
            for (int block : {1, 7, 64, 100, 512, 1024, 4096}) {
                Convolver c;
                c.prepare(ir, 48000, block);
                const Stereo y = run(c, x, block);
                double errL = 0, errR = 0;
                for (std::size_t i = 0; i < x.size(); ++i) {
                    errL = std::max(errL, std::fabs(y.l[i] - refL[i]));
                    errR = std::max(errR, std::fabs(y.r[i] - refR[i]));
                }
                // zita-convolver uses single-precision FFTs: the error stays below -100 dB of
                // the output's peak (measured -134 dB for 12000 taps, -132.5 dB for 105600 taps).
                EXPECT_LT(errL / peak, 1e-5)
                    << "IR " << irLen << " ch " << channels << " block " << block;
                EXPECT_LT(errR / peak, 1e-5)
                    << "IR " << irLen << " ch " << channels << " block " << block;
                // The result does not depend on the block size at all (work is per 64 samples).
                if (first.l.empty())
                    first = y;
                else {
                    EXPECT_EQ(y.l, first.l) << irLen << " " << block;
                    EXPECT_EQ(y.r, first.r) << irLen << " " << block;
                }
            }
        }
    }
}

TEST(Convolver, AddsZeroLatency) {
    // An impulse at input sample 0 gives h[0] at output sample 0, for every block size, and a
    // delayed direct sound stays exactly where the IR puts it.
    for (int block : {1, 32, 64, 256}) {
        for (std::size_t direct : {0u, 1u, 63u, 64u, 100u, 1023u, 1024u, 2000u}) {
            const AudioBuffer ir = noiseIr(4000, 2, 9, 48000, direct);
            Convolver c;
            c.prepare(ir, 48000, block);
            std::vector<float> x(5000, 0.0f);
            x[0] = 1.0f;
            const Stereo y = run(c, x, block);
            for (std::size_t i = 0; i < 4000; ++i) {
                ASSERT_NEAR(y.l[i], ir.at(i, 0), 2e-6) << "block " << block << " sample " << i;
                ASSERT_NEAR(y.r[i], ir.at(i, 1), 2e-6) << "block " << block << " sample " << i;
            }
            EXPECT_EQ(y.l[0], ir.at(0, 0)); // the head is exact, not only within tolerance
        }
    }
    // An impulse in the middle of a block, not only at 0.
    const AudioBuffer ir = noiseIr(3000, 1, 4);
    Convolver c;
    c.prepare(ir, 48000, 128);
    std::vector<float> x(4000, 0.0f);
    x[777] = 1.0f;
    const Stereo y = run(c, x, 128);
    for (std::size_t i = 0; i < 777; ++i) ASSERT_EQ(y.l[i], 0.0f);
    for (std::size_t i = 0; i < 3000; ++i) ASSERT_NEAR(y.l[777 + i], ir.at(i, 0), 2e-6);
    EXPECT_EQ(y.l, y.r); // mono IR feeds both sides
}

TEST(Convolver, DeterministicAndResetClearsHistory) {
    const AudioBuffer ir = noiseIr(30000, 2, 2);
    std::vector<float> x = noise(20000, 8);
    Convolver a, b;
    a.prepare(ir, 48000, 256);
    b.prepare(ir, 48000, 256);
    const Stereo ya = run(a, x, 256), yb = run(b, x, 256);
    EXPECT_EQ(ya.l, yb.l);
    EXPECT_EQ(ya.r, yb.r);
    a.reset();
    const Stereo again = run(a, x, 256);
    EXPECT_EQ(again.l, ya.l);
    a.reset();
    const Stereo silence = run(a, std::vector<float>(40000, 0.0f), 512);
    EXPECT_TRUE(std::all_of(silence.l.begin(), silence.l.end(), [](float v) { return v == 0; }));
}

TEST(Convolver, ResampledIrKeepsItsFrequencyResponse) {
    // A 24 kHz IR: a 2 ms Hann pulse (DC gain = sum of taps = 24) plus a weak tail. At 48 kHz
    // there are twice as many taps; the DC gain and a 300 Hz sine's gain must stay the same.
    AudioBuffer ir;
    ir.sampleRateHz = 24000;
    ir.channels = 1;
    for (int i = 0; i < 2400; ++i) {
        const double hann = i < 48 ? 0.5 * (1 - std::cos(2 * M_PI * (i + 0.5) / 48)) : 0.0;
        ir.samples.push_back(static_cast<float>(hann + (i >= 48 ? 1e-3 * std::sin(0.3 * i) : 0)));
    }
    // Reference gain at 300 Hz from the 24 kHz taps (DTFT).
    double re = 0, im = 0, dc = 0;
    for (int i = 0; i < 2400; ++i) {
        re += ir.samples[i] * std::cos(2 * M_PI * 300 * i / 24000.0);
        im -= ir.samples[i] * std::sin(2 * M_PI * 300 * i / 24000.0);
        dc += ir.samples[i];
    }
    const double gain300 = std::hypot(re, im);
    Convolver c;
    c.prepare(ir, 48000, 256);
    EXPECT_NEAR(static_cast<double>(c.impulseLength()), 4800.0, 1.0);
    std::vector<float> ones(20000, 1.0f);
    const Stereo y = run(c, ones, 256);
    EXPECT_NEAR(y.l.back() / dc, 1.0, 2e-3);
    std::vector<float> s(48000);
    for (std::size_t i = 0; i < s.size(); ++i)
        s[i] = static_cast<float>(std::sin(2 * M_PI * 300 * double(i) / 48000));
    c.reset();
    const Stereo ys = run(c, s, 256);
    double peak = 0;
    for (std::size_t i = 24000; i < 48000; ++i) peak = std::max(peak, double(std::fabs(ys.l[i])));
    EXPECT_NEAR(peak / gain300, 1.0, 2e-3);
}

TEST(Convolver, RejectsBadImpulseResponses) {
    Convolver c;
    AudioBuffer empty;
    empty.sampleRateHz = 48000;
    empty.channels = 1;
    EXPECT_THROW(c.prepare(empty, 48000, 64), std::invalid_argument);
    AudioBuffer three = noiseIr(100, 1, 1);
    three.channels = 3;
    three.samples.resize(300);
    EXPECT_THROW(c.prepare(three, 48000, 64), std::invalid_argument);
    AudioBuffer nan = noiseIr(100, 1, 1);
    nan.samples[50] = std::nanf("");
    EXPECT_THROW(c.prepare(nan, 48000, 64), std::invalid_argument);
    EXPECT_THROW(c.prepare(noiseIr(100, 1, 1), 0, 64), std::invalid_argument);
    EXPECT_THROW(c.prepare(noiseIr(100, 1, 1), 48000, 0), std::invalid_argument);
}

TEST(Convolver, OfflineHelperReturnsTheFullTail) {
    const AudioBuffer ir = noiseIr(5000, 2, 6);
    const std::vector<float> x = noise(1000, 2);
    const AudioBuffer y = convolveOffline(x, 48000, ir);
    ASSERT_EQ(y.frames(), 1000u + 5000u - 1u);
    EXPECT_EQ(y.channels, 2);
    const auto ref = directConvolution(x, ir.channel(1), y.frames());
    double err = 0;
    for (std::size_t i = 0; i < y.frames(); ++i)
        err = std::max(err, std::fabs(y.at(i, 1) - ref[i]));
    EXPECT_LT(err, 1e-5);
}

TEST(Convolver, StagesFollowTheIrLength) {
    // Direct head [0, 64), partition 64 for [64, 512), 256 for [512, 4096), 2048 from 4096 on.
    const std::pair<std::size_t, std::vector<int>> cases[] = {{10, {}},
                                                              {64, {}},
                                                              {65, {64}},
                                                              {512, {64}},
                                                              {513, {64, 256}},
                                                              {4096, {64, 256}},
                                                              {4097, {64, 256, 2048}},
                                                              {100000, {64, 256, 2048}}};
    for (const auto& [len, sizes] : cases) {
        Convolver c;
        c.prepare(noiseIr(len, 1, 1), 48000, 512);
        EXPECT_EQ(c.partitionSizes(), sizes) << len;
    }
}
