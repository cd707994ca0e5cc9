// SPDX-License-Identifier: GPL-3.0-or-later
// The counting replacements of the global allocation functions (see AllocationTrap.h).
#include "tests/common/AllocationTrap.h"

#include <cstdlib>
#include <new>

namespace underfoot::test {
std::atomic<long> allocationCount{0};
std::atomic<bool> countAllocations{false};
namespace {
thread_local bool threadArmed = false;
}
void armThisThread(bool on) noexcept {
    threadArmed = on;
}
} // namespace underfoot::test

// The replacements pair malloc with free; GCC cannot see that once they are inlined here.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
void* countedAllocation(std::size_t size) {
    if (underfoot::test::countAllocations.load(std::memory_order_relaxed) ||
        underfoot::test::threadArmed)
        underfoot::test::allocationCount.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
} // namespace

void* operator new(std::size_t size) {
    return countedAllocation(size);
}
void* operator new[](std::size_t size) {
    return countedAllocation(size);
}
// The nothrow forms too (std::stable_sort's temporary buffer uses them): a default nothrow new
// paired with our free() is an alloc-dealloc mismatch under AddressSanitizer.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return countedAllocation(size);
    } catch (...) {
        return nullptr;
    }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
    try {
        return countedAllocation(size);
    } catch (...) {
        return nullptr;
    }
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
    std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
    std::free(p);
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
