// SPDX-License-Identifier: GPL-3.0-or-later
// A live wading node's run is reproduced exactly from its gait arrivals (each frame
// with the sample at which it took effect). A gait source delivers frames at jittered offsets,
// as gyroscope packets land in whichever audio block is running when they arrive; the node's
// output is compared with renderWadingArrivals() of what it recorded, bit for bit, and the same
// frames on their 100 Hz grid (the older replay) are shown not to reproduce it.
#include "engine/dsp/Random.h"
#include "engine/render/SafetyLimiter.h"
#include "engine/scene/WadingNode.h"
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "tests/common/AllocationTrap.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>

namespace eng = underfoot::engine;

namespace {

/// Frames of a virtual gait, frame k due at sample 480 k plus a seeded jitter of 0-400 samples
/// (always in order), at most one per block as a packet arrives.
class JitteredGaitSource final : public eng::GaitSource {
  public:
    explicit JitteredGaitSource(std::uint64_t seed) {
        eng::VirtualGaitParameters p;
        p.cadenceStepsPerMin = 100;
        gait_ = eng::virtualGait(p, 5.0, seed);
        eng::Random r(seed);
        for (std::size_t k = 0; k < gait_.size(); ++k)
            due_.push_back(static_cast<std::int64_t>(480 * k) +
                           static_cast<std::int64_t>(400 * r.uniform()));
    }
    void prepare(const eng::ProcessSpec&) override {}
    void reset(std::uint64_t) noexcept override { next_ = 0, sample_ = 0; }
    int pull(int n, eng::TimedGaitFrame* frames, int capacity) noexcept override {
        int count = 0;
        while (count < capacity && next_ < gait_.size() && due_[next_] < sample_ + n) {
            frames[count++] = {static_cast<int>(std::max<std::int64_t>(0, due_[next_] - sample_)),
                               gait_[next_]};
            ++next_;
        }
        sample_ += n;
        return count;
    }
    std::string name() const override { return "jittered test gait"; }

  private:
    std::vector<eng::GaitFrame> gait_;
    std::vector<std::int64_t> due_;
    std::size_t next_ = 0;
    std::int64_t sample_ = 0;
};

bool sameBits(double a, double b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

} // namespace

TEST(WadingArrivals, LiveNodeIsReproducedBitForBitFromItsArrivals) {
    eng::WadingOptions options;
    options.depth = "deep";
    options.seed = 77;
    constexpr int kBlock = 64;
    eng::WadingNode node(options, std::make_unique<JitteredGaitSource>(9), 10000);
    node.prepare({options.sampleRateHz, kBlock});
    node.reset(options.seed);
    const std::size_t total = 48000 * 4 + 37; // a last partial block
    std::vector<float> live(2 * total);
    std::vector<float> l(kBlock), r(kBlock);
    eng::StereoSafetyLimiter limiter; // the offline output stage (the live engine's per output)
    limiter.prepare(options.sampleRateHz);
    long allocations = 0;
    for (std::size_t start = 0; start < total; start += kBlock) {
        const int n = static_cast<int>(std::min<std::size_t>(kBlock, total - start));
        {
            underfoot::test::AllocationTrap trap;
            node.process(l.data(), r.data(), n);
            allocations += trap.count();
        }
        limiter.process(l.data(), r.data(), n);
        for (int i = 0; i < n; ++i) {
            live[2 * (start + static_cast<std::size_t>(i))] = l[static_cast<std::size_t>(i)];
            live[2 * (start + static_cast<std::size_t>(i)) + 1] = r[static_cast<std::size_t>(i)];
        }
    }
    EXPECT_EQ(allocations, 0) << "the node allocated on the audio path while recording arrivals";
    ASSERT_GE(node.recordedFrames(), 400u);
    EXPECT_EQ(node.samplesProcessed(), static_cast<std::int64_t>(total));

    // Written and read back: the same samples and the same doubles.
    const auto path =
        (underfoot::test::scratchDir("wading_arrivals") / "gait.csv.arrivals.csv").string();
    node.writeArrivals(path);
    const eng::GaitArrivals recorded = node.arrivals();
    const eng::GaitArrivals back = eng::readGaitArrivals(path);
    ASSERT_EQ(back.samples, recorded.samples);
    ASSERT_EQ(back.frames.size(), recorded.frames.size());
    std::size_t offGrid = 0;
    for (std::size_t k = 0; k < back.frames.size(); ++k) {
        ASSERT_EQ(back.frames[k].sample, recorded.frames[k].sample) << k;
        ASSERT_TRUE(sameBits(back.frames[k].frame.timeS, recorded.frames[k].frame.timeS)) << k;
        for (std::size_t c = 0; c < 4; ++c)
            ASSERT_TRUE(sameBits(back.frames[k].frame.angularVelocityDps[c],
                                 recorded.frames[k].frame.angularVelocityDps[c]))
                << k << " " << c;
        offGrid += back.frames[k].sample != static_cast<std::int64_t>(480 * k);
    }
    EXPECT_GT(offGrid, back.frames.size() / 2) << "the test's frames should be off the grid";

    // Rendered from the arrivals at the live block size: every sample identical.
    const auto replay = eng::renderWadingArrivals(options, back, kBlock);
    ASSERT_EQ(replay.frames(), total);
    std::size_t differing = 0;
    double energy = 0;
    for (std::size_t i = 0; i < 2 * total; ++i) {
        differing += replay.samples[i] != live[i];
        energy += double(live[i]) * live[i];
    }
    EXPECT_GT(energy, 0.0) << "the water was silent: nothing compared";
    EXPECT_EQ(differing, 0u);

    // The same frames on their 100 Hz grid (the replay of trials without arrivals) differ.
    const auto grid = eng::renderWading(options, node.recording());
    std::size_t gridDiffering = 0;
    for (std::size_t i = 0; i < std::min(grid.samples.size(), live.size()); ++i)
        gridDiffering += grid.samples[i] != live[i];
    std::printf("[ wading   ] %zu frames, %zu off the 100 Hz grid: arrivals replay %zu of %zu "
                "samples differ, 100 Hz grid replay %zu\n",
                back.frames.size(), offGrid, differing, 2 * total, gridDiffering);
    EXPECT_GT(gridDiffering, total / 10);
}

TEST(WadingArrivals, BadFilesAreRefusedNamingFileLineAndWhatWasExpected) {
    const std::string header =
        "sample,time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,right_shank_dps\n";
    const auto message = [](const std::string& text) {
        try {
            eng::parseGaitArrivals(text, "a.csv");
        } catch (const eng::GaitFileError& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    EXPECT_EQ(message("# samples = 100\n" + header + "0,0,1,2,3,4\n99,0.1,1,2,3,4\n"),
              "(accepted)");
    const auto ok = eng::parseGaitArrivals("# samples = 100\n" + header + "0,0,1,2,3,4\n", "a");
    EXPECT_EQ(ok.samples, 100);
    ASSERT_EQ(ok.frames.size(), 1u);
    EXPECT_EQ(ok.frames[0].frame.angularVelocityDps[3], 4.0);

    EXPECT_EQ(message(""), "a.csv: no header line `" + header.substr(0, header.size() - 1) + "`");
    EXPECT_NE(message(header).find("a.csv:1: no `# samples = N` line"), std::string::npos)
        << message(header);
    EXPECT_NE(message("# samples = -3\n" + header).find("a.csv:1:"), std::string::npos);
    EXPECT_NE(message("# samples = 100\ntime,x\n").find("a.csv:2: header `time,x`: expected"),
              std::string::npos);
    EXPECT_NE(message("# samples = 100\n" + header + "0,0,1,2,3\n")
                  .find("a.csv:3: 5 fields: expected sample, time and 4 angular velocities"),
              std::string::npos);
    EXPECT_NE(
        message("# samples = 100\n" + header + "0,0,1,2,3,4,5\n").find("a.csv:3: more than 6"),
        std::string::npos);
    EXPECT_NE(message("# samples = 100\n" + header + "0,0,nan,2,3,4\n")
                  .find("a.csv:3: angular velocity `nan`: expected a finite number"),
              std::string::npos);
    EXPECT_NE(message("# samples = 100\n" + header + "5,0,1,2,3,4\n4,0,1,2,3,4\n")
                  .find("a.csv:4: sample 4: expected 5 to 99"),
              std::string::npos);
    EXPECT_NE(message("# samples = 100\n" + header + "100,0,1,2,3,4\n").find("a.csv:3: sample 100"),
              std::string::npos);
    EXPECT_NE(message("# samples = 100\n" + header + "x,0,1,2,3,4\n")
                  .find("a.csv:3: sample `x`: expected a whole number"),
              std::string::npos);
    // Found by fuzz_gait_arrivals (regressions/gait_arrivals/): a second `# samples` line after
    // the frames shortened the run and left frames already read outside it.
    EXPECT_NE(message("# samples = 9600\n" + header + "480,0.01,1,2,3,4\n# samples = 96\n")
                  .find("a.csv:4: `# samples = 96`: a second `# samples = ` line"),
              std::string::npos)
        << message("# samples = 9600\n" + header + "480,0.01,1,2,3,4\n# samples = 96\n");
    EXPECT_THROW(eng::readGaitArrivals("/nonexistent/a.csv"), eng::GaitFileError);
}

// The run length is a number read from the file: a tiny file must not make the replay allocate
// hours of audio (found reviewing fuzz_gait_arrivals: `# samples` up to 24 h asked ~33 GB).
TEST(WadingArrivals, ARunFarLongerThanItsFramesIsRefusedBeforeAllocating) {
    eng::WadingOptions options;
    options.sampleRateHz = 48000;
    const auto refused = [&](const eng::GaitArrivals& a) {
        try {
            eng::renderWadingArrivals(options, a, 64);
        } catch (const eng::WadingOptionError& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    eng::GaitArrivals a;
    a.samples = 24LL * 3600 * 48000 - 1; // under the 24 h cap: the gaps must refuse it
    a.frames.push_back({480, {}});
    EXPECT_NE(refused(a).find("expected the run to end at most 30 s after its last frame"),
              std::string::npos)
        << refused(a);
    a.frames.push_back({480 + 31 * 48000, {}});
    EXPECT_NE(refused(a).find("31.0 s without a frame (sample 480 to 1488480)"), std::string::npos)
        << refused(a);
    eng::GaitArrivals late;
    late.samples = 40 * 48000;
    late.frames.push_back({31 * 48000, {}});
    EXPECT_NE(refused(late).find("31.0 s without a frame (sample 0 to"), std::string::npos)
        << refused(late);
    eng::GaitArrivals fine; // 2 s with a frame every 10 ms is replayed
    fine.samples = 2 * 48000;
    for (std::int64_t s = 0; s < fine.samples; s += 480) fine.frames.push_back({s, {}});
    EXPECT_EQ(eng::renderWadingArrivals(options, fine, 64).frames(), 96000u);
}
