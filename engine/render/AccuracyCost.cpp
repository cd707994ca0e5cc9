// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/AccuracyCost.h"

#include "engine/dsp/Denormals.h"
#include "engine/dsp/RealFft.h"
#include "engine/models/Aggregate.h"
#include "engine/models/Bubbles.h"
#include "engine/models/Friction.h"
#include "engine/render/Renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace underfoot::engine {
namespace {
using CostClock = std::chrono::steady_clock;
constexpr double kRate = 48000.0;
constexpr int kCostBlock = 64;
/// Blocks between two strikes in the timed runs (one strike every 0.25 s).
constexpr int kStrikeEvery = static_cast<int>(0.25 * kRate / kCostBlock);

const std::vector<Mode>& benchModes() {
    static const std::vector<Mode> modes = {
        {180.0, 0.15, 2.0}, {620.0, 0.08, 0.8}, {1900.0, 0.04, 0.5}};
    return modes;
}

ImpactParams benchParams(const ImpactSetting& s) {
    ImpactParams p;
    p.stiffness = 2e9;
    p.alpha = 1.5;
    p.dissipation = 0.6;
    p.exciterMassKg = 0.1;
    p.solver = s.solver;
    p.newtonIterations = s.iterations;
    p.oversampling = s.oversampling;
    p.contactSubsteps = s.contactSubsteps;
    return p;
}

struct StrikeResult {
    std::vector<float> out;
    double contactTime = 0, restitution = 0;
};

template <typename Real>
StrikeResult strikeOnce(const ImpactSetting& s) {
    HuntCrossleyImpactT<Real> impact;
    impact.configure(benchParams(s), benchModes(), {{1.0, 1.0, 1.0}});
    impact.prepare({kRate, kCostBlock});
    impact.strike(0.5);
    StrikeResult r;
    r.out.assign(static_cast<std::size_t>(0.25 * kRate), 0.0f);
    for (std::size_t i = 0; i < r.out.size(); i += kCostBlock)
        impact.process(nullptr, r.out.data() + i,
                       static_cast<int>(std::min<std::size_t>(kCostBlock, r.out.size() - i)));
    r.contactTime = impact.stats().contactTimeSeconds;
    r.restitution = impact.stats().incomingVelocity != 0.0
                        ? -impact.stats().outgoingVelocity / impact.stats().incomingVelocity
                        : 0.0;
    return r;
}

// What one timed run does per 64-frame block: `prepare` and `check` are not timed (clearing the
// output, a checksum), `block` is.
struct TimedRun {
    std::function<void(int)> prepare, block, check;
};

struct BlockTimes {
    double nsPerSample = 0, medianBlockNs = 0, p99BlockNs = 0, maxBlockNs = 0;
};

// Times `blocks` blocks of `repeats` fresh runs (makeRun() builds one); each block's cost is the
// minimum over the repeats, which removes preemption by other processes (this machine is shared)
// and keeps what the algorithm itself costs in that block. The one timing loop of the bench.
BlockTimes timeBlocks(int blocks, int repeats, const std::function<TimedRun()>& makeRun) {
    std::vector<double> best(static_cast<std::size_t>(blocks), 1e300);
    ScopedFlushDenormals ftz;
    for (int rep = 0; rep < std::max(1, repeats); ++rep) {
        const TimedRun run = makeRun();
        for (int b = 0; b < blocks; ++b) {
            if (run.prepare) run.prepare(b);
            const auto s0 = CostClock::now();
            run.block(b);
            const double ns =
                std::chrono::duration<double, std::nano>(CostClock::now() - s0).count();
            best[static_cast<std::size_t>(b)] = std::min(best[static_cast<std::size_t>(b)], ns);
            if (run.check) run.check(b);
        }
    }
    BlockTimes t;
    double total = 0;
    for (double ns : best) total += ns;
    t.nsPerSample = total / (double(blocks) * kCostBlock);
    std::sort(best.begin(), best.end());
    t.medianBlockNs = best[best.size() / 2];
    t.p99BlockNs = best[best.size() * 99 / 100];
    t.maxBlockNs = best.back();
    return t;
}

// Times a deterministic train of strikes (4 per second) block by block.
template <typename Real>
void timeStrikes(const ImpactSetting& s, double seconds, ImpactMeasurement& m, int repeats = 5) {
    const int blocks = static_cast<int>(seconds * kRate / kCostBlock);
    auto out = std::make_shared<std::vector<float>>(kCostBlock);
    const BlockTimes t = timeBlocks(blocks, repeats, [&] {
        auto impact = std::make_shared<HuntCrossleyImpactT<Real>>();
        impact->configure(benchParams(s), benchModes(), {{1.0, 1.0, 1.0}});
        impact->prepare({kRate, kCostBlock});
        TimedRun run;
        run.block = [impact, out](int b) {
            if (b % kStrikeEvery == 0) impact->strike(0.5);
            impact->process(nullptr, out->data(), kCostBlock);
        };
        return run;
    });
    m.nsPerSample = t.nsPerSample;
    m.medianBlockNs = t.medianBlockNs;
    m.p99BlockNs = t.p99BlockNs;
    m.maxBlockNs = t.maxBlockNs;
}

std::vector<double> thirdOctaveLevels(const std::vector<float>& x, double fs) {
    const int n = static_cast<int>(x.size());
    RealFft fft(n);
    for (int i = 0; i < n; ++i) fft.time()[i] = x[static_cast<std::size_t>(i)];
    fft.forward();
    const fftw_complex* out = fft.spectrum();
    std::vector<double> bands;
    for (double fc = 50.0; fc <= 16000.0; fc *= std::pow(2.0, 1.0 / 3.0)) {
        const double lo = fc / std::pow(2.0, 1.0 / 6.0), hi = fc * std::pow(2.0, 1.0 / 6.0);
        double e = 1e-30;
        for (int k = static_cast<int>(lo * n / fs);
             k <= static_cast<int>(hi * n / fs) && k <= n / 2; ++k)
            e += out[k][0] * out[k][0] + out[k][1] * out[k][1];
        bands.push_back(10 * std::log10(e));
    }
    return bands;
}
// One 64-sample block of the friction-creak scenario (the drag's anchor moving at 0.05 m/s
// under a 105 N load), added into `out`: the scenario and the friction knob share it.
void creakBlock(ElastoPlasticFriction& f, double& anchor, float* out) noexcept {
    for (int i = 0; i < kCostBlock; ++i) {
        anchor += 0.05 / kRate;
        out[i] += static_cast<float>(f.processSample(105.0, 0.0, anchor, 0.05));
    }
    f.resonator().flushTinyState();
}

} // namespace

double spectralDistanceDb(const std::vector<float>& a, const std::vector<float>& ref, double fs) {
    const std::size_t n = std::min(a.size(), ref.size());
    const auto la =
        thirdOctaveLevels(std::vector<float>(a.begin(), a.begin() + static_cast<long>(n)), fs);
    const auto lr =
        thirdOctaveLevels(std::vector<float>(ref.begin(), ref.begin() + static_cast<long>(n)), fs);
    const double top = *std::max_element(lr.begin(), lr.end());
    double sum = 0;
    int count = 0;
    for (std::size_t b = 0; b < lr.size(); ++b) {
        if (lr[b] < top - 80.0) continue;
        sum += (la[b] - lr[b]) * (la[b] - lr[b]);
        ++count;
    }
    return count ? std::sqrt(sum / count) : 0.0;
}

std::vector<ImpactSetting> defaultImpactSettings() {
    return {
        {"explicit, 1x", ImpactSolver::Explicit, 1, 1, false, 1},
        {"explicit, 4x", ImpactSolver::Explicit, 1, 4, false, 1},
        {"Newton 1 it, 1x", ImpactSolver::Newton, 1, 1, false, 1},
        {"Newton 2 it, 1x", ImpactSolver::Newton, 2, 1, false, 1},
        {"Newton 4 it, 1x", ImpactSolver::Newton, 4, 1, false, 1},
        {"Newton 6 it, 1x (old default)", ImpactSolver::Newton, 6, 1, false, 1},
        {"Newton 6 it, 2x", ImpactSolver::Newton, 6, 2, false, 1},
        {"Newton 6 it, 4x", ImpactSolver::Newton, 6, 4, false, 1},
        {"Newton 6 it, 1x, float state", ImpactSolver::Newton, 6, 1, true, 1},
        {"Newton 6 it, 1x, contact sub-steps 2", ImpactSolver::Newton, 6, 1, false, 2},
        {"Newton 6 it, 1x, contact sub-steps 4 (default)", ImpactSolver::Newton, 6, 1, false, 4},
        {"Newton 6 it, 1x, contact sub-steps 8", ImpactSolver::Newton, 6, 1, false, 8},
        {"Newton 6 it, 1x, contact sub-steps 16", ImpactSolver::Newton, 6, 1, false, 16},
    };
}

ImpactMeasurement measureImpact(const ImpactSetting& setting, double seconds) {
    static const StrikeResult reference =
        strikeOnce<double>({"reference", ImpactSolver::Newton, 50, 8, false, 1});
    ImpactMeasurement m;
    m.setting = setting;
    const StrikeResult r =
        setting.floatState ? strikeOnce<float>(setting) : strikeOnce<double>(setting);
    m.contactTimeMs = 1e3 * r.contactTime;
    m.restitution = r.restitution;
    m.contactTimeErrorPct =
        100.0 * std::fabs(r.contactTime - reference.contactTime) / reference.contactTime;
    m.restitutionError = std::fabs(r.restitution - reference.restitution);
    m.spectralDistanceDb = spectralDistanceDb(r.out, reference.out, kRate);
    if (setting.floatState)
        timeStrikes<float>(setting, seconds, m);
    else
        timeStrikes<double>(setting, seconds, m);
    return m;
}

std::vector<KnobMeasurement> measureKnobs(double seconds) {
    std::vector<KnobMeasurement> out;
    WalkerParameters w;
    GrfSignal grf = walkerGrf(w, seconds, kRate, 2);
    grf.channels.resize(1);
    grf.names.resize(1);
    auto run = [&](const std::string& surface, const AccuracyOptions& acc) {
        RenderOptions options;
        options.scene.accuracy = acc;
        options.scene.reverb = ReverbMode::Off;
        return renderSurface(surface, grf, options);
    };
    auto left = [](const RenderResult& r) { return r.audio.channel(0); };
    // One knob swept on one surface: per setting, the distance to the render with `reference`
    // and the CPU time per sample.
    auto sweep = [&](const char* knob, const std::string& surface, const AccuracyOptions& reference,
                     std::initializer_list<int> values, void (*set)(AccuracyOptions&, int)) {
        const auto ref = run(surface, reference);
        for (int value : values) {
            AccuracyOptions a;
            set(a, value);
            const auto r = run(surface, a);
            out.push_back({knob, std::to_string(value),
                           spectralDistanceDb(left(r), left(ref), kRate),
                           1e9 * r.cpuSeconds / double(r.audio.frames())});
        }
    };
    sweep("modes (metal, 14 in the preset)", "metal", AccuracyOptions{}, {3, 6, 10, 14},
          [](AccuracyOptions& a, int modes) { a.maxModes = modes; });
    AccuracyOptions high;
    high.maxEventsPerSecond = 32000;
    sweep("event cap (gravel, events/s per layer)", "gravel", high, {250, 1000, 4000, 32000},
          [](AccuracyOptions& a, int cap) { a.maxEventsPerSecond = cap; });
    // The friction solve's Newton stop on the bench's creak (friction-creak), against the
    // converged reference: the fixed-point passes with libm, started without a warm start and
    // run until a pass changes nothing (at most 50).
    {
        const int blocks = std::max(1, static_cast<int>(seconds * kRate / kCostBlock));
        auto renderCreak = [blocks](const FrictionParams& p, double* nsPerSample) {
            std::vector<float> audio(static_cast<std::size_t>(blocks) * kCostBlock, 0.0f);
            const BlockTimes t = timeBlocks(blocks, 3, [&] { // (per-block minimum of 3 runs)
                auto f = std::make_shared<ElastoPlasticFriction>();
                configureCreakScenario(*f, p);
                auto anchor = std::make_shared<double>(0.0);
                TimedRun timed;
                auto at = [&audio](int b) {
                    return audio.data() + static_cast<std::size_t>(b) * kCostBlock;
                };
                timed.prepare = [at](int b) { std::fill(at(b), at(b) + kCostBlock, 0.0f); };
                timed.block = [f, anchor, at](int b) { creakBlock(*f, *anchor, at(b)); };
                return timed;
            });
            if (nsPerSample) *nsPerSample = t.nsPerSample;
            return audio;
        };
        FrictionParams reference;
        reference.newton = false;
        reference.libmFunctions = true;
        reference.warmStart = false;
        reference.extrapolate = false;
        reference.maxIterations = 50;
        reference.tolerance = 0.0;
        const std::vector<float> ref = renderCreak(reference, nullptr);
        const double shipped = FrictionParams{}.newtonStepTolerance;
        const std::pair<double, const char*> settings[] = {
            {0.0, "0 (tight)"}, {1e-4, "1e-4"}, {1e-3, "1e-3"}, {1e-2, "1e-2"}};
        for (const auto& [stepTol, name] : settings) {
            FrictionParams p;
            p.newtonStepTolerance = stepTol;
            double ns = 0.0;
            const std::vector<float> y = renderCreak(p, &ns);
            std::string setting = name;
            if (stepTol == shipped) setting += " (default)";
            out.push_back({"friction Newton stop (creak, newtonStepTolerance; vs 50 passes)",
                           setting, spectralDistanceDb(y, ref, kRate), ns});
        }
    }
    return out;
}

namespace {

// One scenario: a block function that adds 64 samples into `out` given the block index.
using BlockFn = std::function<void(int block, float* out)>;

ImpactParams scenarioImpact() {
    ImpactParams p; // shipped defaults (solver, iterations, contact sub-steps)
    p.stiffness = 2e9;
    p.alpha = 1.5;
    p.dissipation = 0.6;
    p.exciterMassKg = 0.1;
    return p;
}

// Metal preset (engine/data/surfaces/metal.toml when the cost table was measured): 14 modes.
const std::vector<Mode>& metalModes() {
    static const std::vector<Mode> m = {
        {187, 0.235173, 8.0},   {467, 0.205776, 4.0},   {748, 0.17638, 3.0},
        {935, 0.161681, 2.5},   {1216, 0.139634, 2.0},  {1683, 0.117586, 2.0},
        {1870, 0.110237, 2.0},  {2431, 0.0881898, 2.0}, {2992, 0.0734915, 2.0},
        {3553, 0.0617329, 2.0}, {4395, 0.0514441, 2.0}, {5236, 0.0440949, 2.0},
        {6545, 0.0323363, 2.0}, {8040, 0.0235173, 2.5}};
    return m;
}
const std::vector<double>& metalGains() {
    static const std::vector<double> g = {1.79504,  1.17389,  0.940628, 0.818982, 0.74723,
                                          0.625424, 0.562659, 0.476764, 0.409332, 0.353383,
                                          0.298281, 0.252543, 0.207667, 0.144962};
    return g;
}

struct Scenario {
    std::shared_ptr<void> state;
    BlockFn block;
};

// gravel.toml's first ("sharp clicks") grains layer; with oneVoice, like for like with SDT's
// crumpling patch: one grain resonator, retriggered by each event (the new grain cuts the last
// one off), no follow-up bursts.
AggregateParameters gravelGrains(bool oneVoice) {
    AggregateParameters p;
    p.gamma = -1.6;
    p.energyMin = 0.001;
    p.resonances = 2;
    p.freqMinHz = 1690.95;
    p.freqMaxHz = 7609.26;
    p.qMin = 9.8455;
    p.qMax = 41.0229;
    p.voices = oneVoice ? 1 : 48;
    p.burstEvents = oneVoice ? 0.0 : 1.0;
    p.burstMs = 1.5;
    return p;
}

// A stream of events (AggregateModel, BubbleStream) prepared for at most maxEventsPerSecond and
// seeded 7, driven at a constant event rate (events/s) and energy scale 1.
template <typename Stream, typename Parameters>
Scenario streamScenario(const Parameters& p, float rateHz, int maxEventsPerSecond = 4000) {
    auto s = std::make_shared<Stream>();
    s->configure(p);
    s->prepare(kRate, maxEventsPerSecond);
    s->reset(7);
    auto rate = std::make_shared<std::vector<float>>(kCostBlock, rateHz);
    auto scale = std::make_shared<std::vector<float>>(kCostBlock, 1.0f);
    return {s, [s, rate, scale](int, float* out) {
                s->process(rate->data(), scale->data(), out, kCostBlock);
            }};
}

Scenario makeScenario(const std::string& id) {
    if (id == "impact-strikes" || id == "impact-pressed" || id == "impact-metal") {
        auto impact = std::make_shared<HuntCrossleyImpact>();
        ImpactParams p = scenarioImpact();
        double v = 0.5;
        if (id == "impact-metal") {
            p.stiffness = 50885308640.155411;
            p.dissipation = 0.3;
            v = 0.45;
            impact->configure(p, metalModes(), {metalGains()});
        } else {
            impact->configure(p, benchModes(), {{1.0, 1.0, 1.0}});
        }
        impact->prepare({kRate, kCostBlock});
        const bool pressed = id == "impact-pressed";
        auto force = std::make_shared<std::vector<float>>(kCostBlock, pressed ? 300.0f : 0.0f);
        return {impact, [impact, force, pressed, v](int b, float* out) {
                    if (pressed ? b == 0 : b % kStrikeEvery == 0) impact->strike(v);
                    impact->process(pressed ? force->data() : nullptr, out, kCostBlock);
                }};
    }
    if (id == "friction-creak") {
        auto f = std::make_shared<ElastoPlasticFriction>();
        configureCreakScenario(*f);
        auto anchor = std::make_shared<double>(0.0);
        return {f, [f, anchor](int, float* out) { creakBlock(*f, *anchor, out); }};
    }
    if (id == "aggregate-gravel" || id == "aggregate-gravel-1voice")
        return streamScenario<AggregateModel>(gravelGrains(id == "aggregate-gravel-1voice"),
                                              1000.0f);
    if (id == "bubbles") {
        BubbleStreamParameters p;
        p.voices = 48;
        return streamScenario<BubbleStream>(p, 500.0f);
    }
    throw std::invalid_argument("unknown bench scenario '" + id + "'");
}
} // namespace

const std::vector<std::string>& scenarioIds() {
    static const std::vector<std::string> ids = {
        "impact-strikes",   "impact-pressed", "impact-metal",           "friction-creak",
        "aggregate-gravel", "bubbles",        "aggregate-gravel-1voice"};
    return ids;
}

void configureCreakScenario(ElastoPlasticFriction& f, FrictionParams p) {
    // The creaking-wood friction layer as it was when the cost table was measured
    // (engine/data/surfaces/creaking_wood.toml before its creak was re-voiced,
    // docs/decisions/realism-revoicing.md: sigma3 0.05, top modes 1130/1870/2650 Hz). A fixed
    // benchmark of the solver: it stays as it is so that its figures stay comparable with the Sound
    // Design Toolkit's.
    p.sigma0 = 2e5;
    p.sigma1 = 150.0;
    p.sigma2 = 0.2;
    p.sigma3 = 0.05;
    p.staticCoefficient = 0.55;
    p.dynamicCoefficient = 0.25;
    p.stribeckVelocity = 0.02;
    p.breakAway = 0.6;
    p.exciterMassKg = 0.02;
    p.driveStiffness = 5e5;
    p.driveDamping = 2.0;
    f.configure(p,
                {{310, 0.06, 0.05},
                 {690, 0.05, 0.04},
                 {1130, 0.04, 0.04},
                 {1870, 0.03, 0.05},
                 {2650, 0.02, 0.06}},
                {{1.0, 0.8, 0.7, 0.5, 0.3}});
    f.prepare(kRate);
    f.reset(7);
}

ScenarioMeasurement measureScenario(const std::string& id, double seconds, int repeats) {
    const int blocks = static_cast<int>(seconds * kRate / kCostBlock);
    auto out = std::make_shared<std::vector<float>>(kCostBlock);
    auto checksum = std::make_shared<double>(0.0);
    ScenarioMeasurement m;
    m.id = id;
    const BlockTimes t = timeBlocks(blocks, repeats, [&] {
        auto sc = std::make_shared<Scenario>(makeScenario(id));
        *checksum = 0.0;
        TimedRun run;
        run.prepare = [out](int) { std::fill(out->begin(), out->end(), 0.0f); };
        run.block = [sc, out](int b) { sc->block(b, out->data()); };
        run.check = [out, checksum](int) {
            for (float y : *out) *checksum += std::fabs(double(y));
        };
        return run;
    });
    m.checksum = *checksum;
    m.nsPerSample = t.nsPerSample;
    m.medianBlockNs = t.medianBlockNs;
    m.p99BlockNs = t.p99BlockNs;
    m.maxBlockNs = t.maxBlockNs;
    m.budgetShare = m.maxBlockNs / (1e9 * kCostBlock / kRate);
    return m;
}

std::vector<ScalingPoint> measureScaling(double seconds, int repeats) {
    const int blocks = static_cast<int>(seconds * kRate / kCostBlock);
    auto out = std::make_shared<std::vector<float>>(kCostBlock);
    std::vector<ScalingPoint> points;
    auto timeRuns = [&](const std::function<TimedRun()>& make) {
        return timeBlocks(blocks, repeats, make).nsPerSample;
    };
    // Simultaneous impact voices (the impact-strikes scenario's voice), strikes staggered.
    for (int voices : {1, 2, 4, 8, 16, 32, 64, 128, 256}) {
        const double ns = timeRuns([&] {
            auto pool =
                std::make_shared<std::vector<HuntCrossleyImpact>>(static_cast<std::size_t>(voices));
            for (auto& v : *pool) {
                v.configure(scenarioImpact(), benchModes(), {{1.0, 1.0, 1.0}});
                v.prepare({kRate, kCostBlock});
            }
            TimedRun run;
            run.block = [pool, out](int b) {
                for (std::size_t v = 0; v < pool->size(); ++v) {
                    auto& voice = (*pool)[v];
                    if ((b + static_cast<int>(v) * 7) % kStrikeEvery == 0) voice.strike(0.5);
                    voice.process(nullptr, out->data(), kCostBlock);
                }
            };
            return run;
        });
        points.push_back({"voices", voices, ns, ns / voices});
    }
    // Modes per voice: one impact voice, modes spread over 100 Hz..19 kHz.
    for (int modes : {3, 6, 12, 24, 48, 64}) {
        std::vector<Mode> m;
        for (int i = 0; i < modes; ++i)
            m.push_back({100.0 + 18900.0 * i / std::max(1, modes - 1), 0.2 / (1 + 0.1 * i), 1.0});
        const std::vector<double> g(static_cast<std::size_t>(modes), 1.0);
        const double ns = timeRuns([&] {
            auto impact = std::make_shared<HuntCrossleyImpact>();
            impact->configure(scenarioImpact(), m, {g});
            impact->prepare({kRate, kCostBlock});
            TimedRun run;
            run.block = [impact, out](int b) {
                if (b % kStrikeEvery == 0) impact->strike(0.5);
                impact->process(nullptr, out->data(), kCostBlock);
            };
            return run;
        });
        points.push_back({"modes per voice", modes, ns, ns / modes});
    }
    // Grain rate: the aggregate-gravel scenario's grains layer at 250..16000 events/s.
    for (int rate : {250, 500, 1000, 2000, 4000, 8000, 16000}) {
        const double ns = timeRuns([&] {
            auto sc = std::make_shared<Scenario>(
                streamScenario<AggregateModel>(gravelGrains(false), float(rate), 16000));
            TimedRun run;
            run.prepare = [out](int) { std::fill(out->begin(), out->end(), 0.0f); };
            run.block = [sc, out](int b) { sc->block(b, out->data()); };
            return run;
        });
        points.push_back({"grain events/s", rate, ns, ns / (rate / 1000.0)});
    }
    return points;
}

} // namespace underfoot::engine
