// SPDX-License-Identifier: GPL-3.0-or-later
// The headphone check's rule (experiment/HeadphoneCheck.h): the seed lays out every triplet
// and every sample, the tones are what Woods et al. (2017) describe (200 Hz, one 6 dB down,
// one of the loud ones in antiphase), and the scoring refuses what a page could forge.
#include "experiment/HeadphoneCheck.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace underfoot::experiment {
namespace {

constexpr double kLate = std::numeric_limits<double>::infinity();

/// Peak of channel `ch` (0 left, 1 right) in tone interval `k` of a rendered triplet.
int peak(const std::vector<std::int16_t>& s, int k, int ch) {
    const int tone = static_cast<int>(HeadphoneCheck::kToneSeconds * HeadphoneCheck::kSampleRateHz);
    const int gap = static_cast<int>(HeadphoneCheck::kGapSeconds * HeadphoneCheck::kSampleRateHz);
    int p = 0;
    for (int i = 0; i < tone; ++i)
        p = std::max(p, std::abs(static_cast<int>(
                            s[static_cast<std::size_t>((k * (tone + gap) + i) * 2 + ch)])));
    return p;
}

TEST(HeadphoneCheck, TheSeedLaysOutEveryTriplet) {
    const auto a = HeadphoneCheck::layout(42), b = HeadphoneCheck::layout(42);
    ASSERT_EQ(a.size(), 6u);
    int differs = 0;
    for (std::uint64_t seed = 1; seed <= 50; ++seed) {
        const auto l = HeadphoneCheck::layout(seed);
        for (const auto& t : l) {
            EXPECT_NE(t.quiet, t.antiphase);
            EXPECT_GE(t.quiet, 0);
            EXPECT_LE(t.quiet, 2);
            EXPECT_GE(t.antiphase, 0);
            EXPECT_LE(t.antiphase, 2);
        }
        differs += l[0].quiet != a[0].quiet || l[0].antiphase != a[0].antiphase;
    }
    EXPECT_GT(differs, 10); // other seeds, other layouts
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].quiet, b[k].quiet);
        EXPECT_EQ(a[k].antiphase, b[k].antiphase);
    }
    // Every quiet interval and antiphase partner occurs (1000 triplets).
    int seen[3][3] = {};
    for (const auto& t : HeadphoneCheck::layout(7, 1000)) ++seen[t.quiet][t.antiphase];
    for (int q = 0; q < 3; ++q)
        for (int p = 0; p < 3; ++p)
            if (q != p) {
                EXPECT_GT(seen[q][p], 100) << q << " " << p;
            }
}

TEST(HeadphoneCheck, TonesAreQuietAndAntiphaseWhereTheLayoutSays) {
    EXPECT_DOUBLE_EQ(HeadphoneCheck::tripletSeconds(), 4.0);
    const HeadphoneCheck::Triplet t{2, 0};
    const auto s = HeadphoneCheck::render(t);
    ASSERT_EQ(s.size(), static_cast<std::size_t>(HeadphoneCheck::tripletFrames()) * 2);
    // Left = right except the antiphase tone, where left = -right, sample for sample.
    const int tone = static_cast<int>(HeadphoneCheck::kToneSeconds * HeadphoneCheck::kSampleRateHz);
    for (std::size_t f = 0; f < s.size() / 2; ++f) {
        const bool inFirstTone = f < static_cast<std::size_t>(tone);
        ASSERT_EQ(s[2 * f], inFirstTone ? -s[2 * f + 1] : s[2 * f + 1]) << f;
    }
    // The quiet tone is 6 dB down (20 log10 0.5012 = -6.0 dB) in each ear.
    const double down = 20.0 * std::log10(static_cast<double>(peak(s, 2, 0)) / peak(s, 1, 0));
    EXPECT_NEAR(down, -6.0, 0.05);
    EXPECT_EQ(peak(s, 0, 0), peak(s, 1, 0));
    EXPECT_GT(peak(s, 0, 0), 3000); // 0.1 of full scale: audible, far from clipping
    // The WAV is the same samples behind a 44-byte header.
    const std::string w = HeadphoneCheck::wav(t);
    ASSERT_EQ(w.size(), 44 + s.size() * 2);
    EXPECT_EQ(w.substr(0, 4), "RIFF");
    EXPECT_EQ(w.substr(8, 8), "WAVEfmt ");
    EXPECT_EQ(w.substr(36, 4), "data");
    EXPECT_EQ(HeadphoneCheck::wav(t), w);
    EXPECT_NE(HeadphoneCheck::wav({1, 0}), w);
}

TEST(HeadphoneCheck, ScoringRefusesWhatAPageCouldForge) {
    HeadphoneCheck c(9, 4.0);
    const auto& l = c.triplets();
    EXPECT_TRUE(c.answer(0, l[0].quiet + 1, std::nullopt).has_value()); // tones never served
    EXPECT_TRUE(c.answer(0, l[0].quiet + 1, 3.9).has_value());          // before they ended
    EXPECT_TRUE(c.answer(1, l[1].quiet + 1, kLate).has_value());        // out of order
    EXPECT_TRUE(c.answer(0, 0, kLate).has_value());
    EXPECT_TRUE(c.answer(0, 4, kLate).has_value());
    EXPECT_EQ(c.next(), 0);
    EXPECT_FALSE(c.answer(0, l[0].quiet + 1, 4.0).has_value());
    EXPECT_EQ(c.next(), 1);
}

TEST(HeadphoneCheck, FiveOfSixPass) {
    for (int wrong = 0; wrong <= 6; ++wrong) {
        HeadphoneCheck c(11);
        for (int k = 0; k < HeadphoneCheck::kTriplets; ++k) {
            const int quiet = c.triplets()[static_cast<std::size_t>(k)].quiet + 1;
            EXPECT_FALSE(c.passed());
            ASSERT_FALSE(c.answer(k, k < wrong ? quiet % 3 + 1 : quiet, kLate).has_value());
        }
        EXPECT_TRUE(c.done());
        EXPECT_EQ(c.correct(), 6 - wrong);
        EXPECT_EQ(c.passed(), wrong <= 1) << wrong;
        EXPECT_TRUE(c.answer(6, 1, kLate).has_value()); // nothing after the last triplet
    }
}

} // namespace
} // namespace underfoot::experiment
