// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Helpers of the block-size identity tests: tests/engine/test_block_size_identity.cpp
// (default run, label engine) and tests/soak/test_block_size_identity_soak.cpp (label soak).
#include "engine/control/VirtualWalker.h"
#include "engine/render/FootstepScene.h"
#include "engine/render/Renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace underfoot::test::blocksize {
using namespace underfoot::engine;

constexpr double kFs = 48000.0;
constexpr int kMaxBlock = 1000;

/// Host block sizes: a fixed size, or (size 0) a sequence that changes at every call.
struct Blocks {
    int fixed = 64;
    std::uint32_t state = 12345u;
    int next() {
        if (fixed > 0) return fixed;
        // A small LCG: sizes 1..kMaxBlock, with runs of tiny blocks now and then.
        state = state * 1664525u + 1013904223u;
        const int r = static_cast<int>(state >> 8);
        return (r & 3) == 0 ? 1 + (r >> 4) % 7 : 1 + (r >> 4) % kMaxBlock;
    }
    int maxBlock() const { return fixed > 0 ? fixed : kMaxBlock; }
    std::string name() const { return fixed > 0 ? std::to_string(fixed) : "varying"; }
};

inline std::vector<Blocks> hostBlocks(const std::vector<int>& more = {}) {
    std::vector<Blocks> b;
    for (int s : {1, 37, 256, 1000}) b.push_back(Blocks{s});
    for (int s : more) b.push_back(Blocks{s});
    b.push_back(Blocks{0});
    return b;
}

/// Two feet walking, pausing twice long enough for every layer to ring out and fall asleep.
inline GrfSignal walkWithPauses(double walkSeconds, double pauseSeconds) {
    GrfSignal grf;
    grf.sampleRateHz = kFs;
    grf.names = {"left", "right"};
    grf.channels.assign(2, {});
    const auto pause = static_cast<std::size_t>(pauseSeconds * kFs);
    for (std::uint64_t part = 0; part < 3; ++part) {
        const GrfSignal w =
            walkerGrf(WalkerParameters{}, part == 2 ? 0.6 : walkSeconds, kFs, 11 + part);
        for (std::size_t c = 0; c < 2; ++c) {
            auto& ch = grf.channels[c];
            ch.insert(ch.end(), w.channels[c].begin(), w.channels[c].end());
            ch.resize(ch.size() + pause, 0.0f);
        }
    }
    return grf;
}

struct Render {
    std::vector<float> left, right;
    std::vector<int> sleeps; ///< per layer of voice 0: times it fell asleep (64-frame render)
};

inline Render renderScene(const std::string& surface, const GrfSignal& grf, Blocks blocks,
                          bool countSleeps = false) {
    FootstepScene scene;
    scene.build(surface, {});
    scene.prepare({kFs, blocks.maxBlock()});
    scene.reset(5);
    const std::size_t frames = grf.frames();
    Render r;
    r.left.assign(frames, 0.0f);
    r.right.assign(frames, 0.0f);
    const int layers = scene.surface(0).layerCount();
    r.sleeps.assign(static_cast<std::size_t>(layers), 0);
    std::vector<bool> asleep(static_cast<std::size_t>(layers), true);
    for (std::size_t start = 0; start < frames;) {
        const auto n =
            std::min<std::size_t>(static_cast<std::size_t>(blocks.next()), frames - start);
        const float* in[2] = {grf.channels[0].data() + start, grf.channels[1].data() + start};
        scene.process(in, r.left.data() + start, r.right.data() + start, static_cast<int>(n));
        start += n;
        if (countSleeps)
            for (int l = 0; l < layers; ++l) {
                const bool s = scene.surface(0).layer(l).isSleeping();
                if (s && !asleep[static_cast<std::size_t>(l)])
                    ++r.sleeps[static_cast<std::size_t>(l)];
                asleep[static_cast<std::size_t>(l)] = s;
            }
    }
    return r;
}

inline bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

/// Frames that differ (for the failure message).
inline std::string differences(const std::vector<float>& a, const std::vector<float>& b) {
    std::size_t count = 0, first = a.size();
    double largest = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) {
            ++count;
            first = std::min(first, i);
            largest = std::max(largest, std::fabs(double(a[i]) - double(b[i])));
        }
    return std::to_string(count) + " of " + std::to_string(a.size()) + " samples differ, first " +
           std::to_string(first) + ", largest difference " + std::to_string(largest);
}

inline void expectSurfacesBlockSizeIdentical(double walkSeconds,
                                             const std::vector<int>& moreBlocks) {
    const auto surfaces = listSurfaces();
    ASSERT_EQ(surfaces.size(), 18u) << "the shipped surfaces changed: update this test's count";
    // Pauses long enough for every layer to ring out and sleep: 1 s on solid and aggregate
    // floors, 2.6 s in water (its wake lasts 2.4 s after the foot leaves).
    const GrfSignal solid = walkWithPauses(walkSeconds, 1.0);
    const GrfSignal liquid = walkWithPauses(walkSeconds, 2.6);
    for (const auto& info : surfaces) {
        const std::string& id = info.id;
        const GrfSignal& grf = info.category == SurfaceCategory::Liquid ? liquid : solid;
        SCOPED_TRACE(id);
        const Render reference = renderScene(id, grf, Blocks{64}, true);
        for (std::size_t l = 0; l < reference.sleeps.size(); ++l)
            EXPECT_GE(reference.sleeps[l], 2)
                << "layer " << l << " fell asleep " << reference.sleeps[l]
                << " times: it must fall asleep (and wake) more than once for the test to mean "
                   "anything";
        for (const Blocks& b : hostBlocks(moreBlocks)) {
            const Render r = renderScene(id, grf, b);
            EXPECT_TRUE(sameBits(reference.left, r.left))
                << "blocks " << b.name() << ", left: " << differences(reference.left, r.left);
            EXPECT_TRUE(sameBits(reference.right, r.right))
                << "blocks " << b.name() << ", right: " << differences(reference.right, r.right);
        }
    }
}
} // namespace underfoot::test::blocksize
