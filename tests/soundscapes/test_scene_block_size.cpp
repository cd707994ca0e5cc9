// SPDX-License-Identifier: GPL-3.0-or-later
// A whole shipped scene (gravel under both feet + the farm courtyard soundscape,
// mixed as the live headphone mix adds the ambience) renders the same bits for every host block
// size: 1, 37, 64, 256, 1000 and a size that changes at every call. The walk pauses twice, so the
// grains layers fall asleep and wake while the soundscape plays on. (Surfaces and wading alone:
// tests/engine/test_block_size_identity.cpp.)
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"
#include "tests/engine/BlockSizeIdentity.h"

#include <gtest/gtest.h>

using namespace underfoot;
using namespace underfoot::test::blocksize;

TEST(SceneBlockSize, SurfaceWithSoundscapeRendersTheSameBitsForEveryHostBlockSize) {
    const engine::GrfSignal grf = walkWithPauses(1.2, 1.0);
    const std::size_t frames = grf.frames();
    engine::FootstepScene scene;
    scene.build("gravel", {});
    scene.prepare({kFs, kMaxBlock});
    soundscapes::SoundscapeRenderer ambience(soundscapes::loadSoundscape("farm_courtyard"));
    ambience.prepare({kFs, kMaxBlock});
    auto render = [&](Blocks blocks) {
        scene.reset(5);
        ambience.reset(5);
        std::vector<float> l(frames), r(frames), al(kMaxBlock), ar(kMaxBlock);
        for (std::size_t start = 0; start < frames;) {
            const auto n =
                std::min<std::size_t>(static_cast<std::size_t>(blocks.next()), frames - start);
            const float* in[2] = {grf.channels[0].data() + start, grf.channels[1].data() + start};
            scene.process(in, l.data() + start, r.data() + start, static_cast<int>(n));
            ambience.process(al.data(), ar.data(), static_cast<int>(n));
            for (std::size_t i = 0; i < n; ++i) {
                l[start + i] += al[i];
                r[start + i] += ar[i];
            }
            start += n;
        }
        return std::make_pair(l, r);
    };
    const auto reference = render(Blocks{64});
    for (const Blocks& b : hostBlocks()) {
        const auto out = render(b);
        EXPECT_TRUE(sameBits(reference.first, out.first))
            << "blocks " << b.name() << ", left: " << differences(reference.first, out.first);
        EXPECT_TRUE(sameBits(reference.second, out.second))
            << "blocks " << b.name() << ", right: " << differences(reference.second, out.second);
    }
}
