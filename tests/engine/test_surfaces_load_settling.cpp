// SPDX-License-Identifier: GPL-3.0-or-later
// LoadSettling (engine/surfaces/LoadInput.h): a load held still keeps the layers' load-driven
// events for afterS, then they fade with tauS and stop; any movement restores them at once.
#include "engine/surfaces/LoadInput.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace underfoot::engine;

TEST(LoadSettling, HoldsThenFadesThenStopsAndMovementRestoresAtOnce) {
    const double fs = 1000.0;
    LoadSettling s;
    s.prepare({2.0, 0.5}, fs);
    s.reset();
    EXPECT_EQ(s.next(true), 1.0);
    // Held still: exactly 1 for the 2000 samples of the hold (walks render unchanged).
    for (int i = 1; i <= 2000; ++i) ASSERT_EQ(s.next(false), 1.0) << i;
    // Then exp(-t / tau): 500 samples later 1/e (within the rounding of 500 products).
    double f = 1.0;
    for (int i = 1; i <= 500; ++i) f = s.next(false);
    EXPECT_NEAR(f, std::exp(-1.0), 1e-12);
    EXPECT_GT(f, 0.0);
    // Cut to exactly 0 once below 1e-4 (ln(1e4) tau = 4.6 s after the hold), and it stays 0.
    int zeroAt = -1;
    for (int i = 1; i <= 5000; ++i)
        if (s.next(false) == 0.0 && zeroAt < 0) zeroAt = 500 + i;
    EXPECT_NEAR(zeroAt, std::log(1e4) * 500.0, 2.0);
    EXPECT_EQ(s.next(false), 0.0);
    // A movement of the load: full rate at once, and the hold starts again.
    EXPECT_EQ(s.next(true), 1.0);
    for (int i = 1; i <= 2000; ++i) ASSERT_EQ(s.next(false), 1.0) << i;
    EXPECT_LT(s.next(false), 1.0);
    // Leaving the ground (reset) also restores it.
    s.reset();
    EXPECT_EQ(s.next(false), 1.0);
}

TEST(LoadSettling, TheGrainsAndBubblesThresholdIsTheLoadsRateOfChange) {
    LoadSettling s;
    s.prepare({0.001, 0.5}, 1000.0); // hold of one sample
    s.reset();
    EXPECT_EQ(s.inContact(0.4), 1.0); // still (below 0.5 kN/s), but within the hold
    EXPECT_LT(s.inContact(-0.4), 1.0);
    EXPECT_EQ(s.inContact(-0.6), 1.0); // moving, either way
    EXPECT_EQ(s.inContact(0.0), 1.0);
    EXPECT_LT(s.inContact(0.0), 1.0);
}
