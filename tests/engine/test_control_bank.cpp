// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/GrfBank.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

using namespace underfoot::engine;

TEST(GrfBank, HeelPlusToeIsTheStanceAndEachStartsAtItsOnset) {
    WalkerParameters p = WalkerParameters::parse("cadence=100,mass=70,shoe=0.5,variability=0.08");
    const GrfBank bank = makeGrfBank(p, 5, 1, 48000);
    ASSERT_EQ(bank.heel.size(), 5u);
    ASSERT_EQ(bank.toe.size(), 5u);
    const double bw = 70 * kGravity;
    const double nominalStance = VirtualWalker::dutyFactor(100) * 1.2;
    for (std::size_t k = 0; k < 5; ++k) {
        const auto& h = bank.heel[k].channels[0];
        const auto& t = bank.toe[k].channels[0];
        EXPECT_EQ(bank.heel[k].names[0], "heel");
        EXPECT_EQ(h.front(), 0.0f);
        EXPECT_EQ(h.back(), 0.0f);
        EXPECT_EQ(t.back(), 0.0f);
        // The heel GRF rises at once (the heel-strike transient is in it).
        EXPECT_GT(h[static_cast<std::size_t>(0.01 * 48000)], 0.05 * bw);
        // The toe GRF starts at its onset: 1 % of its peak within the first two samples.
        const float toePeak = *std::max_element(t.begin(), t.end());
        EXPECT_GT(t[2], 0.01f * toePeak);
        EXPECT_LT(t[0], 0.01f * toePeak);
        // Stance length varies with the 8 % variability, around the nominal stance.
        EXPECT_NEAR(bank.heel[k].durationSeconds() / nominalStance, 1.0, 0.3);
        // Heel carries the first peak, the toe the push-off peak (~1.1-1.3 BW with variability).
        const float heelPeak = *std::max_element(h.begin(), h.end());
        EXPECT_GT(heelPeak, 0.9 * bw);
        EXPECT_LT(heelPeak, 1.6 * bw);
        EXPECT_GT(toePeak, 0.9 * bw);
        EXPECT_LT(toePeak, 1.5 * bw);
        // heel + toe rebuilds the walker's stance (toe aligned from the end): a double hump
        // whose valley at mid-stance is 0.55-0.9 BW and whose peaks are the parts' peaks.
        const std::size_t offset = h.size() - t.size();
        std::vector<double> sum(h.begin(), h.end());
        for (std::size_t i = 0; i < t.size(); ++i) sum[offset + i] += t[i];
        EXPECT_NEAR(*std::max_element(sum.begin(), sum.end()), std::max(heelPeak, toePeak), 1e-3);
        const double valley = *std::min_element(sum.begin() + long(0.4 * double(sum.size())),
                                                sum.begin() + long(0.6 * double(sum.size())));
        EXPECT_GT(valley, 0.55 * bw);
        EXPECT_LT(valley, 0.9 * bw);
    }
    // Five different GRFs of each kind, deterministic for a seed.
    for (std::size_t a = 0; a < 5; ++a)
        for (std::size_t b = a + 1; b < 5; ++b)
            EXPECT_NE(bank.heel[a].channels[0], bank.heel[b].channels[0]);
    const GrfBank again = makeGrfBank(p, 5, 1, 48000);
    EXPECT_EQ(again.toe[3].channels[0], bank.toe[3].channels[0]);
    EXPECT_THROW(makeGrfBank(p, 0, 1, 48000), std::invalid_argument);
}

TEST(GrfBank, HeelShareHandsOverFromHeelToToe) {
    EXPECT_EQ(heelShare(0.0), 1.0);
    EXPECT_EQ(heelShare(0.3), 1.0);
    EXPECT_NEAR(heelShare(0.45), 0.5, 1e-12);
    EXPECT_EQ(heelShare(0.6), 0.0);
    for (double s = 0; s < 1; s += 0.01) EXPECT_LE(heelShare(s + 0.01), heelShare(s));
}

TEST(GrfBank, ShippedBankLoadsAsGrfFiles) {
    // engine/data/grf/README.md documents the command that made these files.
    const std::string dir = UNDERFOOT_SOURCE_DIR "/engine/data/grf";
    for (const char* kind : {"heel", "toe"})
        for (int i = 1; i <= 5; ++i) {
            const auto path = dir + "/" + kind + "_" + std::to_string(i) + ".wav";
            const GrfSignal g = loadGrfFile(path);
            ASSERT_EQ(g.channels.size(), 1u) << path;
            const float peak = *std::max_element(g.channels[0].begin(), g.channels[0].end());
            EXPECT_GT(peak, 0.9 * 70 * kGravity) << path;
            EXPECT_LT(peak, 1.6 * 70 * kGravity) << path;
        }
    // And they equal what the documented command produces.
    const GrfBank bank = makeGrfBank(
        WalkerParameters::parse("cadence=100,mass=70,shoe=0.5,variability=0.08"), 5, 1, 48000);
    const GrfSignal heel3 = loadGrfFile(dir + "/heel_3.wav");
    ASSERT_EQ(heel3.frames(), bank.heel[2].frames());
    for (std::size_t i = 0; i < heel3.frames(); ++i)
        ASSERT_NEAR(heel3.channels[0][i], bank.heel[2].channels[0][i], 1e-3);
}
