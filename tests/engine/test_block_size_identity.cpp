// SPDX-License-Identifier: GPL-3.0-or-later
// The output is the same, to the last bit, for every host block size. A replay
// renders a live trial at whatever block size it is given, so every decision a layer takes
// (falling asleep, flushing tiny state, starting a grain) must not depend on where the host cuts
// the signal. The layers decide on a fixed grid from reset (engine/dsp/SleepGrid.h).
//
// Every shipped surface (the reverb variants with their impulse responses), both wading depths:
// rendered with host blocks 1, 37, 64, 256, 1000 and a block size that changes at every call,
// the float output compared bit for bit (memcmp) with the 64-frame render. The walk pauses twice
// so that every layer falls asleep and wakes again (counted, so the test checks that it covers
// what it claims). The soundscape scene is in tests/soundscapes/test_scene_block_size.cpp.
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "engine/wading/WadingControl.h"
#include "engine/wading/WadingScene.h"
#include "tests/common/AllocationTrap.h"
#include "tests/engine/BlockSizeIdentity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

using namespace underfoot::engine;
using namespace underfoot::test::blocksize;

TEST(BlockSizeIdentity, EveryShippedSurfaceRendersTheSameBitsForEveryHostBlockSize) {
    expectSurfacesBlockSizeIdentical(1.2, {});
}

TEST(BlockSizeIdentity, WadingRendersTheSameBitsForEveryHostBlockSize) {
    // As renderWading() drives the scene, with the host block size as a parameter: frame k of
    // the virtual gait takes effect at the sample where it arrives.
    VirtualGaitParameters gaitParameters;
    gaitParameters.cadenceStepsPerMin = kNormalCadence;
    const auto gait = virtualGait(gaitParameters, 4.0, 3);
    const auto frames = static_cast<std::size_t>(4.0 * kFs);
    auto render = [&](const std::string& depth, Blocks blocks) {
        WadingScene scene;
        scene.configure(loadWadingPreset(depth), parseWadingAlgorithm("v2"),
                        parseGyroFilter("butterworth_5hz"));
        scene.prepare({kFs, blocks.maxBlock()});
        scene.reset(9);
        std::vector<float> out(2 * frames), l(kMaxBlock), r(kMaxBlock);
        std::vector<TimedGaitFrame> events;
        std::size_t next = 0;
        for (std::size_t start = 0; start < frames;) {
            const auto n =
                std::min<std::size_t>(static_cast<std::size_t>(blocks.next()), frames - start);
            events.clear();
            while (next < gait.size()) {
                const auto at = static_cast<std::size_t>(
                    std::llround(static_cast<double>(next) / kGaitFrameRateHz * kFs));
                if (at >= start + n) break;
                events.push_back({static_cast<int>(at - std::min(at, start)), gait[next]});
                ++next;
            }
            scene.process(events.data(), static_cast<int>(events.size()), l.data(), r.data(),
                          static_cast<int>(n));
            for (std::size_t i = 0; i < n; ++i) {
                out[2 * (start + i)] = l[i];
                out[2 * (start + i) + 1] = r[i];
            }
            start += n;
        }
        return out;
    };
    for (const std::string depth : {"shallow", "deep"}) {
        SCOPED_TRACE(depth);
        const auto reference = render(depth, Blocks{64});
        for (const Blocks& b : hostBlocks()) {
            const auto out = render(depth, b);
            EXPECT_TRUE(sameBits(reference, out))
                << "blocks " << b.name() << ": " << differences(reference, out);
        }
    }
}

TEST(BlockSizeIdentity, SleepingLayersStillNeverAllocate) {
    // The grid split and the per-sample wake add no allocation on the audio path: a whole
    // walk with pauses, irregular blocks, one surface of each layer kind.
    const GrfSignal grf = walkWithPauses(1.2, 1.0);
    for (const std::string id : {"wood", "creaking_wood_reverb", "gravel", "water"}) {
        SCOPED_TRACE(id);
        FootstepScene scene;
        scene.build(id, {});
        scene.prepare({kFs, kMaxBlock});
        scene.reset(5);
        std::vector<float> l(kMaxBlock), r(kMaxBlock);
        Blocks blocks{0};
        underfoot::test::AllocationTrap trap;
        for (std::size_t start = 0; start < grf.frames();) {
            const auto n = std::min<std::size_t>(static_cast<std::size_t>(blocks.next()),
                                                 grf.frames() - start);
            const float* in[2] = {grf.channels[0].data() + start, grf.channels[1].data() + start};
            scene.process(in, l.data(), r.data(), static_cast<int>(n));
            start += n;
        }
        EXPECT_EQ(trap.count(), 0);
    }
}
