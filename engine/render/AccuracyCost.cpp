// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/render/AccuracyCost.h"

#include "engine/dsp/Denormals.h"
#include "engine/render/Renderer.h"

#include <fftw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace underfoot::engine {
namespace {
using Clock = std::chrono::steady_clock;
constexpr double kRate = 48000.0;
constexpr int kBlock = 64;

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
    impact.prepare({kRate, kBlock});
    impact.strike(0.5);
    StrikeResult r;
    r.out.assign(static_cast<std::size_t>(0.25 * kRate), 0.0f);
    for (std::size_t i = 0; i < r.out.size(); i += kBlock)
        impact.process(nullptr, r.out.data() + i,
                       static_cast<int>(std::min<std::size_t>(kBlock, r.out.size() - i)));
    r.contactTime = impact.stats().contactTimeSeconds;
    r.restitution = impact.stats().incomingVelocity != 0.0
                        ? -impact.stats().outgoingVelocity / impact.stats().incomingVelocity
                        : 0.0;
    return r;
}

// Times a deterministic train of strikes (4 per second) block by block, `repeats` times over;
// each block's cost is the minimum over the repeats, which removes preemption by other processes
// (this machine is shared) and keeps what the algorithm itself costs in that block.
template <typename Real>
void timeStrikes(const ImpactSetting& s, double seconds, ImpactMeasurement& m, int repeats = 5) {
    const int blocks = static_cast<int>(seconds * kRate / kBlock);
    const int strikeEvery = static_cast<int>(0.25 * kRate / kBlock);
    std::vector<double> best(static_cast<std::size_t>(blocks), 1e300);
    std::vector<float> out(kBlock);
    ScopedFlushDenormals ftz;
    for (int rep = 0; rep < repeats; ++rep) {
        HuntCrossleyImpactT<Real> impact;
        impact.configure(benchParams(s), benchModes(), {{1.0, 1.0, 1.0}});
        impact.prepare({kRate, kBlock});
        for (int b = 0; b < blocks; ++b) {
            const auto s0 = Clock::now();
            if (b % strikeEvery == 0) impact.strike(0.5);
            impact.process(nullptr, out.data(), kBlock);
            const double ns = std::chrono::duration<double, std::nano>(Clock::now() - s0).count();
            best[static_cast<std::size_t>(b)] = std::min(best[static_cast<std::size_t>(b)], ns);
        }
    }
    double total = 0;
    for (double ns : best) total += ns;
    m.nsPerSample = total / (double(blocks) * kBlock);
    std::sort(best.begin(), best.end());
    m.medianBlockNs = best[best.size() / 2];
    m.p99BlockNs = best[best.size() * 99 / 100];
    m.maxBlockNs = best.back();
}

std::vector<double> thirdOctaveLevels(const std::vector<float>& x, double fs) {
    const int n = static_cast<int>(x.size());
    double* in = fftw_alloc_real(static_cast<std::size_t>(n));
    fftw_complex* out = fftw_alloc_complex(static_cast<std::size_t>(n / 2 + 1));
    fftw_plan plan = fftw_plan_dft_r2c_1d(n, in, out, FFTW_ESTIMATE);
    for (int i = 0; i < n; ++i) in[i] = x[static_cast<std::size_t>(i)];
    fftw_execute(plan);
    std::vector<double> bands;
    for (double fc = 50.0; fc <= 16000.0; fc *= std::pow(2.0, 1.0 / 3.0)) {
        const double lo = fc / std::pow(2.0, 1.0 / 6.0), hi = fc * std::pow(2.0, 1.0 / 6.0);
        double e = 1e-30;
        for (int k = static_cast<int>(lo * n / fs);
             k <= static_cast<int>(hi * n / fs) && k <= n / 2; ++k)
            e += out[k][0] * out[k][0] + out[k][1] * out[k][1];
        bands.push_back(10 * std::log10(e));
    }
    fftw_destroy_plan(plan);
    fftw_free(in);
    fftw_free(out);
    return bands;
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
        {"explicit, 1x", ImpactSolver::Explicit, 1, 1, false},
        {"explicit, 4x", ImpactSolver::Explicit, 1, 4, false},
        {"Newton 1 it, 1x", ImpactSolver::Newton, 1, 1, false},
        {"Newton 2 it, 1x", ImpactSolver::Newton, 2, 1, false},
        {"Newton 4 it, 1x", ImpactSolver::Newton, 4, 1, false},
        {"Newton 6 it, 1x (default)", ImpactSolver::Newton, 6, 1, false},
        {"Newton 6 it, 2x", ImpactSolver::Newton, 6, 2, false},
        {"Newton 6 it, 4x", ImpactSolver::Newton, 6, 4, false},
        {"Newton 6 it, 1x, float state", ImpactSolver::Newton, 6, 1, true},
    };
}

ImpactMeasurement measureImpact(const ImpactSetting& setting, double seconds) {
    static const StrikeResult reference =
        strikeOnce<double>({"reference", ImpactSolver::Newton, 50, 8, false});
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

std::vector<SurfaceCost> measureSurfaceCosts(double seconds) {
    std::vector<SurfaceCost> out;
    WalkerParameters w;
    const GrfSignal grf = walkerGrf(w, seconds, kRate, 1);
    GrfSignal left = grf;
    left.channels.resize(1); // one voice
    left.names.resize(1);
    for (const auto& info : listSurfaces()) {
        RenderOptions options;
        options.blockSize = 256;
        // The fastest of three identical renders: other processes on a shared machine only ever
        // slow a run down.
        double cpu = 1e300;
        std::size_t frames = 0;
        for (int repeat = 0; repeat < 3; ++repeat) {
            const auto r = renderSurface(info.id, left, options);
            cpu = std::min(cpu, r.cpuSeconds);
            frames = r.audio.frames();
        }
        SurfaceCost c;
        c.id = info.id;
        c.realTimeFactor = double(frames) / kRate / cpu;
        c.nsPerSample = 1e9 * cpu / double(frames);
        out.push_back(c);
    }
    return out;
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
    {
        AccuracyOptions full;
        const auto ref = run("metal", full);
        for (int modes : {3, 6, 10, 14}) {
            AccuracyOptions a;
            a.maxModes = modes;
            const auto r = run("metal", a);
            out.push_back({"modes (metal, 14 in the preset)", std::to_string(modes),
                           spectralDistanceDb(left(r), left(ref), kRate),
                           1e9 * r.cpuSeconds / double(r.audio.frames())});
        }
    }
    {
        AccuracyOptions high;
        high.maxEventsPerSecond = 32000;
        const auto ref = run("gravel", high);
        for (int cap : {250, 1000, 4000, 32000}) {
            AccuracyOptions a;
            a.maxEventsPerSecond = cap;
            const auto r = run("gravel", a);
            out.push_back({"event cap (gravel, events/s per layer)", std::to_string(cap),
                           spectralDistanceDb(left(r), left(ref), kRate),
                           1e9 * r.cpuSeconds / double(r.audio.frames())});
        }
    }
    return out;
}

} // namespace underfoot::engine
