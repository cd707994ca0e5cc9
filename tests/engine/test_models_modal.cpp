// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/ModalResonator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {
// Velocity response of one mode to a unit impulse of force (1 N s) at its pickup with gain 1.
std::vector<double> impulseResponse(const Mode& mode, double fs, int n) {
    ModalResonator r;
    r.configure({mode}, {{1.0}});
    r.prepare(fs);
    std::vector<double> y(static_cast<std::size_t>(n));
    // A force of fs newtons held (linearly) around one sample carries an impulse of ~1 N s.
    for (int i = 0; i < n; ++i)
        y[static_cast<std::size_t>(i)] = r.processSample(0, i == 0 ? fs : 0.0, 0);
    return y;
}

// Decay time measured between two one-period windows an exact number of periods apart (the
// period is a whole number of samples): for a decaying sinusoid A exp(-s t) sin(w t + phi) every
// sample pair then has the same phase, so the level ratio is exactly exp(s * distance).
double measuredT60(const std::vector<double>& y, double fs, std::size_t periodSamples) {
    auto sumAbs = [&](std::size_t start) {
        double e = 0;
        for (std::size_t i = start; i < start + periodSamples; ++i) e += std::fabs(y[i]);
        return e;
    };
    const std::size_t a = periodSamples;
    const std::size_t k = (y.size() - 2 * periodSamples) / periodSamples;
    const std::size_t b = a + k * periodSamples;
    const double dbPerSample = 20 * std::log10(sumAbs(a) / sumAbs(b)) / double(b - a);
    return 60.0 / dbPerSample / fs;
}
} // namespace

TEST(ModalResonator, MeasuredDecayMatchesTheSetT60AcrossTheRange) {
    for (const double fs : {22050.0, 48000.0, 192000.0}) {
        for (const double t60 : {0.001, 0.01, 0.3, 3.0, 30.0}) {
            const double f = fs / 40.0; // a period of exactly 40 samples
            const int n = static_cast<int>(std::min(t60 * 0.9, 2.0) * fs);
            const auto y = impulseResponse({f, t60, 0.1}, fs, n);
            if (n >= 160) { // at least four periods to measure (not the 1 ms decay at 22.05 kHz)
                EXPECT_NEAR(measuredT60(y, fs, 40) / t60, 1.0, 1e-6) << fs << " " << t60;
            }
            for (double v : y) ASSERT_TRUE(std::isfinite(v));
        }
    }
}

TEST(ModalResonator, ImpulseResponseMatchesTheAnalyticModeExactly) {
    // v(t) for q'' + 2 s q' + w0^2 q = delta(t)/m : exp(-s t) (cos wd t - s/wd sin wd t) / m.
    const double fs = 48000.0, f = 3000.0, t60 = 0.2, m = 0.5;
    ModalResonator r;
    r.configure({{f, t60, m}}, {{1.0}});
    r.prepare(fs);
    const double s = std::log(1000.0) / t60, wd = kTwoPi * f;
    // Drive with a short linear force ramp that is exactly representable by the hold: a triangle
    // of area 1 N s over 2 samples; after it, the free response is the analytic one delayed.
    const double T = 1.0 / fs;
    std::vector<double> forces = {0.0, fs, 0.0};
    double v = 0;
    for (double F : forces) v = r.processSample(0, F, 0);
    (void)v;
    for (int i = 3; i < 200; ++i) {
        v = r.processSample(0, 0.0, 0);
        // Convolution of the impulse response with a unit-area triangle centred at t = T.
        const double t = i * T;
        double expected = 0;
        const int sub = 2000;
        for (int k = 0; k < sub; ++k) {
            const double tau = 2.0 * T * (k + 0.5) / sub;
            const double w = (tau < T ? tau : 2 * T - tau) / (T * T);
            const double tt = t - tau;
            expected += w * std::exp(-s * tt) * (std::cos(wd * tt) - s / wd * std::sin(wd * tt)) /
                        m * (2.0 * T / sub);
        }
        ASSERT_NEAR(v, expected, 2e-6 * std::fabs(1.0 / m)) << i;
    }
}

TEST(ModalResonator, ModesAtAndBeyondNyquistBecomeQuasiStaticComplianceNotDropped) {
    const double fs = 48000.0;
    ModalResonator r;
    r.configure({{1000.0, 0.5, 1.0}, {30000.0, 0.5, 1.0}, {24000.0, 0.5, 1.0}}, {{1.0, 1.0, 1.0}});
    r.prepare(fs);
    EXPECT_EQ(r.quasiStaticModeCount(), 2);
    // A slow constant force deflects the quasi-static modes by F / (m w0^2).
    for (int i = 0; i < 48000; ++i) {
        r.predict();
        r.commit(0, 1.0);
    }
    const double s = std::log(1000.0) / 0.5;
    const double expected = 1.0 / (std::pow(kTwoPi * 1000.0, 2) + s * s) +
                            1.0 / (std::pow(kTwoPi * 30000.0, 2) + s * s) +
                            1.0 / (std::pow(kTwoPi * 24000.0, 2) + s * s);
    EXPECT_NEAR(r.position(0) / expected, 1.0, 1e-3);
    // At 4x the rate the same modes ring again.
    r.prepare(4 * fs);
    EXPECT_EQ(r.quasiStaticModeCount(), 0);
}

TEST(ModalResonator, FreeVibrationNeverGainsEnergy) {
    ModalResonator r;
    r.configure({{120.0, 0.05, 2.0}, {800.0, 2.0, 0.1}, {23999.0, 30.0, 0.01}}, {{1.0, -0.7, 0.3}});
    r.prepare(48000.0);
    // The held force ramps down during the sample after it: check from the second sample on.
    r.processSample(0, 1000.0, 0);
    r.processSample(0, 0.0, 0);
    double last = r.energy();
    for (int i = 0; i < 48000; ++i) {
        r.processSample(0, 0.0, 0);
        const double e = r.energy();
        ASSERT_LE(e, last * (1.0 + 1e-12) + 1e-300) << i;
        last = e;
    }
}

TEST(ModalResonator, RejectsNonPhysicalModes) {
    ModalResonator r;
    EXPECT_THROW(r.configure({{-1.0, 0.5, 1.0}}, {}), std::invalid_argument);
    EXPECT_THROW(r.configure({{100.0, 0.0, 1.0}}, {}), std::invalid_argument);
    EXPECT_THROW(r.configure({{100.0, 0.5, NAN}}, {}), std::invalid_argument);
    EXPECT_THROW(r.configure({{100.0, 0.5, 1.0}}, {{1.0, 2.0}}), std::invalid_argument);
}

namespace {
// A bank of `n` modes (one above Nyquist: quasi-static) seen through two pickups; pickup 1 has
// pickup 0's gains, so its sums (computed mode by mode) check pickup 0's (computed in O(1)).
template <typename Real>
void configureBank(ModalResonatorT<Real>& r, int n) {
    std::vector<Mode> modes;
    std::vector<double> g;
    for (int i = 0; i < n; ++i) {
        const double f = i == n - 1 ? 30000.0 : 150.0 * std::pow(1.9, i);
        modes.push_back({f, 0.3 / (1 + i), 0.5 + 0.3 * i});
        g.push_back(1.0 - 0.05 * i);
    }
    r.configure(modes, {g, g});
    r.prepare(48000.0, 8);
}
} // namespace

// commit() updates the pickup sums as prediction + force x instantaneous response,
// and with energy tracking energy()/energyIfCommitted() come from a quadratic in the force;
// both must agree with the sums over the modes, for odd and even mode counts (the bank is padded
// to a multiple of four modes), at both rates and in float as in double.
template <typename Real>
void checkO1SumsAgainstModeSums(double tolerance) {
    for (int n : {1, 2, 3, 5, 14}) {
        ModalResonatorT<Real> tracked, plain;
        configureBank(tracked, n);
        configureBank(plain, n);
        tracked.setEnergyTracking(true);
        tracked.setOutputPickup(0);
        double maxRel = 0;
        for (int i = 0; i < 2000; ++i) {
            const bool fine = (i / 7) % 3 == 0;
            tracked.setFineRate(fine);
            plain.setFineRate(fine);
            // A force that rises, holds, releases and is zero for a while (free ringing).
            const double f = (i % 400) < 300 ? 50.0 * std::sin(0.01 * i) + 60.0 : 0.0;
            tracked.predict();
            plain.predict();
            const double e = tracked.energyIfCommitted(0, f);
            const double eRef = plain.energyIfCommitted(1, f); // the sum over the modes
            tracked.commit(0, f);
            plain.commit(0, f);
            auto rel = [](double a, double b) {
                return std::fabs(a - b) / std::max({std::fabs(a), std::fabs(b), 1e-30});
            };
            const double scaleX = std::fabs(tracked.position(1)) + 1e-12;
            const double scaleV = std::fabs(tracked.velocity(1)) + 1e-9;
            maxRel = std::max(maxRel, rel(e, eRef));
            maxRel =
                std::max(maxRel, std::fabs(tracked.position(0) - tracked.position(1)) / scaleX);
            maxRel =
                std::max(maxRel, std::fabs(tracked.velocity(0) - tracked.velocity(1)) / scaleV);
            maxRel = std::max(maxRel, rel(tracked.energy(), plain.energy()));
            ASSERT_EQ(tracked.energy() >= 0.0, true);
            if (i % 64 == 63) {
                tracked.flushTinyState();
                plain.flushTinyState();
            }
        }
        EXPECT_LT(maxRel, tolerance) << n << " modes";
    }
}

TEST(ModalResonatorFastPath, ConstantTimeSumsAndEnergiesEqualTheSumsOverTheModes) {
    checkO1SumsAgainstModeSums<double>(1e-9);
    checkO1SumsAgainstModeSums<float>(1e-4);
}

// commit() defers its per-mode update into the next predict(); every reader of the
// modes (another pickup's position or velocity, energy, flushing, the peak velocity) completes it
// first. A bank read through pickup 1 after every commit (so the update happens in commit's
// sample) and a bank never read (so it happens inside the next predict) give the same samples,
// bit for bit, through force changes, free ringing and rate switches.
TEST(ModalResonatorFastPath, DeferredCommitEqualsTheImmediateUpdate) {
    for (int n : {1, 3, 5, 14}) {
        ModalResonator read, unread;
        configureBank(read, n);
        configureBank(unread, n);
        read.setEnergyTracking(true);
        unread.setEnergyTracking(true);
        for (int i = 0; i < 3000; ++i) {
            const bool fine = (i / 11) % 4 == 0;
            read.setFineRate(fine);
            unread.setFineRate(fine);
            const double f = (i % 500) < 350 ? 40.0 * std::sin(0.013 * i) + 45.0 : 0.0;
            const double held = (i % 97) == 5 ? 0.5 : 1.0; // the passivity guard's held scale
            read.predict(held);
            unread.predict(held);
            read.commit(0, f);
            unread.commit(0, f);
            (void)read.position(1);
            (void)read.velocity(1);
            ASSERT_EQ(read.contactVelocity(), unread.contactVelocity()) << n << " modes, " << i;
            ASSERT_EQ(read.velocity(0), unread.velocity(0)) << n << " modes, " << i;
            ASSERT_EQ(read.position(0), unread.position(0)) << n << " modes, " << i;
            if (i % 64 == 63) {
                read.flushTinyState();
                unread.flushTinyState();
            }
        }
        EXPECT_EQ(read.position(1), unread.position(1));
        EXPECT_EQ(read.energy(), unread.energy());
        EXPECT_EQ(read.peakModalVelocity(), unread.peakModalVelocity());
    }
}

// the per-mode loops run four modes per step, as one AVX vector where the CPU has it
// or as two SSE2 pairs. Both kernels must give the same samples bit for bit (a replay on another
// machine depends on it), for mode counts below, at and across multiples of four, through force
// changes, held-force scales, free ringing and rate switches, with and without energy tracking.
TEST(ModalResonatorFastPath, AvxAndSse2KernelsGiveTheSameSamples) {
    for (const bool tracking : {true, false})
        for (int n : {1, 3, 4, 5, 8, 12, 14}) {
            ModalResonator avx, sse2;
            configureBank(avx, n);
            configureBank(sse2, n);
            sse2.allowAvx(false);
            EXPECT_FALSE(sse2.usesAvx());
            avx.setEnergyTracking(tracking);
            sse2.setEnergyTracking(tracking);
            for (int i = 0; i < 3000; ++i) {
                const bool fine = (i / 11) % 4 == 0;
                avx.setFineRate(fine);
                sse2.setFineRate(fine);
                const double f = (i % 500) < 350 ? 40.0 * std::sin(0.013 * i) + 45.0 : 0.0;
                const double held = (i % 97) == 5 ? 0.5 : (i % 89) == 7 ? 0.0 : 1.0;
                avx.predict(held);
                sse2.predict(held);
                ASSERT_EQ(avx.predictedPosition(0), sse2.predictedPosition(0)) << n << ", " << i;
                ASSERT_EQ(avx.energyIfCommitted(0, f), sse2.energyIfCommitted(0, f))
                    << n << ", " << i;
                avx.commit(0, f);
                sse2.commit(0, f);
                ASSERT_EQ(avx.contactVelocity(), sse2.contactVelocity()) << n << ", " << i;
                ASSERT_EQ(avx.velocity(0), sse2.velocity(0)) << n << ", " << i;
                ASSERT_EQ(avx.energy(), sse2.energy()) << n << ", " << i;
                if (i % 64 == 63) {
                    avx.flushTinyState();
                    sse2.flushTinyState();
                }
            }
            EXPECT_EQ(avx.position(1), sse2.position(1)) << n;
            EXPECT_EQ(avx.velocity(1), sse2.velocity(1)) << n;
            EXPECT_EQ(avx.peakModalVelocity(), sse2.peakModalVelocity()) << n;
        }
    ModalResonator probe;
    configureBank(probe, 3);
    RecordProperty("avx_kernel_used", probe.usesAvx() ? "yes" : "no (this CPU has no AVX)");
}

// ringFreeUntilContact runs free ringing sample by sample while a body at soleX[t]
// stays clear of the contact point, and must stop exactly where predict() / commit(0, 0) pairs
// would first find soleX[t] - predictedPosition(0) > 0, with the same samples and state, in both
// kernels (AVX and SSE2), for mode counts below, at and across multiples of four; runs of any
// length, a body that never touches, and one that would touch at once.
TEST(ModalResonatorFastPath, RingingUntilContactStopsWhereTheSampleBySampleTestDoes) {
    for (const bool avx : {true, false})
        for (int n : {1, 3, 4, 5, 12, 14}) {
            ModalResonator run, ref;
            configureBank(run, n);
            configureBank(ref, n);
            run.allowAvx(avx);
            ref.allowAvx(avx);
            for (auto* r : {&run, &ref}) { // ring: a force, then none
                for (int i = 0; i < 40; ++i) {
                    r->predict();
                    r->commit(0, i < 20 ? 30.0 : 0.0);
                }
            }
            ASSERT_TRUE(run.ringsFree());
            // (one mode is quasi-static here, at rest without a force: a bound of 0)
            const double a = std::max(1e-9, 1.2 * run.freeContactBound());
            int total = 0, stops = 0, laterStops = 0;
            for (int call = 0; call < 60; ++call) {
                // a body that swings about the contact point's range (and sometimes far away)
                double sole[ModalResonator::kFreeRunMax];
                const int len = 1 + (call * 7) % ModalResonator::kFreeRunMax;
                for (int t = 0; t < len; ++t)
                    sole[t] = call % 5 == 4
                                  ? -10.0 * a
                                  : a * std::sin(0.05 * (total + t) + 0.3 * call) - 0.6 * a;
                double vo[ModalResonator::kFreeRunMax];
                const int k = run.ringFreeUntilContact(len, sole, vo);
                ASSERT_GE(k, 0);
                ASSERT_LE(k, len);
                // the reference: sample by sample, stopping where the test finds contact
                int expected = 0;
                for (; expected < len; ++expected) {
                    ref.predict();
                    if (!(sole[expected] - ref.predictedPosition(0) <= 0.0)) break;
                    ref.commit(0, 0.0);
                    ASSERT_EQ(vo[expected], ref.velocity(ref.outputPickup())) << n << " " << call;
                }
                ASSERT_EQ(k, expected) << n << " " << call;
                if (k < len) {
                    ++stops;
                    // (a touch after a whole chunk ran: the chunk with the touch is not committed)
                    if (k >= ModalResonator::kTestedChunk) ++laterStops;
                    // the reference predicted the touching sample: step it with no force, as the
                    // caller's contact step would with a force, then both go on alike
                    ref.commit(0, 0.0);
                    run.predict();
                    run.commit(0, 0.0);
                }
                EXPECT_EQ(run.contactVelocity(), ref.contactVelocity()) << n << " " << call;
                EXPECT_EQ(run.position(0), ref.position(0)) << n << " " << call;
                EXPECT_EQ(run.velocity(1), ref.velocity(1)) << n << " " << call;
                EXPECT_EQ(run.energy(), ref.energy()) << n << " " << call;
                total += k;
            }
            EXPECT_GT(stops, 5) << n;      // the test did stop runs
            EXPECT_GT(laterStops, 0) << n; // also in a later chunk than the first
            EXPECT_GT(total, 200) << n;    // and ran samples
        }
}
