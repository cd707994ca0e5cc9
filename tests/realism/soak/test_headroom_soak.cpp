// SPDX-License-Identifier: GPL-3.0-or-later
// Soak (label soak): headroom of every bundled surface over masses 20-200 kg, shoes soft to hard,
// cadences 60-150 steps/min and sixteen seeds; prints the worst peak of every surface.
#include "tests/realism/Headroom.h"

using namespace underfoot::test;

TEST(HeadroomSoak, EveryWalkerAndSeedStaysOneDbBelowTheLimiter) {
    std::vector<std::string> walkers;
    for (const char* m : {"20", "70", "120", "200"})
        for (const char* s : {"0", "0.5", "1"})
            for (const char* c : {"60", "100", "150"})
                walkers.push_back(std::string("mass=") + m + ",shoe=" + s + ",cadence=" + c);
    const auto worst = worstPeaks(walkers, 16, 3.0);
    printPeaks(worst);
    expectWithinLimits(worst);
}
