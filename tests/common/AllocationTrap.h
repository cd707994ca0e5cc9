// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Proof that audio-thread code does not allocate: AllocationTrap.cpp replaces the global
/// allocation functions of the test program with counting ones, armed only inside a trap
/// (JUCE's convolution test does the same). Link AllocationTrap.cpp into a test program to use it.
#include <atomic>

namespace underfoot::test {

extern std::atomic<long> allocationCount;  ///< allocations seen while armed
extern std::atomic<bool> countAllocations; ///< armed?

/// Arms (or disarms) the counter for the calling thread only, independently of
/// `countAllocations`: audio-callback hooks use it where other threads (a sensor receiver, a
/// recorder's writer) legitimately allocate while the callback runs.
void armThisThread(bool on) noexcept;

/// Arms the counter (from zero) for its lifetime.
struct AllocationTrap {
    AllocationTrap() {
        allocationCount = 0;
        countAllocations = true;
    }
    ~AllocationTrap() { countAllocations = false; }
    AllocationTrap(const AllocationTrap&) = delete;
    AllocationTrap& operator=(const AllocationTrap&) = delete;
    long count() const { return allocationCount.load(); }
};

} // namespace underfoot::test
