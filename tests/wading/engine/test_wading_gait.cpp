// SPDX-License-Identifier: GPL-3.0-or-later
// Gait inputs: the virtual gait, gait CSV files and the live frame assembler.
#include "engine/wading/Gait.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace {
using namespace underfoot::engine;

std::string errorOf(const std::string& text) {
    try {
        parseGaitCsv(text, "walk.csv");
    } catch (const GaitFileError& e) {
        return e.what();
    }
    return "";
}

TEST(VirtualGait, StandingStillIsZero) {
    VirtualGaitParameters p;
    p.cadenceStepsPerMin = 0;
    const auto g = virtualGait(p, 3.0, 1);
    ASSERT_EQ(g.size(), 300u);
    for (const auto& f : g)
        for (double v : f.angularVelocityDps) ASSERT_EQ(v, 0.0);
}

TEST(VirtualGait, CadenceAntiphaseAndNoDrift) {
    for (double cadence : {27.0, 63.0, 118.0}) {
        VirtualGaitParameters p;
        p.cadenceStepsPerMin = cadence;
        p.variability = 0;
        const double seconds = 40;
        const auto g = virtualGait(p, seconds, 1);
        // Swing onsets: upward crossings of 20 deg/s by the left thigh -> stride period.
        std::vector<double> onsetsL, onsetsR;
        double integral = 0;
        for (std::size_t k = 1; k < g.size(); ++k) {
            if (g[k - 1][Limb::LeftThigh] < 20 && g[k][Limb::LeftThigh] >= 20)
                onsetsL.push_back(g[k].timeS);
            if (g[k - 1][Limb::RightThigh] < 20 && g[k][Limb::RightThigh] >= 20)
                onsetsR.push_back(g[k].timeS);
            integral += g[k][Limb::LeftShank] / 100.0;
        }
        ASSERT_GE(onsetsL.size(), 3u) << cadence;
        const double stride =
            (onsetsL.back() - onsetsL.front()) / static_cast<double>(onsetsL.size() - 1);
        EXPECT_NEAR(stride, 120.0 / cadence, 0.02) << cadence;
        // Right swings half a stride after left ones.
        double lag = onsetsR.front() - onsetsL.front();
        if (lag < 0) lag += stride;
        EXPECT_NEAR(lag, stride / 2, 0.03) << cadence;
        // Forward and backward rotations balance over whole strides (angle does not drift).
        EXPECT_LT(std::fabs(integral), 150.0) << cadence;
    }
}

TEST(VirtualGait, FasterCadenceSwingsFasterAndShankPeaksLater) {
    auto peak = [](double cadence, Limb limb) {
        VirtualGaitParameters p;
        p.cadenceStepsPerMin = cadence;
        p.variability = 0;
        double m = 0;
        for (const auto& f : virtualGait(p, 10, 1)) m = std::max(m, f[limb]);
        return m;
    };
    for (double c : {27.0, 63.0, 118.0})
        std::printf("[ measured ] virtual gait %.0f steps/min: thigh peak %.0f deg/s, shank peak "
                    "%.0f deg/s\n",
                    c, peak(c, Limb::LeftThigh), peak(c, Limb::LeftShank));
    EXPECT_LT(peak(27, Limb::LeftThigh), peak(63, Limb::LeftThigh));
    EXPECT_LT(peak(63, Limb::LeftThigh), peak(118, Limb::LeftThigh));
    EXPECT_GT(peak(63, Limb::LeftShank), peak(63, Limb::LeftThigh));
    // Within one swing the shank peak comes after the thigh peak (paper Fig. 3).
    VirtualGaitParameters p;
    p.variability = 0;
    const auto g = virtualGait(p, 4, 1);
    std::size_t thighAt = 0, shankAt = 0;
    for (std::size_t k = 0; k < 200; ++k) {
        if (g[k][Limb::LeftThigh] > g[thighAt][Limb::LeftThigh]) thighAt = k;
        if (g[k][Limb::LeftShank] > g[shankAt][Limb::LeftShank]) shankAt = k;
    }
    EXPECT_GT(shankAt, thighAt);
}

TEST(VirtualGait, SeededAndValidated) {
    VirtualGaitParameters p;
    const auto a = virtualGait(p, 5, 7), b = virtualGait(p, 5, 7), c = virtualGait(p, 5, 8);
    ASSERT_EQ(a.size(), b.size());
    bool differ = false;
    for (std::size_t k = 0; k < a.size(); ++k) {
        ASSERT_EQ(a[k].angularVelocityDps, b[k].angularVelocityDps);
        differ |= a[k].angularVelocityDps != c[k].angularVelocityDps;
    }
    EXPECT_TRUE(differ);
    p.cadenceStepsPerMin = 5;
    EXPECT_THROW(virtualGait(p, 5, 1), std::invalid_argument);
    p.cadenceStepsPerMin = NAN;
    EXPECT_THROW(virtualGait(p, 5, 1), std::invalid_argument);
}

TEST(GaitCsv, RoundTripAndResampling) {
    VirtualGaitParameters p;
    const auto g = virtualGait(p, 3, 2);
    const auto path = (std::filesystem::temp_directory_path() / "wading_gait_rt.csv").string();
    writeGaitCsv(path, g);
    bool shanks = false;
    const auto back = readGaitCsv(path, &shanks);
    std::filesystem::remove(path);
    EXPECT_TRUE(shanks);
    ASSERT_EQ(back.size(), g.size());
    for (std::size_t k = 0; k < g.size(); ++k)
        for (std::size_t l = 0; l < 4; ++l)
            ASSERT_NEAR(back[k].angularVelocityDps[l], g[k].angularVelocityDps[l], 1e-6);
    // 50 Hz thigh-only rows are interpolated onto 100 Hz frames; shanks read as 0.
    const auto half = parseGaitCsv("# thighs only\ntime,left_thigh,right_thigh\n"
                                   "10.00,0,100\n10.02,20,80\n10.04,40,60\n",
                                   "half.csv", &shanks);
    EXPECT_FALSE(shanks);
    ASSERT_EQ(half.size(), 5u);
    EXPECT_NEAR(half[1][Limb::LeftThigh], 10, 1e-9);
    EXPECT_NEAR(half[3][Limb::RightThigh], 70, 1e-9);
    EXPECT_NEAR(half[3].timeS, 0.03, 1e-12);
    EXPECT_EQ(half[2][Limb::LeftShank], 0.0);
}

TEST(GaitCsv, MalformedFilesNameFileLineAndExpectation) {
    const std::string header = "time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,"
                               "right_shank_dps\n";
    EXPECT_EQ(errorOf(header + "0,1,2,3,4\n0.01,1,2,nan,4\n"),
              "walk.csv:3: field 4 (\"nan\"): expected a finite number (NaN/Inf refused)");
    EXPECT_NE(errorOf(header + "0,1,2,3,4\n0.01,1,2,inf,4\n").find("walk.csv:3: field 4"),
              std::string::npos);
    EXPECT_EQ(errorOf(header + "0,1,2,3,4\n0.01,1,2,3\n"),
              "walk.csv:3: expected 5 comma-separated numbers, got 4 fields");
    EXPECT_EQ(errorOf(header + "0,1,2,3,4\n0.01,1,x2,3,4\n"),
              "walk.csv:3: field 3 (\"x2\"): expected a number");
    EXPECT_NE(errorOf(header + "0,1,2,3,4\n0,1,2,3,4\n")
                  .find("walk.csv:3: time 0 s: expected "
                        "times to increase"),
              std::string::npos);
    EXPECT_NE(errorOf("time_s,left_knee\n").find("walk.csv:1: unknown column \"left_knee\""),
              std::string::npos);
    EXPECT_NE(errorOf("time_s,left_thigh\n0,1\n").find("walk.csv:1: expected a header"),
              std::string::npos);
    EXPECT_NE(errorOf("# nothing\n").find("walk.csv:1: empty file"), std::string::npos);
    EXPECT_NE(errorOf(header + "0,1,2,3,4\n").find("at least two rows"), std::string::npos);
    EXPECT_NE(errorOf(header + "0,1,2,3,4\n0.01,1,2,3,9000\n").find("within +-5000"),
              std::string::npos);
    EXPECT_THROW(readGaitCsv("/nonexistent/gait.csv"), GaitFileError);
}

TEST(GaitFrameAssembler, FoldsPerLimbPacketsIntoFrames) {
    GaitFrameAssembler a;
    a.reset();
    GaitFrame f;
    int frames = 0;
    // Four limbs per 10 ms, one packet each, 2 ms apart, for 1 s.
    for (int k = 0; k < 100; ++k)
        for (int l = 0; l < 4; ++l) {
            GyroSample s;
            s.timeS = 0.01 * k + 0.002 * l;
            s.limb = static_cast<Limb>(l);
            s.angularVelocityDps = 10.0 * l + k;
            if (a.push(s, f)) ++frames;
        }
    EXPECT_EQ(frames, 100);
    EXPECT_EQ(f[Limb::LeftThigh], 99.0);
    EXPECT_EQ(f[Limb::RightShank], 30.0 + 98.0); // the latest held value at the frame's instant
    GyroSample bad;
    bad.timeS = 1.5;
    bad.angularVelocityDps = NAN;
    EXPECT_FALSE(a.push(bad, f));
    EXPECT_EQ(a.rejectedSamples(), 1u);
}

} // namespace
