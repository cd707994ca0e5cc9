// SPDX-License-Identifier: GPL-3.0-or-later
// Stochastic aggregate model: Poisson event rate (constant, ramped, modulated, capped), power-law
// energy exponent, determinism, silence, no allocation in process().
#include "engine/models/Aggregate.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "tests/common/AllocationTrap.h"

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;
constexpr double kPiValue = 3.141592653589793;

struct Collector {
    std::vector<AggregateEvent> events;
};
void collect(void* user, const AggregateEvent& e) {
    static_cast<Collector*>(user)->events.push_back(e);
}

AggregateModel makeModel(AggregateParameters p = {}, int cap = 100000) {
    AggregateModel m;
    m.configure(p);
    m.prepare(kFs, cap);
    m.reset(1);
    return m;
}

// Runs the model with a per-sample rate function; returns the output.
template <typename RateFn>
std::vector<float> run(AggregateModel& m, double seconds, RateFn rate, double scale = 1.0) {
    const int n = static_cast<int>(seconds * kFs);
    std::vector<float> out(static_cast<std::size_t>(n), 0.0f);
    std::vector<float> r(512), s(512, static_cast<float>(scale));
    for (int done = 0; done < n; done += 512) {
        const int k = std::min(512, n - done);
        for (int i = 0; i < k; ++i)
            r[static_cast<std::size_t>(i)] = static_cast<float>(rate((done + i) / kFs));
        m.process(r.data(), s.data(), out.data() + done, k);
    }
    return out;
}
} // namespace

TEST(AggregateModel, ConstantRateMatchesSetRateAndIntervalsAreExponential) {
    auto m = makeModel();
    Collector c;
    m.setEventObserver(&collect, &c);
    const double rate = 500.0, seconds = 40.0;
    run(m, seconds, [&](double) { return rate; });
    // Poisson count: mean = sd^2 = 20000; 4 sd = 566.
    const double expected = rate * seconds;
    EXPECT_NEAR(static_cast<double>(m.eventCount()), expected, 4.0 * std::sqrt(expected));
    // Inter-arrival times: exponential, so mean = 1/rate and coefficient of variation = 1.
    double sum = 0, sumSq = 0;
    for (std::size_t i = 1; i < c.events.size(); ++i) {
        const double dt = static_cast<double>(c.events[i].sample - c.events[i - 1].sample) / kFs;
        sum += dt;
        sumSq += dt * dt;
    }
    const double k = static_cast<double>(c.events.size() - 1);
    const double mean = sum / k, sd = std::sqrt(sumSq / k - mean * mean);
    EXPECT_NEAR(mean, 1.0 / rate, 0.03 / rate);
    EXPECT_NEAR(sd / mean, 1.0, 0.03);
}

TEST(AggregateModel, RampedAndModulatedRatesMatchTheIntegratedRate) {
    // Linear ramp 0 -> 2000 events/s over 10 s: 2500 events in the first half, 7500 in the second.
    auto m = makeModel();
    Collector c;
    m.setEventObserver(&collect, &c);
    run(m, 10.0, [](double t) { return 200.0 * t; });
    int first = 0, second = 0;
    for (const auto& e : c.events) (e.sample < 5 * 48000 ? first : second)++;
    EXPECT_NEAR(first, 2500.0, 4.0 * std::sqrt(2500.0));
    EXPECT_NEAR(second, 7500.0, 4.0 * std::sqrt(7500.0));
    // Fast modulation (a step of the GRF is ~0.7 s): 800 (1 + sin(2 pi 8 t)) for 10 s -> 8000
    // events, and the events concentrate where the rate is high.
    auto m2 = makeModel();
    Collector c2;
    m2.setEventObserver(&collect, &c2);
    run(m2, 10.0, [](double t) { return 800.0 * (1.0 + std::sin(6.283185307179586 * 8.0 * t)); });
    EXPECT_NEAR(static_cast<double>(c2.events.size()), 8000.0, 4.0 * std::sqrt(8000.0));
    int high = 0;
    for (const auto& e : c2.events) {
        const double phase = std::fmod(static_cast<double>(e.sample) / kFs * 8.0, 1.0);
        if (phase < 0.5) ++high; // sin > 0 half: expected share (1 + 2/pi) / 2 = 0.818
    }
    EXPECT_NEAR(high / static_cast<double>(c2.events.size()), 0.5 + 1.0 / 3.141592653589793, 0.02);
}

TEST(AggregateModel, RateIsCappedIncludingBursts) {
    AggregateParameters p;
    p.burstEvents = 3.0;
    p.burstMs = 0.5;
    auto m = makeModel(p, 1000);
    EXPECT_DOUBLE_EQ(m.rateCapHz(), 1000.0);
    run(m, 10.0, [](double) { return 1e7; });
    // Total (primary + burst) about the cap: 10000 +- statistical spread of the bursts.
    EXPECT_NEAR(static_cast<double>(m.eventCount()), 10000.0, 600.0);
    // Bursts: with a moderate rate, each primary event brings burstEvents follow-ups on average.
    auto m2 = makeModel(p);
    Collector c;
    m2.setEventObserver(&collect, &c);
    run(m2, 20.0, [](double) { return 100.0; });
    int primary = 0, burst = 0;
    for (const auto& e : c.events) (e.burst ? burst : primary)++;
    EXPECT_NEAR(primary, 2000.0, 4.0 * std::sqrt(2000.0));
    // Geometric counts with mean 3: variance 12 per primary event -> sd of the total ~155.
    EXPECT_NEAR(static_cast<double>(burst) / primary, 3.0, 0.3);
    // Bursts stay local: dense primaries do not queue their bursts up; 50 ms after the rate drops
    // to zero (100 x the mean delay) no micro-event is left.
    AggregateParameters q;
    q.burstEvents = 5.0;
    q.burstMs = 0.5;
    auto m3 = makeModel(q);
    Collector c3;
    m3.setEventObserver(&collect, &c3);
    run(m3, 1.0, [](double t) { return t < 0.5 ? 500.0 : 0.0; });
    ASSERT_GT(c3.events.size(), 1000u);
    EXPECT_LT(c3.events.back().sample, static_cast<std::int64_t>(0.55 * kFs));
}

namespace {
// Least-squares slope of log density against log energy on log-spaced bins.
double fittedExponent(const std::vector<AggregateEvent>& events, double lo, double hi) {
    const int bins = 20;
    std::vector<double> counts(bins, 0.0);
    const double logLo = std::log(lo), span = std::log(hi) - logLo;
    for (const auto& e : events) {
        const int b = static_cast<int>((std::log(e.energy) - logLo) / span * bins);
        if (b >= 0 && b < bins) counts[static_cast<std::size_t>(b)] += 1;
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int used = 0;
    for (int b = 0; b < bins; ++b) {
        const double c = counts[static_cast<std::size_t>(b)];
        if (c < 20) continue; // too few to fit
        const double e0 = std::exp(logLo + span * b / bins),
                     e1 = std::exp(logLo + span * (b + 1) / bins);
        const double x = std::log(std::sqrt(e0 * e1)), y = std::log(c / (e1 - e0));
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++used;
    }
    return (used * sxy - sx * sy) / (used * sxx - sx * sx);
}
} // namespace

class AggregateEnergyLaw : public ::testing::TestWithParam<double> {};

TEST_P(AggregateEnergyLaw, FittedExponentMatchesGamma) {
    AggregateParameters p;
    p.gamma = GetParam();
    p.energyMin = 1e-4;
    p.energyMax = 1.0;
    auto m = makeModel(p);
    Collector c;
    m.setEventObserver(&collect, &c);
    run(m, 20.0, [](double) { return 3000.0; });
    ASSERT_GT(c.events.size(), 50000u);
    EXPECT_NEAR(fittedExponent(c.events, p.energyMin, p.energyMax), p.gamma, 0.06);
}

INSTANTIATE_TEST_SUITE_P(Gammas, AggregateEnergyLaw, ::testing::Values(-2.5, -1.5, -1.0, -0.5));

TEST(AggregateModel, EnergyScaleMultipliesEnergiesAndSetsAmplitude) {
    AggregateParameters p;
    p.resonances = 1;
    p.freqMinHz = p.freqMaxHz = 1000.0;
    p.qMin = p.qMax = 50.0;
    auto m = makeModel(p);
    m.trigger(0.25); // peak amplitude sqrt(0.25) = 0.5
    auto out = run(m, 0.05, [](double) { return 0.0; });
    double peak = 0;
    for (float v : out) peak = std::max(peak, std::fabs(static_cast<double>(v)));
    // a r^n sin(n theta) peaks at the first quarter period: 0.5 exp(-pi f t / Q), t = 0.25 ms
    EXPECT_NEAR(peak, 0.5 * std::exp(-3.14159 * 1000.0 * 0.00025 / 50.0), 0.002);
    // Scaled energies in the observer.
    auto m2 = makeModel();
    Collector c;
    m2.setEventObserver(&collect, &c);
    run(
        m2, 2.0, [](double) { return 1000.0; }, 4.0);
    for (const auto& e : c.events) {
        EXPECT_GE(e.energy, 4.0 * 1e-3 * (1 - 1e-12));
        EXPECT_LE(e.energy, 4.0 * (1 + 1e-12));
    }
}

TEST(AggregateModel, EachResonanceRingsAtItsFrequencyAndDecayAtAnyRate) {
    // One event, one resonance of fixed f and Q: zero crossings give f, the slope of log peak
    // heights gives the decay rate pi f / Q; low frequencies at high rates are the hard case for
    // a float two-pole (the rotation form keeps them exact).
    for (double fs : {22050.0, 48000.0, 192000.0}) {
        for (double f : {40.0, 1000.0, 8000.0}) {
            AggregateParameters p;
            p.resonances = 1;
            p.freqMinHz = p.freqMaxHz = f;
            p.qMin = p.qMax = 30.0;
            AggregateModel m;
            m.configure(p);
            m.prepare(fs, 1000);
            m.reset(1);
            m.trigger(1.0);
            const double decay = kPiValue * f / 30.0; // 1/s
            const int n = static_cast<int>(std::min(3.0 / decay, 2.0) * fs);
            std::vector<float> out(static_cast<std::size_t>(n), 0.0f),
                zero(static_cast<std::size_t>(n), 0.0f);
            m.process(zero.data(), zero.data(), out.data(), n);
            std::vector<double> crossings;
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            int peaks = 0;
            for (std::size_t i = 1; i + 1 < out.size(); ++i) {
                if (out[i - 1] < 0 && out[i] >= 0)
                    crossings.push_back(static_cast<double>(i - 1) +
                                        out[i - 1] / (out[i - 1] - out[i]));
                const double a = std::fabs(out[i]);
                if (a > std::fabs(out[i - 1]) && a >= std::fabs(out[i + 1]) && a > 1e-6 &&
                    f < fs / 8) {
                    const double t = static_cast<double>(i) / fs;
                    sx += t;
                    sy += std::log(a);
                    sxx += t * t;
                    sxy += t * std::log(a);
                    ++peaks;
                }
            }
            ASSERT_GT(crossings.size(), 5u);
            const double measured = fs * static_cast<double>(crossings.size() - 1) /
                                    (crossings.back() - crossings.front());
            EXPECT_NEAR(measured, f, f * 2e-3) << "fs " << fs << " f " << f;
            if (peaks >
                10) { // sampled peaks are exact maxima only when a period spans many samples
                const double slope = (peaks * sxy - sx * sy) / (peaks * sxx - sx * sx);
                EXPECT_NEAR(-slope, decay, decay * 0.03) << "fs " << fs << " f " << f;
            }
        }
    }
}

TEST(AggregateModel, DeterministicForASeedAndSeedsDiffer) {
    auto a = makeModel(), b = makeModel(), c = makeModel();
    a.reset(42);
    b.reset(42);
    c.reset(43);
    auto rate = [](double t) { return 1500.0 * (1.0 + std::sin(10.0 * t)); };
    const auto xa = run(a, 2.0, rate), xb = run(b, 2.0, rate), xc = run(c, 2.0, rate);
    EXPECT_EQ(xa, xb);
    EXPECT_NE(xa, xc);
    // reset() restores the initial state exactly.
    a.reset(42);
    EXPECT_EQ(run(a, 2.0, rate), xa);
}

// The resonators run in runs of samples between voice starts and ends, slot group by slot group,
// with an AVX or an SSE2 kernel. Driven one sample per call, every run is one sample long: the
// sample-by-sample recurrence, as the model computed it before the runs. Every way of cutting
// the input, and both kernels, must give exactly those samples: padded groups (3 resonances),
// one group, an odd number of groups, a full pool that steals, bursts, and calls longer than a
// run (777 samples).
TEST(AggregateModel, RunsAndKernelsGiveTheSampleBySampleSamples) {
    struct Case {
        int resonances, voices;
        double burst, q;
    };
    for (const Case c : {Case{1, 1, 0.0, 5.0}, Case{3, 5, 2.0, 10.0}, Case{4, 48, 4.0, 8.0},
                         Case{2, 20, 1.0, 60.0}, Case{4, 13, 0.0, 3.0}}) {
        AggregateParameters p;
        p.resonances = c.resonances;
        p.voices = c.voices;
        p.burstEvents = c.burst;
        p.qMin = c.q;
        p.qMax = 2.0 * c.q;
        p.freqMinHz = 120.0;
        p.freqMaxHz = 6000.0;
        const int n = static_cast<int>(0.6 * kFs);
        std::vector<float> rate(static_cast<std::size_t>(n)), scale(rate.size());
        for (int i = 0; i < n; ++i) { // steps: a rate that rises, holds and stops
            const double t = std::fmod(i / kFs, 0.3);
            rate[static_cast<std::size_t>(i)] = t < 0.2 ? static_cast<float>(4000.0 * t) : 0.0f;
            scale[static_cast<std::size_t>(i)] = static_cast<float>(0.5 + t);
        }
        auto render = [&](int chunk, bool avx) {
            AggregateModel m = makeModel(p);
            m.allowAvx(avx);
            m.reset(9);
            std::vector<float> out(rate.size(), 0.0f);
            for (int done = 0; done < n; done += chunk)
                m.process(rate.data() + done, scale.data() + done, out.data() + done,
                          std::min(chunk, n - done));
            EXPECT_GT(m.eventCount(), 100u);
            return out;
        };
        const auto reference = render(1, false);
        double energy = 0.0;
        for (float v : reference) energy += static_cast<double>(v) * v;
        EXPECT_GT(energy, 0.0);
        for (int chunk : {1, 64, 777})
            for (bool avx : {false, true})
                EXPECT_EQ(render(chunk, avx), reference)
                    << c.resonances << " resonances, " << c.voices << " voices, chunk " << chunk
                    << (avx ? ", AVX" : ", SSE2");
    }
}

// The energy scale may be computed on demand (GrainsLayer: a pow and tanh per sample otherwise):
// the model asks for it only at samples where events start, and the samples are those of the
// array it would otherwise read.
TEST(AggregateModel, EnergyScaleOnDemandGivesTheArraysSamples) {
    AggregateParameters p;
    p.burstEvents = 1.5;
    const int n = static_cast<int>(0.5 * kFs);
    std::vector<float> rate(static_cast<std::size_t>(n)), scale(rate.size());
    for (int i = 0; i < n; ++i) {
        rate[static_cast<std::size_t>(i)] = static_cast<float>(800.0 * (1.0 + std::sin(i * 1e-3)));
        scale[static_cast<std::size_t>(i)] =
            static_cast<float>(0.2 + 0.8 * std::fabs(std::cos(i * 7e-4)));
    }
    struct Source {
        const float* scale;
        int offset = 0, calls = 0;
    } source{scale.data()};
    auto fromArray = makeModel(p), onDemand = makeModel(p);
    std::vector<float> a(rate.size(), 0.0f), b(rate.size(), 0.0f);
    for (int done = 0; done < n; done += 300) {
        const int k = std::min(300, n - done);
        fromArray.process(rate.data() + done, scale.data() + done, a.data() + done, k);
        source.offset = done;
        onDemand.process(
            rate.data() + done,
            [](void* user, int i) noexcept {
                auto* s = static_cast<Source*>(user);
                ++s->calls;
                return s->scale[s->offset + i];
            },
            &source, b.data() + done, k);
    }
    EXPECT_EQ(a, b);
    EXPECT_GT(fromArray.eventCount(), 300u);
    EXPECT_GT(source.calls, 0);
    // asked once per sample with a primary event, never for a burst's micro-events alone
    EXPECT_LT(static_cast<std::uint64_t>(source.calls), fromArray.eventCount());
}

TEST(AggregateModel, SilentAtZeroRateAndVoicesEnd) {
    auto m = makeModel();
    auto out = run(m, 1.0, [](double) { return 0.0; });
    for (float v : out) ASSERT_EQ(v, 0.0f);
    EXPECT_TRUE(m.idle());
    // A burst of events, then zero rate: every voice ends (idle) and the output is exactly zero.
    run(m, 0.2, [](double) { return 2000.0; });
    EXPECT_GT(m.activeVoices(), 0);
    auto tail = run(m, 2.0, [](double) { return 0.0; });
    EXPECT_TRUE(m.idle());
    for (std::size_t i = tail.size() - 1000; i < tail.size(); ++i) ASSERT_EQ(tail[i], 0.0f);
    // NaN and negative rates count as zero.
    auto out2 = run(m, 0.5, [](double t) { return t < 0.25 ? std::nan("") : -5.0; });
    for (float v : out2) ASSERT_EQ(v, 0.0f);
}

TEST(AggregateModel, VoicePoolIsBoundedAndStealsTheQuietest) {
    AggregateParameters p;
    p.voices = 4;
    p.qMin = p.qMax = 200.0; // long-ringing voices fill the pool
    p.freqMinHz = 200.0;
    p.freqMaxHz = 400.0;
    auto m = makeModel(p);
    auto out = run(m, 1.0, [](double) { return 2000.0; });
    EXPECT_LE(m.activeVoices(), 4);
    EXPECT_GT(m.stolenVoices(), 0u);
    // Bounded: at most 4 voices of peak sqrt(K E) <= sqrt(2) each.
    for (float v : out) ASSERT_LE(std::fabs(v), 4.0f * std::sqrt(2.0f) + 1e-3f);
}

TEST(AggregateModel, NoAllocationInProcess) {
    AggregateParameters p;
    p.burstEvents = 2;
    auto m = makeModel(p);
    std::vector<float> rate(512, 3000.0f), scale(512, 1.0f), out(512, 0.0f);
    underfoot::test::allocationCount = 0;
    underfoot::test::countAllocations = true;
    for (int b = 0; b < 200; ++b) m.process(rate.data(), scale.data(), out.data(), 512);
    m.trigger(1.0);
    m.process(rate.data(), scale.data(), out.data(), 512);
    underfoot::test::countAllocations = false;
    EXPECT_GT(m.eventCount(), 1000u);
    EXPECT_EQ(underfoot::test::allocationCount.load(), 0);
}

TEST(AggregateModel, RejectsInvalidParameters) {
    AggregateParameters p;
    p.energyMin = 0;
    EXPECT_THROW(p.validate(), std::invalid_argument);
    p = {};
    p.freqMaxHz = 10.0; // below freqMinHz
    EXPECT_THROW(p.validate(), std::invalid_argument);
    p = {};
    p.resonances = 5;
    EXPECT_THROW(p.validate(), std::invalid_argument);
    p = {};
    p.qMin = std::nan("");
    EXPECT_THROW(p.validate(), std::invalid_argument);
}

// Noise excitation (Aggregate.h): every event is a decaying burst of white noise. The event
// rate of the resonant grains, the same samples however the
// input is cut, a burst of energy E starts at power E and decays with noise_decay_ms, white
// noise spreads its energy over the band, and the layer falls silent after its last event.
TEST(AggregateModel, NoiseBurstsAreBroadbandDecayingAndDeterministic) {
    AggregateParameters p;
    p.excitation = AggregateParameters::Excitation::Noise;
    p.noiseDecayMs = 4.0;
    AggregateParameters resonant;
    Collector noiseEvents, ringEvents;
    auto noise = makeModel(p), ring = makeModel(resonant);
    noise.setEventObserver(collect, &noiseEvents);
    ring.setEventObserver(collect, &ringEvents);
    noise.reset(7);
    ring.reset(7);
    auto rate = [](double t) { return t < 1.0 ? 300.0 : 0.0; };
    const auto x = run(noise, 1.5, rate);
    run(ring, 1.5, rate);
    // As many events as the rate asks (300 in 1 s, Poisson: sd 17), as with resonances.
    EXPECT_NEAR(double(noiseEvents.events.size()), 300.0, 60.0);
    EXPECT_NEAR(double(ringEvents.events.size()), 300.0, 60.0);
    // One sample per call: the same samples.
    auto single = makeModel(p);
    single.reset(7);
    std::vector<float> y(x.size());
    for (std::size_t i = 0; i < y.size(); ++i) {
        const auto r = static_cast<float>(rate(double(i) / kFs)), s = 1.0f;
        single.process(&r, &s, &y[i], 1);
    }
    EXPECT_EQ(x, y);
    EXPECT_TRUE(noise.idle());
    for (std::size_t i = static_cast<std::size_t>(1.4 * kFs); i < x.size(); ++i)
        ASSERT_EQ(x[i], 0.0f);
    // White: the first difference of white noise has twice its power; of a low tone, far less.
    double power = 0, diff = 0;
    for (std::size_t i = 1; i < static_cast<std::size_t>(kFs); ++i) {
        power += double(x[i]) * x[i];
        diff += std::pow(double(x[i]) - x[i - 1], 2);
    }
    EXPECT_NEAR(diff / power, 2.0, 0.15);
    // One burst: power E at its start, decaying as exp(-2 t / noise_decay_ms).
    auto one = makeModel(p);
    one.trigger(0.25);
    std::vector<float> z(static_cast<std::size_t>(0.05 * kFs)), zero(z.size(), 0.0f),
        unit(z.size(), 1.0f);
    one.process(zero.data(), unit.data(), z.data(), static_cast<int>(z.size()));
    double energy = 0;
    for (float v : z) energy += double(v) * v;
    EXPECT_NEAR(energy / (0.25 * 0.004 * kFs / 2), 1.0, 0.25); // sum of E e^(-2t/tau)
}
