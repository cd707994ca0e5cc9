// SPDX-License-Identifier: GPL-3.0-or-later
// The soundscape renderer's process() runs on the audio thread: prove that it never allocates
// with the counting allocation functions of tests/common/AllocationTrap.cpp, armed only around
// process().
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"
#include "tests/common/AllocationTrap.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

using underfoot::test::AllocationTrap;

using namespace underfoot::soundscapes;

TEST(SoundscapeRealtime, TheTrapSeesAnAllocation) {
    long seen = 0;
    {
        AllocationTrap trap;
        int* volatile p = new int(3); // volatile: the allocation cannot be elided
        delete p;
        seen = trap.count();
    }
    EXPECT_EQ(seen, 1); // the trap works, so the zero below means something
}

TEST(SoundscapeRealtime, ProcessNeverAllocatesInAnyEnvironment) {
    for (const char* id : {"beach_summer", "farm_courtyard", "ski_slope", "forest", "park_fall"}) {
        SCOPED_TRACE(id);
        SoundscapeRenderer r(loadSoundscape(id));
        r.prepare({48000.0, 256});
        std::vector<float> l(1000), rr(1000);
        long allocations = 0;
        {
            AllocationTrap trap;
            r.reset(9);
            // 30 s in odd-sized blocks (some longer than the prepared block size), so that
            // many events start and end inside blocks.
            for (int b = 0; b < 1500; ++b) r.process(l.data(), rr.data(), b % 3 == 0 ? 1000 : 960);
            allocations = trap.count();
        }
        EXPECT_EQ(allocations, 0);
    }
}
