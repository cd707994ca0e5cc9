// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/VirtualWalker.h"
#include "engine/dsp/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {

struct Walk {
    std::vector<float> left, right;
};

Walk walk(const WalkerParameters& p, double seconds, double rateHz = 48000, std::uint64_t seed = 7,
          int block = 256) {
    VirtualWalker w(p);
    w.prepare({rateHz, block});
    w.reset(seed);
    const auto n = static_cast<std::size_t>(seconds * rateHz);
    Walk out{std::vector<float>(n), std::vector<float>(n)};
    for (std::size_t i = 0; i < n; i += static_cast<std::size_t>(block)) {
        const int m =
            static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(block), n - i));
        w.process(out.left.data() + i, out.right.data() + i, m);
    }
    return out;
}

struct Contact {
    std::size_t on, off; // first sample > 0, first sample back at 0
};

std::vector<Contact> contacts(const std::vector<float>& x) {
    std::vector<Contact> c;
    bool in = false;
    std::size_t on = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (!in && x[i] > 0)
            in = true, on = i;
        else if (in && x[i] <= 0)
            in = false, c.push_back({on, i});
    }
    return c;
}

} // namespace

TEST(VirtualWalker, PeaksValleyAndTimingMatchTheParameters) {
    for (double cadence : {80.0, 100.0, 120.0, 140.0}) {
        WalkerParameters p;
        p.cadenceStepsPerMin = cadence;
        p.massKg = 80;
        p.variability = 0;
        p.shoeHardness = 0.5;
        const double fs = 48000, bw = 80 * kGravity;
        const Walk w = walk(p, 12, fs);
        const auto steps = contacts(w.left);
        ASSERT_GE(steps.size(), 5u) << cadence;
        const double stride = 120.0 / cadence;
        const StanceShape sh = VirtualWalker::shapeFor(p, stride / 2);
        for (std::size_t k = 1; k + 1 < steps.size(); ++k) {
            const auto [on, off] = steps[k];
            // Stride: heel strike to heel strike of the same foot.
            EXPECT_NEAR(double(steps[k + 1].on - on) / fs, stride, 1.5 / fs) << cadence;
            // Stance = duty factor x stride.
            const double stance = double(off - on) / fs;
            EXPECT_NEAR(stance, VirtualWalker::dutyFactor(cadence) * stride, 1.5 / fs);
            // (the onset copied: clang before 16 cannot capture a structured binding)
            const auto at = [&, onset = on](double s) {
                return onset + static_cast<std::size_t>(s * stance * fs);
            };
            // Heel peak: the maximum in s in [0.1, 0.4] is at s = 0.25 and equals F1.
            auto maxIn = [&](double a, double b) {
                return std::max_element(w.left.begin() + long(at(a)), w.left.begin() + long(at(b)));
            };
            auto heel = maxIn(0.1, 0.4);
            EXPECT_NEAR(*heel / bw, sh.heelPeakBw, 1e-4) << cadence;
            EXPECT_NEAR(double(heel - w.left.begin() - long(on)) / (stance * fs), 0.25, 0.01);
            auto valley =
                std::min_element(w.left.begin() + long(at(0.3)), w.left.begin() + long(at(0.7)));
            EXPECT_NEAR(*valley / bw, sh.valleyBw, 1e-4);
            EXPECT_NEAR(double(valley - w.left.begin() - long(on)) / (stance * fs), 0.5, 0.01);
            auto push = maxIn(0.6, 0.9);
            EXPECT_NEAR(*push / bw, sh.pushOffPeakBw, 1e-4);
            EXPECT_NEAR(double(push - w.left.begin() - long(on)) / (stance * fs), 0.75, 0.01);
        }
        // Literature ranges (Perry & Burnfield; Keller et al. 1996).
        EXPECT_GE(sh.heelPeakBw, 1.05);
        EXPECT_LE(sh.heelPeakBw, 1.35);
        EXPECT_GE(sh.valleyBw, 0.65) << cadence;
        EXPECT_LE(sh.valleyBw, 0.82) << cadence;
        EXPECT_GE(sh.pushOffPeakBw, 1.05);
        EXPECT_LE(sh.pushOffPeakBw, 1.2);
        // The right foot strikes half a stride after the left: double support ~ (duty - 0.5).
        const auto rs = contacts(w.right);
        const auto nextRight = std::find_if(rs.begin(), rs.end(),
                                            [&](const Contact& r) { return r.on > steps[1].on; });
        ASSERT_NE(nextRight, rs.end());
        EXPECT_NEAR(double(nextRight->on - steps[1].on) / fs, stride / 2, 2.0 / fs);
        std::size_t both = 0;
        for (std::size_t i = 0; i < w.left.size(); ++i) both += (w.left[i] > 0 && w.right[i] > 0);
        EXPECT_NEAR(double(both) / double(w.left.size()),
                    2 * (VirtualWalker::dutyFactor(cadence) - 0.5), 0.01);
    }
    // Stance shortens with cadence; about 60 % of the cycle at normal cadence.
    EXPECT_GT(VirtualWalker::dutyFactor(80), VirtualWalker::dutyFactor(120));
    EXPECT_NEAR(VirtualWalker::dutyFactor(110), 0.60, 1e-12);
}

TEST(VirtualWalker, ForceBalanceOverStridesEqualsBodyWeight) {
    // Mean vertical GRF of both feet over whole strides = m g (vertical momentum balance).
    for (double cadence : {60.0, 90.0, 110.0, 150.0}) {
        for (double shoe : {0.0, 1.0}) {
            WalkerParameters p;
            p.cadenceStepsPerMin = cadence;
            p.shoeHardness = shoe;
            p.variability = 0;
            p.massKg = 65;
            const double fs = 44100, stride = 120.0 / cadence;
            const int strides = 8;
            const Walk w = walk(p, stride * strides, fs);
            double sum = 0;
            for (std::size_t i = 0; i < w.left.size(); ++i) sum += double(w.left[i]) + w.right[i];
            const double meanN = sum / double(w.left.size());
            EXPECT_NEAR(meanN / (65 * kGravity), 1.0, 0.002) << cadence << " shoe " << shoe;
        }
    }
    // With 5 % step variability the balance holds per step, so on average too.
    WalkerParameters p;
    p.variability = 0.05;
    const Walk w = walk(p, 60, 48000, 3);
    double sum = 0;
    for (std::size_t i = 0; i < w.left.size(); ++i) sum += double(w.left[i]) + w.right[i];
    EXPECT_NEAR(sum / double(w.left.size()) / (70 * kGravity), 1.0, 0.02);
}

TEST(VirtualWalker, HardShoesGiveSharperLargerHeelTransient) {
    auto transient = [](double shoe) {
        WalkerParameters p;
        p.shoeHardness = shoe;
        p.variability = 0;
        const double fs = 48000;
        const Walk w = walk(p, 2, fs);
        const auto c = contacts(w.left);
        // Maximum of the force slope in the first 40 ms after contact (N per ms), and the
        // overshoot of the transient over the smooth curve at its peak.
        double maxSlope = 0;
        for (std::size_t i = c[0].on + 1; i < c[0].on + 40 * 48; ++i)
            maxSlope = std::max(maxSlope, double(w.left[i] - w.left[i - 1]) * 48.0);
        return maxSlope;
    };
    const double soft = transient(0.0), mid = transient(0.5), hard = transient(1.0);
    EXPECT_GT(mid, 1.5 * soft);
    EXPECT_GT(hard, 1.5 * mid);
    WalkerParameters soft0, hard1;
    soft0.shoeHardness = 0, hard1.shoeHardness = 1;
    const auto s = VirtualWalker::shapeFor(soft0, 0.6), h = VirtualWalker::shapeFor(hard1, 0.6);
    EXPECT_GT(h.transientBw, 4 * s.transientBw);
    EXPECT_LT(h.transientSeconds, s.transientSeconds / 2);
    // The hard-shoe transient is a local maximum (a visible spike) before the heel peak.
    bool localMax = false;
    for (double x = 0.001; x < 0.1; x += 0.0005)
        if (h.forceBw(x) > h.forceBw(x - 0.0005) && h.forceBw(x) > h.forceBw(x + 0.0005))
            localMax = true;
    EXPECT_TRUE(localMax);
}

TEST(VirtualWalker, DeterministicForASeedAndIndependentOfBlockSize) {
    WalkerParameters p;
    p.variability = 0.08;
    const Walk a = walk(p, 5, 48000, 42, 64);
    const Walk b = walk(p, 5, 48000, 42, 1000);
    EXPECT_EQ(a.left, b.left);
    EXPECT_EQ(a.right, b.right);
    const Walk c = walk(p, 5, 48000, 43, 64);
    EXPECT_NE(a.left, c.left);
    // reset() restarts the same sequence.
    VirtualWalker w(p);
    w.prepare({48000, 512});
    w.reset(42);
    std::vector<float> l(48000), r(48000);
    w.process(l.data(), r.data(), 48000);
    w.reset(42);
    std::vector<float> l2(48000), r2(48000);
    w.process(l2.data(), r2.data(), 48000);
    EXPECT_EQ(l, l2);
    EXPECT_EQ(std::vector<float>(a.left.begin(), a.left.begin() + 48000), l);
}

TEST(VirtualWalker, FiniteAndBoundedOverTheDocumentedRanges) {
    for (double mass : {20.0, 200.0})
        for (double cadence : {60.0, 150.0})
            for (double shoe : {0.0, 1.0})
                for (double var : {0.0, 0.2})
                    for (double fs : {22050.0, 192000.0}) {
                        WalkerParameters p{mass, cadence, shoe, var};
                        const Walk w = walk(p, 6, fs, 11);
                        const double bw = mass * kGravity;
                        float peak = 0;
                        for (std::size_t i = 0; i < w.left.size(); ++i) {
                            ASSERT_TRUE(std::isfinite(w.left[i]) && std::isfinite(w.right[i]));
                            ASSERT_GE(w.left[i], 0.0f);
                            ASSERT_GE(w.right[i], 0.0f);
                            peak = std::max({peak, w.left[i], w.right[i]});
                        }
                        EXPECT_GT(peak, 0.9 * bw);
                        EXPECT_LT(peak, 2.0 * bw) << mass << " " << cadence << " " << shoe;
                    }
}

TEST(VirtualWalker, ParserReadsSpecsAndReportsErrors) {
    const auto p = WalkerParameters::parse("cadence=100,mass=70,shoe=0.5,variability=0.03");
    EXPECT_EQ(p.cadenceStepsPerMin, 100);
    EXPECT_EQ(p.massKg, 70);
    EXPECT_EQ(p.shoeHardness, 0.5);
    EXPECT_EQ(p.variability, 0.03);
    const auto q = WalkerParameters::parse(" mass = 90 ");
    EXPECT_EQ(q.massKg, 90);
    EXPECT_EQ(q.cadenceStepsPerMin, WalkerParameters{}.cadenceStepsPerMin);
    EXPECT_EQ(WalkerParameters::parse(p.toString()).variability, 0.03);

    auto message = [](const std::string& spec) {
        try {
            WalkerParameters::parse(spec);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    EXPECT_NE(message("").find("empty"), std::string::npos);
    EXPECT_NE(message("cadence=100,speed=3").find("unknown key \"speed\""), std::string::npos);
    EXPECT_NE(message("cadence=100,speed=3").find("column 13"), std::string::npos);
    EXPECT_NE(message("cadence").find("expected key=value"), std::string::npos);
    EXPECT_NE(message("cadence=fast").find("expected a finite number"), std::string::npos);
    EXPECT_NE(message("cadence=100x").find("expected a finite number"), std::string::npos);
    EXPECT_NE(message("mass=nan").find("finite"), std::string::npos);
    EXPECT_NE(message("mass=inf").find("finite"), std::string::npos);
    EXPECT_NE(message("cadence=300").find("[60, 150]"), std::string::npos);
    EXPECT_NE(message("shoe=-0.1").find("shoe"), std::string::npos);
    EXPECT_NE(message("variability=0.5").find("variability"), std::string::npos);
    EXPECT_NE(message("mass=70,mass=80").find("twice"), std::string::npos);
    EXPECT_NE(message("mass=70,").find("expected key=value"), std::string::npos);
    EXPECT_THROW(VirtualWalker(WalkerParameters{10, 100, 0.5, 0}), std::invalid_argument);
}

TEST(VirtualWalker, JitteredStancesKeepForceBalanceAndAPlausibleShape) {
    // Worst cases of the documented range: shape jitter of variability 0.2 / 2 clamped at
    // 2 sigma = +-20 %.
    for (double cadence : {60.0, 100.0, 150.0})
        for (double h : {-0.2, 0.0, 0.2})
            for (double v : {-0.2, 0.0, 0.2})
                for (double pu : {-0.2, 0.0, 0.2}) {
                    WalkerParameters p;
                    p.cadenceStepsPerMin = cadence;
                    const double step = 60.0 / cadence;
                    const StanceShape sh = VirtualWalker::shapeFor(p, step, {h, v, pu});
                    // Balance: mean force over the stance = step / stance body weights.
                    double sum = 0;
                    const int n = 200000;
                    for (int i = 0; i < n; ++i) sum += sh.forceBw((i + 0.5) / n);
                    EXPECT_NEAR(sum / n, step / sh.stanceSeconds, 1e-4)
                        << cadence << " " << h << " " << v << " " << pu;
                    // A double hump: the valley is below both peaks, not below 35 % of either.
                    EXPECT_LE(sh.valleyBw, 0.9 * std::min(sh.heelPeakBw, sh.pushOffPeakBw) + 1e-12);
                    EXPECT_GE(sh.valleyBw,
                              0.35 * std::max(sh.heelPeakBw, sh.pushOffPeakBw) - 1e-12);
                    EXPECT_GT(sh.valleyBw, 0.3);
                    EXPECT_LT(std::max(sh.heelPeakBw, sh.pushOffPeakBw), 2.0);
                }
    // At the default 3 % (1.5 % on the shape) the valley of every step stays within 0.6-0.9 BW.
    WalkerParameters p;
    VirtualWalker w(p);
    w.prepare({48000, 512});
    w.reset(1);
    Random r(3);
    for (int i = 0; i < 1000; ++i) {
        const StanceJitter j{0.015 * r.gaussian(), 0.015 * r.gaussian(), 0.015 * r.gaussian()};
        const StanceShape sh = VirtualWalker::shapeFor(p, 0.6, j);
        ASSERT_GT(sh.valleyBw, 0.6);
        ASSERT_LT(sh.valleyBw, 0.9);
    }
}

TEST(VirtualWalker, TenMinutesWithoutDrift) {
    // Minute 1 and minute 10 of a walk: same mean force (= body weight), same step count, same
    // peak range (the step clock is a double sample position: no accumulated rounding).
    WalkerParameters p; // default 3 % variability
    VirtualWalker w(p);
    w.prepare({48000, 4096});
    w.reset(9);
    const std::size_t minute = 48000 * 60;
    std::vector<float> l(minute), r(minute);
    struct Stats {
        double mean = 0;
        int steps = 0;
    };
    auto run = [&] {
        w.process(l.data(), r.data(), static_cast<int>(minute));
        Stats s;
        bool on = false;
        for (std::size_t i = 0; i < minute; ++i) {
            s.mean += double(l[i]) + r[i];
            if (!on && l[i] > 0)
                on = true, ++s.steps;
            else if (on && l[i] <= 0)
                on = false;
        }
        s.mean /= double(minute);
        return s;
    };
    const Stats first = run();
    for (int m = 1; m < 9; ++m) run();
    const Stats last = run();
    const double bw = 70 * kGravity;
    EXPECT_NEAR(first.mean / bw, 1.0, 0.002);
    EXPECT_NEAR(last.mean / bw, 1.0, 0.002);
    EXPECT_NEAR(first.steps, 50, 1); // 100 steps/min = 50 left steps per minute
    EXPECT_NEAR(last.steps, 50, 1);
}
