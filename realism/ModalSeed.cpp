// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/ModalSeed.h"

#include "realism/Descriptors.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace underfoot::realism {

std::vector<std::vector<Mode>> modesOfStrongestSteps(const std::string& path, int steps,
                                                     const ModalOptions& o, bool preEmphasis) {
    AnalysisOptions ao;
    ao.noiseFloorDb = 0; // the matrix pencil sees the recording as it is
    const auto audio = engine::readAudioFile(path);
    const auto x = analysisSignal(audio, ao);
    const auto spans = segmentSteps(x, ao.analysisRateHz, ao);
    if (spans.empty()) throw std::invalid_argument(fmt::format("{}: no step found", path));
    struct Peak {
        std::size_t at, end;
        float level;
    };
    std::vector<Peak> peaks;
    for (const auto& s : spans) {
        Peak p{s.begin, s.end, -1.0f};
        for (std::size_t i = s.begin; i < s.end && i < x.size(); ++i)
            if (std::fabs(x[i]) > p.level) p.level = std::fabs(x[i]), p.at = i;
        peaks.push_back(p);
    }
    std::stable_sort(peaks.begin(), peaks.end(),
                     [](const Peak& a, const Peak& b) { return a.level > b.level; });
    if (peaks.size() > std::size_t(std::max(steps, 1)))
        peaks.resize(std::size_t(std::max(steps, 1)));
    auto opt = o;
    opt.maxHz = std::min(o.maxHz, 0.95 * 0.5 * audio.sampleRateHz);
    std::vector<std::vector<Mode>> out;
    for (const auto& p : peaks) {
        std::vector<double> seg;
        for (std::size_t i = p.at;
             i < std::min(p.end, x.size()) && seg.size() < std::size_t(std::max(o.maxSamples, 0));
             ++i)
            seg.push_back(preEmphasis ? double(x[i]) - double(i > 0 ? x[i - 1] : 0.0f) : x[i]);
        try {
            auto modes = matrixPencilModes(seg, ao.analysisRateHz, opt);
            if (preEmphasis) {
                for (auto& m : modes)
                    m.amplitude /=
                        2 * std::sin(std::numbers::pi * m.frequencyHz / ao.analysisRateHz);
                std::stable_sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) {
                    return a.amplitude > b.amplitude;
                });
            }
            out.push_back(std::move(modes));
        } catch (const std::invalid_argument&) {
            // a step too short for the model order: the others still count
        }
    }
    if (out.empty())
        throw std::invalid_argument(
            fmt::format("{}: no step long enough for {} modes", path, o.modes));
    return out;
}

namespace {

// Weighted median of (value, weight) pairs (the smallest value whose cumulative weight reaches
// half the total).
double weightedMedian(std::vector<std::pair<double, double>> v) {
    std::sort(v.begin(), v.end());
    double total = 0;
    for (const auto& p : v) total += p.second;
    double acc = 0;
    for (const auto& p : v) {
        acc += p.second;
        if (acc >= 0.5 * total) return p.first;
    }
    return v.back().first;
}

} // namespace

std::vector<RecordedMode> aggregateModes(const std::vector<ModeObservation>& observations,
                                         const ModalSeedOptions& o) {
    struct Obs {
        double logF, t60, mass; // mass = weight x strength
        double weight;
        int step;
    };
    std::vector<Obs> obs;
    std::map<int, double> stepWeight; // a step's weight counts once in the support
    int own = -2;
    for (const auto& m : observations) {
        if (!(m.frequencyHz > 0) || !(m.t60S > 0) || !(m.strength > 0) || !(m.weight > 0) ||
            !std::isfinite(m.frequencyHz) || !std::isfinite(m.t60S) || !std::isfinite(m.strength) ||
            !std::isfinite(m.weight))
            continue;
        const int step = m.step >= 0 ? m.step : own--;
        obs.push_back({std::log2(m.frequencyHz), m.t60S, m.weight * m.strength, m.weight, step});
        stepWeight[step] = std::max(stepWeight[step], m.weight);
    }
    double totalWeight = 0;
    for (const auto& [step, w] : stepWeight) totalWeight += w;
    // Sorted by frequency so that ties resolve the same way whatever the input order.
    std::sort(obs.begin(), obs.end(), [](const Obs& a, const Obs& b) {
        return a.logF != b.logF ? a.logF < b.logF : a.t60 < b.t60;
    });
    const double k = std::max(o.kernelOctaves, 1e-3);
    std::vector<bool> used(obs.size(), false);
    std::vector<RecordedMode> out;
    while (int(out.size()) < o.maxModes) {
        // The densest remaining observation (kernel density of the weighted strength).
        int best = -1;
        double bestDensity = 0;
        for (std::size_t i = 0; i < obs.size(); ++i) {
            if (used[i]) continue;
            double d = 0;
            for (std::size_t j = 0; j < obs.size(); ++j)
                if (!used[j]) {
                    const double u = (obs[i].logF - obs[j].logF) / k;
                    if (std::fabs(u) < 6) d += obs[j].mass * std::exp(-0.5 * u * u);
                }
            if (d > bestDensity) bestDensity = d, best = int(i);
        }
        if (best < 0) break;
        const double centre = obs[std::size_t(best)].logF;
        std::vector<std::pair<double, double>> f, t;
        RecordedMode m;
        double mass = 0;
        std::map<int, double> found;
        for (std::size_t j = 0; j < obs.size(); ++j)
            if (!used[j] && std::fabs(obs[j].logF - centre) <= o.clusterOctaves) {
                used[j] = true;
                f.emplace_back(obs[j].logF, obs[j].mass);
                t.emplace_back(obs[j].t60, obs[j].mass);
                mass += obs[j].mass;
                found[obs[j].step] = std::max(found[obs[j].step], obs[j].weight);
                ++m.observations;
            }
        m.frequencyHz = std::exp2(weightedMedian(f));
        m.t60S = weightedMedian(t);
        m.gain = mass;
        double weight = 0;
        for (const auto& [step, w] : found) weight += w;
        m.support = totalWeight > 0 ? weight / totalWeight : 0;
        out.push_back(m);
    }
    double top = 0;
    for (const auto& m : out) top = std::max(top, m.gain);
    for (auto& m : out) m.gain = top > 0 ? m.gain / top : 0;
    std::sort(out.begin(), out.end(), [](const RecordedMode& a, const RecordedMode& b) {
        return a.frequencyHz < b.frequencyHz;
    });
    return out;
}

std::vector<RecordedMode> recordedModes(const std::vector<Recording>& recordings,
                                        const ModalSeedOptions& o,
                                        std::vector<std::string>* skipped) {
    ModalOptions mo;
    mo.modes = o.modesPerStep;
    mo.maxSamples = o.maxSamples;
    mo.minHz = o.minHz;
    // Files per source (a recording of unknown source is a source of its own).
    std::map<std::string, int> filesOf;
    auto sourceOf = [](const Recording& r) { return r.source.empty() ? r.path : r.source; };
    for (const auto& r : recordings) ++filesOf[sourceOf(r)];
    std::vector<ModeObservation> obs;
    int stepId = 0;
    for (const auto& r : recordings) {
        std::vector<std::vector<Mode>> steps;
        try {
            steps = modesOfStrongestSteps(r.path, o.stepsPerFile, mo, o.preEmphasis);
        } catch (const std::invalid_argument&) {
            if (skipped) skipped->push_back(r.file.empty() ? r.path : r.file);
            continue;
        }
        const double fileWeight = 1.0 / filesOf[sourceOf(r)];
        for (const auto& modes : steps) {
            if (modes.empty()) continue;
            const double top = modes.front().amplitude;
            for (const auto& m : modes)
                obs.push_back({m.frequencyHz, m.t60S, top > 0 ? m.amplitude / top : 0,
                               fileWeight / double(steps.size()), stepId});
            ++stepId;
        }
    }
    if (obs.empty()) throw std::runtime_error("modal seed: no recording yielded a mode");
    return aggregateModes(obs, o);
}

} // namespace underfoot::realism
