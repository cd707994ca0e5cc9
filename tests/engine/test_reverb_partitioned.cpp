// SPDX-License-Identifier: GPL-3.0-or-later
// The time-distributed partitioned convolver (engine/reverb/Convolver): equal to direct
// convolution through every stage, bit-identical for every host block size, no allocation on
// the audio thread, denormals flushed, finite output.
#include "engine/dsp/Random.h"
#include "engine/reverb/Convolver.h"
#include "tests/common/AllocationTrap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

using namespace underfoot::engine;

namespace {

AudioBuffer decayingNoiseIr(std::size_t frames, int channels, std::uint64_t seed) {
    AudioBuffer ir;
    ir.sampleRateHz = 48000;
    ir.channels = channels;
    Random r(seed);
    for (std::size_t i = 0; i < frames; ++i)
        for (int c = 0; c < channels; ++c) {
            const double decay = std::exp(-6.9 * static_cast<double>(i) / double(frames));
            double v = 0.3 * decay * r.bipolar();
            if (i == 0) v += c == 0 ? 0.5 : 0.45;
            ir.samples.push_back(static_cast<float>(v));
        }
    return ir;
}

std::vector<float> noise(std::size_t n, std::uint64_t seed, double amplitude = 0.5) {
    Random r(seed);
    std::vector<float> x(n);
    for (auto& v : x) v = static_cast<float>(amplitude * r.bipolar());
    return x;
}

struct Stereo {
    std::vector<float> l, r;
};

// Runs x through c in host blocks cycling through `blocks`.
Stereo run(Convolver& c, const std::vector<float>& x, const std::vector<int>& blocks) {
    Stereo out{std::vector<float>(x.size()), std::vector<float>(x.size())};
    std::size_t pos = 0, b = 0;
    while (pos < x.size()) {
        const int m = static_cast<int>(std::min<std::size_t>(
            static_cast<std::size_t>(blocks[b++ % blocks.size()]), x.size() - pos));
        c.process(x.data() + pos, out.l.data() + pos, out.r.data() + pos, m);
        pos += static_cast<std::size_t>(m);
    }
    return out;
}

} // namespace

TEST(PartitionedConvolver, EqualsDirectConvolutionThroughAllStagesOfAHallLengthIr) {
    // 105600 taps as the shipped hall: head, the 64-, 256- and 2048-sample stages (50
    // partitions). Input: a noise burst, then silence to the end of the tail; reference in
    // double precision. Float FFTs: the error must stay below 1e-6 of the output's peak.
    const std::size_t irLen = 105600, burst = 1500;
    for (int channels : {1, 2}) {
        const AudioBuffer ir = decayingNoiseIr(irLen, channels, 11 + channels);
        std::vector<float> x = noise(burst, 3);
        x.resize(burst + irLen + 100, 0.0f);
        Convolver c;
        c.prepare(ir, 48000, 64);
        ASSERT_EQ(c.partitionSizes(), (std::vector<int>{64, 256, 2048}));
        const Stereo y = run(c, x, {64});
        for (int ch = 0; ch < 2; ++ch) {
            const std::vector<float> h = ir.channel(std::min(ch, channels - 1));
            std::vector<double> ref(x.size(), 0.0);
            for (std::size_t i = 0; i < burst; ++i)
                for (std::size_t k = 0; k < irLen && i + k < ref.size(); ++k)
                    ref[i + k] += double(x[i]) * h[k];
            double peak = 0, err = 0;
            const std::vector<float>& out = ch == 0 ? y.l : y.r;
            for (std::size_t i = 0; i < ref.size(); ++i) {
                peak = std::max(peak, std::fabs(ref[i]));
                err = std::max(err, std::fabs(out[i] - ref[i]));
            }
            std::cout << "channels " << channels << " side " << ch
                      << ": max error / peak = " << err / peak << "\n";
            EXPECT_LT(err / peak, 1e-6) << "channels " << channels << " side " << ch;
            EXPECT_GT(peak, 0.1);
        }
    }
}

TEST(PartitionedConvolver, IdenticalSamplesForEveryHostBlockSize) {
    // Replay depends on it: the same input gives the same bits whatever the host block,
    // including irregular sequences of blocks.
    const AudioBuffer ir = decayingNoiseIr(30000, 2, 5);
    const std::vector<float> x = noise(40000, 9);
    Stereo first;
    const std::vector<std::vector<int>> sequences = {
        {1}, {17}, {64}, {256}, {1024}, {4096}, {5, 300, 64, 1, 2000}};
    for (const auto& blocks : sequences) {
        Convolver c;
        c.prepare(ir, 48000, 4096);
        const Stereo y = run(c, x, blocks);
        if (first.l.empty()) {
            first = y;
            continue;
        }
        EXPECT_TRUE(y.l == first.l) << "first host block " << blocks.front();
        EXPECT_TRUE(y.r == first.r) << "first host block " << blocks.front();
    }
    // In-place use (in aliases outL) gives the same samples.
    Convolver c;
    c.prepare(ir, 48000, 256);
    std::vector<float> buf = x, r(x.size());
    for (std::size_t pos = 0; pos < x.size(); pos += 256) {
        const int m = static_cast<int>(std::min<std::size_t>(256, x.size() - pos));
        c.process(buf.data() + pos, buf.data() + pos, r.data() + pos, m);
    }
    EXPECT_TRUE(buf == first.l);
    EXPECT_TRUE(r == first.r);
}

TEST(PartitionedConvolver, NoAllocationOnTheAudioThread) {
    const AudioBuffer ir = decayingNoiseIr(20000, 2, 7);
    const std::vector<float> x = noise(30000, 4);
    std::vector<float> l(x.size()), r(x.size());
    for (int block : {1, 64, 1000}) {
        Convolver c;
        c.prepare(ir, 48000, block);
        long count = 0;
        {
            underfoot::test::AllocationTrap trap;
            for (std::size_t pos = 0; pos < x.size(); pos += static_cast<std::size_t>(block)) {
                const int m = static_cast<int>(
                    std::min<std::size_t>(static_cast<std::size_t>(block), x.size() - pos));
                c.process(x.data() + pos, l.data() + pos, r.data() + pos, m);
            }
            count = trap.count();
        }
        EXPECT_EQ(count, 0) << "block " << block;
    }
}

TEST(PartitionedConvolver, FlushesDenormalsAndStaysFinite) {
    const AudioBuffer ir = decayingNoiseIr(10000, 2, 3);
    Convolver c;
    c.prepare(ir, 48000, 64);
    // Subnormal input is read as zero (DAZ) by every stage: the output is exactly silent.
    const std::vector<float> tiny(12000, 1e-40f);
    ASSERT_EQ(std::fpclassify(tiny[0]), FP_SUBNORMAL);
    const Stereo y = run(c, tiny, {64});
    EXPECT_TRUE(std::all_of(y.l.begin(), y.l.end(), [](float v) { return v == 0.0f; }));
    EXPECT_TRUE(std::all_of(y.r.begin(), y.r.end(), [](float v) { return v == 0.0f; }));
    // Loud finite input (full scale x 1e4) gives finite output, no NaN/Inf.
    c.reset();
    const Stereo loud = run(c, noise(30000, 6, 1e4), {128});
    for (std::size_t i = 0; i < loud.l.size(); ++i) {
        ASSERT_TRUE(std::isfinite(loud.l[i])) << i;
        ASSERT_TRUE(std::isfinite(loud.r[i])) << i;
    }
}

TEST(PartitionedConvolver, EverySimdLevelGivesTheSameSamples) {
    // The SSE, AVX and AVX-512 kernels (products and direct head) do the same IEEE operations per
    // bin and output in the same order: the output does not depend on the CPU. Levels the CPU
    // lacks fall back to the widest it has (then the comparison still holds, trivially).
    const AudioBuffer ir = decayingNoiseIr(20000, 2, 21);
    const std::vector<float> x = noise(30000, 22);
    Stereo first;
    for (auto level : {Convolver::Simd::Sse, Convolver::Simd::Avx, Convolver::Simd::Avx512}) {
        Convolver c;
        c.limitSimd(level);
        c.prepare(ir, 48000, 100);
        EXPECT_LE(static_cast<int>(c.simd()), static_cast<int>(level));
        const Stereo y = run(c, x, {100, 7, 64});
        if (first.l.empty()) {
            first = y;
            continue;
        }
        EXPECT_TRUE(y.l == first.l) << "level " << static_cast<int>(level);
        EXPECT_TRUE(y.r == first.r) << "level " << static_cast<int>(level);
    }
}
