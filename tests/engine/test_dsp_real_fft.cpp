// SPDX-License-Identifier: GPL-3.0-or-later
// RealFft: FFTW plans made and destroyed under one lock, so analysis can run on several worker
// threads at once (the console computes descriptors and costs off the UI thread).
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/RealFft.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

using underfoot::engine::RealFft;

namespace {
using underfoot::engine::kPi;

/// Magnitude of bin k of a unit cosine at bin k (n / 2) and the round trip error.
void transformCosine(int n, int k, double& peak, double& roundTrip) {
    RealFft fft(n);
    for (int i = 0; i < n; ++i) fft.time()[i] = std::cos(2 * kPi * k * i / n);
    fft.forward();
    peak = std::hypot(fft.spectrum()[k][0], fft.spectrum()[k][1]);
    fft.inverse();
    roundTrip = 0;
    for (int i = 0; i < n; ++i)
        roundTrip =
            std::max(roundTrip, std::abs(fft.time()[i] / n - std::cos(2 * kPi * k * i / n)));
}
} // namespace

TEST(RealFft, CosineLandsInItsBinAndRoundTrips) {
    double peak = 0, err = 1;
    transformCosine(512, 17, peak, err);
    EXPECT_NEAR(peak, 256.0, 1e-9);
    EXPECT_LT(err, 1e-12);
    EXPECT_THROW(RealFft(1), std::bad_alloc);
}

TEST(RealFft, PlansFromManyThreadsAtOnceGiveTheSameAnswers) {
    std::atomic<int> wrong{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([t, &wrong] {
            for (int r = 0; r < 40; ++r) {
                const int n = 64 << ((t + r) % 6); // sizes 64 .. 2048: new plans all the time
                double peak = 0, err = 1;
                transformCosine(n, 5, peak, err);
                if (std::abs(peak - n / 2.0) > 1e-9 * n || err > 1e-10) ++wrong;
            }
        });
    for (auto& th : threads) th.join();
    EXPECT_EQ(wrong.load(), 0);
}
