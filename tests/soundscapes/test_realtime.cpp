// SPDX-License-Identifier: GPL-3.0-or-later
// The soundscape renderer's process() runs on the audio thread: prove that it never allocates
// by replacing the global allocation functions of this test program with counting ones that
// are armed only around process() (JUCE's convolution test does the same).
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> gArmed{false};
std::atomic<long> gAllocations{0};

void* countedAlloc(std::size_t size) {
    if (gArmed.load(std::memory_order_relaxed)) gAllocations.fetch_add(1);
    if (void* p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}

struct AllocationTrap {
    AllocationTrap() {
        gAllocations = 0;
        gArmed = true;
    }
    ~AllocationTrap() { gArmed = false; }
};
} // namespace

void* operator new(std::size_t size) {
    return countedAlloc(size);
}
void* operator new[](std::size_t size) {
    return countedAlloc(size);
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}

using namespace underfoot::soundscapes;

TEST(SoundscapeRealtime, TheTrapSeesAnAllocation) {
    long seen = 0;
    {
        AllocationTrap trap;
        auto* p = new int(3);
        delete p;
        seen = gAllocations.load();
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
            allocations = gAllocations.load();
        }
        EXPECT_EQ(allocations, 0);
    }
}
