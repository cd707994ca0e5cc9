// SPDX-License-Identifier: GPL-3.0-or-later
// Counts in words (base/Plural.h): only 1 takes the singular, in every integer type the
// programs count with.
#include "base/Plural.h"

#include <gtest/gtest.h>

#include <cstddef>

using underfoot::counted;
using underfoot::plural;

TEST(Plural, OneTakesTheSingularEveryOtherCountThePlural) {
    EXPECT_EQ(counted(1, "participant"), "1 participant");
    EXPECT_EQ(counted(2, "participant"), "2 participants");
    EXPECT_EQ(counted(0, "trial"), "0 trials");
    EXPECT_EQ(counted(std::size_t{1}, "simulated participant"), "1 simulated participant");
    EXPECT_EQ(counted(std::size_t{12}, "trial row"), "12 trial rows");
    EXPECT_EQ(counted(-1, "step"), "-1 steps");
}

TEST(Plural, AnIrregularPluralIsGiven) {
    EXPECT_EQ(counted(1, "child", "children"), "1 child");
    EXPECT_EQ(counted(3, "child", "children"), "3 children");
    EXPECT_EQ(plural(1u, "stimulus", "stimuli"), "stimulus");
    EXPECT_EQ(plural(2u, "stimulus", "stimuli"), "stimuli");
    EXPECT_EQ(plural(5L, "column"), "columns");
}
