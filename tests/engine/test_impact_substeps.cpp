// SPDX-License-Identifier: GPL-3.0-or-later
// Impact with contact sub-steps (the shipped default): the samples in contact are
// computed as ImpactParams::contactSubsteps exact sub-steps, free flight as single steps.
// Accuracy against the 8x oversampled reference, the stability matrix, passivity, determinism,
// block-size independence and no allocation on the audio path.
#include "engine/models/Impact.h"
#include "engine/render/AccuracyCost.h"
#include "tests/common/AllocationTrap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

// The benchmark's impact (AccuracyCost.h): 0.1 kg sole, k = 2e9, alpha 1.5, mu 0.6, 3 modes.
ImpactParams benchImpact(int substeps, int oversampling = 1, int iterations = 6) {
    ImpactParams p;
    p.stiffness = 2e9;
    p.alpha = 1.5;
    p.dissipation = 0.6;
    p.exciterMassKg = 0.1;
    p.newtonIterations = iterations;
    p.oversampling = oversampling;
    p.contactSubsteps = substeps;
    return p;
}

const std::vector<Mode> kModes = {{180.0, 0.15, 2.0}, {620.0, 0.08, 0.8}, {1900.0, 0.04, 0.5}};

struct Strike {
    std::vector<float> out;
    double restitution = 0, contactTime = 0;
};

Strike strike(const ImpactParams& p, int block = 64, double seconds = 0.25) {
    HuntCrossleyImpact impact;
    impact.configure(p, kModes, {{1.0, 1.0, 1.0}});
    impact.prepare({kFs, 64});
    impact.strike(0.5);
    Strike s;
    s.out.assign(static_cast<std::size_t>(seconds * kFs), 0.0f);
    for (std::size_t i = 0; i < s.out.size(); i += static_cast<std::size_t>(block))
        impact.process(nullptr, s.out.data() + i,
                       static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(block),
                                                              s.out.size() - i)));
    s.restitution = -impact.stats().outgoingVelocity / impact.stats().incomingVelocity;
    s.contactTime = impact.stats().contactTimeSeconds;
    return s;
}
} // namespace

TEST(ImpactContactSubsteps, DefaultIsSubsteppedAndMatchesTheReferenceRestitution) {
    EXPECT_EQ(ImpactParams{}.contactSubsteps, 4);
    const Strike ref = strike(benchImpact(1, 8, 50)); // the bench's 8x oversampled reference
    const Strike def = strike(ImpactParams{benchImpact(ImpactParams{}.contactSubsteps)});
    const Strike old = strike(benchImpact(1)); // the single-step solver (the old default)
    ASSERT_GT(ref.restitution, 0.5);
    EXPECT_NEAR(def.restitution, ref.restitution, 0.01 * ref.restitution);
    // The sub-steps are what brings it there: the single step is several percent off.
    EXPECT_GT(std::fabs(old.restitution - ref.restitution), 0.03 * ref.restitution);
    EXPECT_NEAR(def.contactTime, ref.contactTime, 0.01 * ref.contactTime);
    EXPECT_LE(spectralDistanceDb(def.out, ref.out, kFs), 0.1);
    EXPECT_GT(spectralDistanceDb(old.out, ref.out, kFs), 0.3);
}

TEST(ImpactContactSubsteps, MoreSubstepsConvergeTowardsTheReference) {
    const Strike ref = strike(benchImpact(1, 8, 50));
    double previous = 1e9;
    for (int sub : {1, 2, 4, 8}) {
        const double err = std::fabs(strike(benchImpact(sub)).restitution - ref.restitution);
        EXPECT_LT(err, previous) << sub;
        previous = err;
    }
}

TEST(ImpactContactSubsteps, BlockSizeIndependentAndDeterministic) {
    const Strike a = strike(benchImpact(8), 64);
    const Strike b = strike(benchImpact(8), 1);
    const Strike c = strike(benchImpact(8), 37);
    const Strike d = strike(benchImpact(8), 64);
    ASSERT_EQ(a.out.size(), b.out.size());
    for (std::size_t i = 0; i < a.out.size(); ++i) {
        ASSERT_EQ(a.out[i], b.out[i]) << i;
        ASSERT_EQ(a.out[i], c.out[i]) << i;
        ASSERT_EQ(a.out[i], d.out[i]) << i;
    }
}

TEST(ImpactContactSubsteps, StabilityMatrixStaysFiniteAndPassive) {
    // Stiffness 1e5..1e11, alpha up to 3, up to 10 m/s, soles down to 1 mg, with and without
    // sub-steps, a pressing force and strikes: finite, the exciter never leaves faster than it came
    // and the total energy never exceeds what was put in.
    int cases = 0;
    for (int sub : {1, 4, 8, 16}) {
        for (double k : {1e5, 1e8, 1e11}) {
            for (double alpha : {1.0, 1.5, 3.0}) {
                for (double m : {1e-6, 1e-3, 1.0}) {
                    for (double v : {0.01, 10.0}) {
                        ImpactParams p;
                        p.stiffness = k;
                        p.alpha = alpha;
                        p.dissipation = 0.3;
                        p.exciterMassKg = m;
                        p.contactSubsteps = sub;
                        HuntCrossleyImpact impact;
                        impact.configure(
                            p, {{150.0, 0.3, 1.0}, {1200.0, 0.1, 0.3}, {30000.0, 0.02, 0.1}},
                            {{1.0, 1.0, 1.0}});
                        impact.prepare({kFs, 64});
                        impact.strike(v);
                        const double e0 = impact.totalEnergy();
                        std::vector<float> out(64);
                        bool ok = true;
                        for (int b = 0; b < 200 && ok; ++b) {
                            impact.process(nullptr, out.data(), 64);
                            for (float y : out) ok &= std::isfinite(y);
                            ok &= impact.totalEnergy() <= e0 * (1 + 1e-6);
                        }
                        EXPECT_TRUE(ok) << "sub=" << sub << " k=" << k << " a=" << alpha
                                        << " m=" << m << " v=" << v;
                        EXPECT_LE(std::fabs(impact.exciterVelocity()), v * (1 + 1e-6))
                            << "sub=" << sub << " k=" << k << " a=" << alpha << " m=" << m;
                        ++cases;
                    }
                }
            }
        }
    }
    EXPECT_EQ(cases, 216);
}

TEST(ImpactContactSubsteps, PressedSoleStaysFiniteAndDoesNotAllocate) {
    // A sole pressed on the floor (the contact never opens): every sample is sub-stepped.
    ImpactParams p = benchImpact(8);
    HuntCrossleyImpact impact;
    impact.configure(p, kModes, {{1.0, 1.0, 1.0}});
    impact.prepare({kFs, 64});
    impact.strike(0.5);
    std::vector<float> force(64, 300.0f), out(64);
    long allocations = 0;
    {
        underfoot::test::AllocationTrap trap;
        for (int b = 0; b < 750; ++b) impact.process(force.data(), out.data(), 64);
        allocations = trap.count();
    }
    EXPECT_EQ(allocations, 0);
    for (float y : out) EXPECT_TRUE(std::isfinite(y));
    // Static equilibrium: the contact force carries the pressing force.
    EXPECT_NEAR(impact.lastContactForce(), 300.0, 3.0);
    // Once the strike's transient has died out, the resting contact is single-stepped: far fewer
    // solved steps than 8 per sample.
    EXPECT_GE(impact.stats().solvedSamples, 750 * 64);
    EXPECT_LT(impact.stats().solvedSamples, 750 * 64 * 2);
}

TEST(ImpactContactSubsteps, PressedSoleMatchesTheFullySubsteppedSolution) {
    // The transient criterion (sub-step only while the force changes by more than
    // substepForceChange per sample) against sub-stepping every sample in contact.
    auto run = [](double threshold) {
        ImpactParams p = benchImpact(8);
        p.substepForceChange = threshold;
        HuntCrossleyImpact impact;
        impact.configure(p, kModes, {{1.0, 1.0, 1.0}});
        impact.prepare({kFs, 64});
        impact.strike(0.5);
        std::vector<float> force(64, 300.0f), out(12032);
        for (std::size_t i = 0; i < out.size(); i += 64)
            impact.process(force.data(), out.data() + i, 64);
        return out;
    };
    const auto all = run(0.0), shipped = run(ImpactParams{}.substepForceChange);
    EXPECT_LE(spectralDistanceDb(shipped, all, kFs), 0.1);
}

TEST(ImpactContactSubsteps, RejectsUnsupportedSubstepCounts) {
    for (int bad : {0, 3, 5, 32, -1}) {
        ImpactParams p;
        p.contactSubsteps = bad;
        HuntCrossleyImpact impact;
        EXPECT_THROW(impact.configure(p, kModes, {{1.0, 1.0, 1.0}}), std::invalid_argument) << bad;
    }
}

TEST(ModalResonatorFastPath, FreeRingingEqualsTheGeneralRecursion) {
    // predict()/commit() skip the force terms and swap buffers when no force acts;
    // the result must equal the general recursion s[n+1] = A s[n] + B0 u[n] + B1 u[n+1] computed
    // here independently, for a force that switches on and off (bit-exact up to rounding order,
    // which is the same: tolerance 1e-15 relative).
    const std::vector<Mode> modes = {{180.0, 0.15, 2.0}, {620.0, 0.08, 0.8}, {30000.0, 0.04, 0.5}};
    const std::vector<double> g = {1.0, -0.7, 0.4};
    ModalResonator r;
    r.configure(modes, {g});
    r.prepare(kFs);
    std::vector<ModeCoefficients> c;
    for (const auto& m : modes) c.push_back(computeModeCoefficients(m, kFs));
    std::vector<double> q(3, 0.0), v(3, 0.0), u(3, 0.0);
    for (int n = 0; n < 4000; ++n) {
        const double f = (n % 500 < 20) ? 10.0 * std::sin(0.3 * n) : 0.0;
        const double y = r.processSample(0, f, 0);
        double ref = 0.0;
        for (std::size_t i = 0; i < 3; ++i) {
            const double un = g[i] / modes[i].massKg * f;
            const double qn = c[i].a00 * q[i] + c[i].a01 * v[i] + c[i].b0x * u[i] + c[i].b1x * un;
            const double vn = c[i].a10 * q[i] + c[i].a11 * v[i] + c[i].b0v * u[i] + c[i].b1v * un;
            q[i] = qn;
            v[i] = vn;
            u[i] = un;
            if (!c[i].quasiStatic) ref += g[i] * vn;
        }
        ASSERT_NEAR(y, ref, 1e-15 * (1.0 + std::fabs(ref)) + 1e-300) << n;
    }
}

namespace {
// Ten modes (three quads, one of them part padding), one above Nyquist (quasi-static), and the
// gains of two pickups.
struct ManyModes {
    std::vector<Mode> modes;
    std::vector<double> g1, g2;
};
ManyModes manyModes() {
    ManyModes m;
    m.modes = {{83.6, 0.07, 6.0},  {120.8, 0.03, 6.0},  {203.3, 0.92, 2.5}, {238.8, 0.02, 2.5},
               {363.1, 0.04, 1.2}, {441.1, 0.035, 1.2}, {667.3, 0.03, 0.9}, {1130.0, 0.02, 0.5},
               {2650.0, 0.5, 0.3}, {30000.0, 0.01, 0.2}};
    m.g1.resize(m.modes.size());
    m.g2.resize(m.modes.size());
    for (std::size_t i = 0; i < m.modes.size(); ++i) {
        m.g1[i] = 1.0 - 0.15 * static_cast<double>(i);
        m.g2[i] = 0.5 + 0.1 * static_cast<double>(i % 3);
    }
    return m;
}

// Strikes of several strengths, a sole pushed back onto the floor by an external force after
// some of them (contacts that start from free flight), rendered in blocks of `block` samples.
// (substepLoop, avx: HuntCrossleyImpactT::allowSubstepLoop, allowAvx; velocityScale scales the
// strikes' velocities)
template <typename Real>
std::vector<float> strikesAndPushes(const ImpactParams& p, const std::vector<Mode>& modes,
                                    const std::vector<std::vector<double>>& gains, int listen,
                                    bool freeRuns, int block, ContactStats& stats, double& energy,
                                    bool substepLoop = true, bool avx = true,
                                    double velocityScale = 1.0) {
    HuntCrossleyImpactT<Real> impact;
    impact.configure(p, modes, gains, listen);
    impact.allowAvx(avx);
    impact.prepare({kFs, 64});
    impact.allowFreeRuns(freeRuns);
    impact.allowSubstepLoop(substepLoop);
    const int n = static_cast<int>(1.2 * kFs);
    std::vector<float> out(static_cast<std::size_t>(n), 0.0f), push(out.size(), 0.0f);
    for (int i = 0; i < n; ++i) { // 40 N pushes after the second and fourth strikes
        const int t = i % 12000;
        if ((i / 12000) % 2 == 1 && t > 3000 && t < 5000) push[static_cast<std::size_t>(i)] = 40.0f;
    }
    for (int start = 0; start < n; start += 2400) {
        // a strike every 50 ms, processed in blocks of `block` between them
        impact.strike(velocityScale * (0.1 + 0.15 * ((start / 2400) % 5)));
        for (int i = start; i < std::min(n, start + 2400); i += block) {
            const int k = std::min({block, n - i, start + 2400 - i});
            impact.process(push.data() + i, out.data() + i, k);
        }
    }
    stats = impact.stats();
    energy = impact.totalEnergy();
    return out;
}

template <typename Real>
void expectFreeRunsEqualSteps(const ImpactParams& p, const std::vector<Mode>& modes,
                              const std::vector<std::vector<double>>& gains, int listen) {
    ContactStats refStats;
    double refEnergy = 0.0;
    const auto ref = strikesAndPushes<Real>(p, modes, gains, listen, false, 1, refStats, refEnergy);
    double sum = 0.0;
    for (float v : ref) sum += std::fabs(v);
    ASSERT_GT(sum, 0.0);
    for (int block : {1, 64, 777}) {
        ContactStats stats;
        double energy = 0.0;
        const auto out =
            strikesAndPushes<Real>(p, modes, gains, listen, true, block, stats, energy);
        EXPECT_EQ(out, ref) << "block " << block << ", " << modes.size() << " modes, "
                            << p.contactSubsteps << " sub-steps";
        EXPECT_EQ(stats.contactTimeSeconds, refStats.contactTimeSeconds);
        EXPECT_EQ(stats.peakForceN, refStats.peakForceN);
        EXPECT_EQ(stats.incomingVelocity, refStats.incomingVelocity);
        EXPECT_EQ(stats.outgoingVelocity, refStats.outgoingVelocity);
        EXPECT_EQ(stats.solvedSamples, refStats.solvedSamples);
        EXPECT_EQ(energy, refEnergy);
        if (p.solver != ImpactSolver::Explicit) { // most of the walk is free flight, run at once
            EXPECT_GT(stats.freeRunSamples, static_cast<long long>(ref.size()) * 4 / 5);
            // the samples right after the contacts too, with the per-sample contact test
            EXPECT_GT(stats.testedRunSamples, 0);
        } else {
            EXPECT_EQ(stats.freeRunSamples, 0);
        }
    }
    EXPECT_EQ(refStats.freeRunSamples, 0);
    EXPECT_EQ(refStats.testedRunSamples, 0);
}
} // namespace

// Free flight runs at once over the samples where the sole cannot touch the ringing floor
// (HuntCrossleyImpactT::runFree, ModalResonatorT::ringFree, and right after a contact
// ModalResonatorT::ringFreeUntilContact). It must give exactly what stepping
// sample by sample gives: samples, statistics and energy, for any block size, with one quad of
// modes or several, a mode above Nyquist (quasi-static), two pickups, sub-steps or none, the
// explicit solver (never run at once), and float state.
TEST(ImpactFreeRuns, RunsGiveTheSampleBySampleSamples) {
    const ManyModes m = manyModes();
    const std::vector<Mode>& many = m.modes;
    const std::vector<std::vector<double>> gains = {m.g1, m.g2};
    for (int sub : {1, 4, 8}) {
        expectFreeRunsEqualSteps<double>(benchImpact(sub), kModes, {{1.0, 1.0, 1.0}}, 0);
        expectFreeRunsEqualSteps<double>(benchImpact(sub), many, gains, 1);
        expectFreeRunsEqualSteps<float>(benchImpact(sub), many, gains, 1);
    }
    ImpactParams explicitSolver = benchImpact(1);
    explicitSolver.solver = ImpactSolver::Explicit;
    expectFreeRunsEqualSteps<double>(explicitSolver, kModes, {{1.0, 1.0, 1.0}}, 0);
}

// A strike's first sample finds the sole on the floor, so its free-run try fails and the next
// samples would step without trying (HuntCrossleyImpactT::kFreeRetrySamples). That wait must not
// outlast the contact: once the sole leaves, the samples after it run free at once (right after a
// contact, the run tested sample by sample: a wood strike's block stepped eight more
// samples one by one).
TEST(ImpactFreeRuns, RunsStartRightAfterAContact) {
    HuntCrossleyImpact impact;
    impact.configure(benchImpact(4), kModes, {{1.0, 1.0, 1.0}});
    impact.prepare({kFs, 64});
    impact.strike(0.5);
    float y = 0.0f;
    int contactSamples = 0;
    while (contactSamples == 0 || impact.lastContactForce() > 0.0) { // up to the contact's end
        impact.process(nullptr, &y, 1);
        if (impact.lastContactForce() > 0.0) ++contactSamples;
        ASSERT_LT(contactSamples, 1000);
    }
    ASSERT_GT(contactSamples, 5);
    int stepped = 0; // samples after the contact stepped before a free run starts
    for (const long long before = impact.stats().freeRunSamples; stepped < 100; ++stepped) {
        impact.process(nullptr, &y, 1);
        if (impact.stats().freeRunSamples > before) break;
    }
    EXPECT_EQ(stepped, 0);
}

namespace {
// The loop of a sample's sub-steps against step() sub-step by sub-step (allowSubstepLoop):
// samples, every statistic and the energy; returns the passivity corrections of the runs.
template <typename Real>
long long expectSubstepLoopEqualsSteps(const ImpactParams& p, const std::vector<Mode>& modes,
                                       const std::vector<std::vector<double>>& gains, int listen,
                                       double velocityScale) {
    long long corrections = 0;
    for (bool avx : {true, false}) {
        ContactStats refStats, stats;
        double refEnergy = 0.0, energy = 0.0;
        const auto ref = strikesAndPushes<Real>(p, modes, gains, listen, true, 64, refStats,
                                                refEnergy, false, avx, velocityScale);
        const auto out = strikesAndPushes<Real>(p, modes, gains, listen, true, 64, stats, energy,
                                                true, avx, velocityScale);
        const auto where = ::testing::Message()
                           << (avx ? "AVX" : "SSE2") << ", " << p.contactSubsteps
                           << " sub-steps, k " << p.stiffness << ", sole " << p.exciterMassKg
                           << " kg, " << modes.size() << " modes";
        EXPECT_GT(refStats.solvedSamples, 0) << where;
        EXPECT_EQ(out, ref) << where;
        EXPECT_EQ(energy, refEnergy) << where;
        EXPECT_EQ(stats.contactTimeSeconds, refStats.contactTimeSeconds) << where;
        EXPECT_EQ(stats.peakForceN, refStats.peakForceN) << where;
        EXPECT_EQ(stats.incomingVelocity, refStats.incomingVelocity) << where;
        EXPECT_EQ(stats.outgoingVelocity, refStats.outgoingVelocity) << where;
        EXPECT_EQ(stats.solverIterations, refStats.solverIterations) << where;
        EXPECT_EQ(stats.solvedSamples, refStats.solvedSamples) << where;
        EXPECT_EQ(stats.maxIterationsInOneSample, refStats.maxIterationsInOneSample) << where;
        EXPECT_EQ(stats.passivityCorrections, refStats.passivityCorrections) << where;
        EXPECT_EQ(stats.freeRunSamples, refStats.freeRunSamples) << where;
        EXPECT_EQ(stats.testedRunSamples, refStats.testedRunSamples) << where;
        corrections += stats.passivityCorrections;
    }
    return corrections;
}
} // namespace

// A sample's contact sub-steps under the Hertz law run as one loop with the sole's state in
// registers and the resonator's pass and the Newton solve inline
// (HuntCrossleyImpactT::substepLoop). It must give exactly what step() sub-step by sub-step
// gives: the samples, every statistic (solver iterations and passivity corrections included) and
// the energy, with both kernels, in double and float state, with two pickups, and in contacts
// stiff, light and fast enough for the passivity guard to correct sub-steps (its bisection runs
// out of the loop, from the loop's state).
TEST(ImpactContactSubsteps, SubstepLoopGivesTheStepBySubstepSamples) {
    const ManyModes m = manyModes();
    const std::vector<Mode>& many = m.modes;
    const std::vector<std::vector<double>> gains = {m.g1, m.g2};
    for (int sub : {2, 4, 16}) {
        expectSubstepLoopEqualsSteps<double>(benchImpact(sub), kModes, {{1.0, 1.0, 1.0}}, 0, 1.0);
        expectSubstepLoopEqualsSteps<double>(benchImpact(sub), many, gains, 1, 1.0);
        expectSubstepLoopEqualsSteps<float>(benchImpact(sub), many, gains, 1, 1.0);
    }
    long long corrections = 0;
    for (double stiffness : {1e9, 1e11}) {
        for (double mass : {1e-6, 1e-4}) {
            ImpactParams hard = benchImpact(4);
            hard.stiffness = stiffness;
            hard.exciterMassKg = mass;
            hard.dissipation = 0.3;
            corrections +=
                expectSubstepLoopEqualsSteps<double>(hard, kModes, {{1.0, 1.0, 1.0}}, 0, 10.0);
            corrections += expectSubstepLoopEqualsSteps<float>(hard, many, gains, 1, 10.0);
        }
    }
    EXPECT_GT(corrections, 0); // the correction ran from the loop
}
