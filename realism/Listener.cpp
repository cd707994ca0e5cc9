// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Listener.h"

#include "realism/Distance.h"
#include "realism/Recordings.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace underfoot::realism {

std::vector<double> fileFeatures(const std::vector<StepDescriptors>& steps) {
    if (steps.empty()) throw std::invalid_argument("a file without steps has no features");
    std::vector<double> f;
    for (int d = 0; d < kDescriptorCount; ++d) {
        std::vector<double> v;
        for (const auto& s : steps)
            v.push_back(comparisonScale(d, s.value[static_cast<std::size_t>(d)]));
        f.push_back(quantile(v, 0.5));
    }
    const std::size_t bands = steps.front().thirdOctaveDb.size();
    for (std::size_t b = 0; b < bands; ++b) {
        std::vector<double> v;
        for (const auto& s : steps) v.push_back(s.thirdOctaveDb.at(b));
        f.push_back(quantile(v, 0.5));
    }
    return f;
}

std::vector<Example> recordingExamples(const std::vector<Recording>& recordings,
                                       const AnalysisOptions& o, std::vector<std::string>* silent) {
    std::vector<Example> out;
    for (const auto& r : recordings) {
        const auto steps = describeFile(r.path, o);
        if (steps.empty()) {
            if (silent) silent->push_back(r.file);
            continue;
        }
        out.push_back({r.file, r.source, r.material, fileFeatures(steps)});
    }
    return out;
}

void centreBySource(std::vector<Example>& ex) {
    std::set<std::string> sources;
    for (const auto& e : ex) sources.insert(e.source);
    for (const auto& s : sources) {
        std::size_t n = 0;
        for (const auto& e : ex)
            if (e.source == s) n = std::max(n, e.features.size());
        std::vector<double> med(n);
        for (std::size_t k = 0; k < n; ++k) {
            std::vector<double> v;
            for (const auto& e : ex)
                if (e.source == s && k < e.features.size()) v.push_back(e.features[k]);
            med[k] = quantile(v, 0.5);
        }
        for (auto& e : ex)
            if (e.source == s)
                for (std::size_t k = 0; k < e.features.size(); ++k) e.features[k] -= med[k];
    }
}

void Listener::train(const std::vector<Example>& ex) {
    if (ex.empty()) throw std::invalid_argument("the listener needs at least one example");
    const std::size_t n = ex.front().features.size();
    for (const auto& e : ex)
        if (e.features.size() != n || e.material.empty())
            throw std::invalid_argument(
                fmt::format("example {}: features of another length or no material label", e.name));
    centre_.assign(n, 0);
    scale_.assign(n, 1);
    weight_.assign(n, 1);
    const std::size_t bands = n > kDescriptorCount ? n - kDescriptorCount : 0;
    for (std::size_t k = 0; k < n; ++k) {
        std::vector<double> v;
        for (const auto& e : ex) v.push_back(e.features[k]);
        centre_[k] = quantile(v, 0.5);
        const double floor = k < kDescriptorCount ? descriptorInfo(int(k)).floor : 1.0;
        scale_[k] = std::max((quantile(v, 0.75) - quantile(v, 0.25)) / 1.349, floor);
        if (k >= kDescriptorCount && bands > 0)
            weight_[k] =
                opt_.scalarsOnly ? 0.0 : std::sqrt(double(kDescriptorCount) / double(bands));
    }
    std::set<std::string> mats;
    std::set<std::pair<std::string, std::string>> groups; // (material, source)
    for (const auto& e : ex) {
        mats.insert(e.material);
        groups.insert({e.material, opt_.centroidPerSource ? e.source : std::string()});
    }
    materials_.assign(mats.begin(), mats.end());
    centroids_.clear();
    centroidMaterial_.clear();
    for (const auto& [m, src] : groups) {
        std::vector<double> c(n);
        for (std::size_t k = 0; k < n; ++k) {
            std::vector<double> v;
            for (const auto& e : ex)
                if (e.material == m && (src.empty() || e.source == src))
                    v.push_back((e.features[k] - centre_[k]) / scale_[k]);
            c[k] = quantile(v, 0.5);
        }
        centroids_.push_back(std::move(c));
        centroidMaterial_.push_back(m);
    }
}

std::vector<std::pair<std::string, double>>
Listener::distances(const std::vector<double>& f) const {
    if (f.size() != centre_.size())
        throw std::invalid_argument(fmt::format(
            "features of length {}, the listener was trained on {}", f.size(), centre_.size()));
    std::map<std::string, double> best; // material -> distance to its nearest centroid
    for (std::size_t m = 0; m < centroids_.size(); ++m) {
        double d2 = 0;
        for (std::size_t k = 0; k < f.size(); ++k) {
            const double z = ((f[k] - centre_[k]) / scale_[k] - centroids_[m][k]) * weight_[k];
            d2 += z * z;
        }
        const double d = std::sqrt(d2);
        auto [it, fresh] = best.emplace(centroidMaterial_[m], d);
        if (!fresh) it->second = std::min(it->second, d);
    }
    std::vector<std::pair<std::string, double>> out(best.begin(), best.end());
    std::stable_sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.second < b.second; });
    return out;
}

std::string Listener::classify(const std::vector<double>& f) const {
    if (materials_.empty()) throw std::logic_error("the listener is not trained");
    return distances(f).front().first;
}

void LosoResult::score(const std::string& source, const std::string& material,
                       const std::string& heard) {
    ++confusion[material][heard];
    ++files;
    auto& ps = perSource[source];
    ++ps.second;
    if (heard == material) {
        ++materialCorrect;
        ++ps.first;
    }
    if (categoryOfMaterial(heard) == categoryOfMaterial(material)) {
        ++categoryCorrect;
        ++perSourceCategory[source];
    }
}

namespace {
// The sources of (labelled) examples; throws std::invalid_argument with fewer than two.
std::set<std::string> twoSourcesOrMore(const std::vector<Example>& ex, const char* who) {
    std::set<std::string> sources;
    for (const auto& e : ex) sources.insert(e.source);
    if (sources.size() < 2)
        throw std::invalid_argument(
            fmt::format("{} needs recordings from two sources or more", who));
    return sources;
}

// A listener trained on the examples (already centred when the options say so) of every source
// but `held`.
Listener trainedWithout(const std::vector<Example>& ex, const std::string& held,
                        ListenerOptions o) {
    std::vector<Example> train;
    for (const auto& e : ex)
        if (e.source != held) train.push_back(e);
    Listener l(o);
    l.train(train);
    return l;
}

// Every labelled file of every source S judged by the listener trained without S (examples
// centred by source first when the options say so): judge(file, heard, seen), seen false for a
// material no other source recorded. Throws std::invalid_argument with fewer than two sources.
template <typename Judge>
void judgeEachSourceWithout(const std::vector<Example>& input, ListenerOptions o, const char* who,
                            Judge judge) {
    std::vector<Example> ex = input;
    if (o.centrePerSource) centreBySource(ex);
    for (const auto& held : twoSourcesOrMore(ex, who)) {
        const Listener l = trainedWithout(ex, held, o);
        const auto& mats = l.materials();
        for (const auto& e : ex) {
            if (e.source != held) continue;
            judge(e, l.classify(e.features),
                  std::find(mats.begin(), mats.end(), e.material) != mats.end());
        }
    }
}
} // namespace

LosoResult leaveOneSourceOut(const std::vector<Example>& input, ListenerOptions o) {
    LosoResult r;
    judgeEachSourceWithout(input, o, "leave-one-source-out",
                           [&](const Example& e, const std::string& heard, bool seen) {
                               if (seen)
                                   r.score(e.source, e.material, heard);
                               else
                                   ++r.unseenMaterialFiles;
                           });
    return r;
}

std::vector<std::string> heardWithoutSource(const std::vector<Example>& recordings,
                                            const std::vector<Example>& renders,
                                            const std::string& heldOut, ListenerOptions o) {
    if (renders.empty()) throw std::invalid_argument("heardWithoutSource: no render to judge");
    std::vector<Example> ex = recordings, synth = renders;
    if (o.centrePerSource) {
        centreBySource(ex);
        centreBySource(synth);
    }
    const auto sources = twoSourcesOrMore(ex, "heardWithoutSource");
    if (!sources.count(heldOut))
        throw std::invalid_argument(
            fmt::format("heardWithoutSource: no recording of source \"{}\"", heldOut));
    const Listener l = trainedWithout(ex, heldOut, o);
    std::vector<std::string> heard;
    for (const auto& r : synth) heard.push_back(l.classify(r.features));
    return heard;
}

std::map<std::string, std::vector<std::string>>
heardWithoutEachSource(const std::vector<Example>& recordings, const std::vector<Example>& renders,
                       ListenerOptions o) {
    std::map<std::string, std::vector<std::string>> heard;
    for (const auto& held : twoSourcesOrMore(recordings, "heardWithoutEachSource"))
        heard[held] = heardWithoutSource(recordings, renders, held, o);
    return heard;
}

void JudgedCounts::add(const std::string& material, const std::string& heard) {
    ++files;
    categoryRight += categoryOfMaterial(heard) == categoryOfMaterial(material);
    materialRight += heard == material;
}

std::map<std::string, std::map<std::string, JudgedCounts>>
heldOutRecordings(const std::vector<Example>& input, ListenerOptions o) {
    std::map<std::string, std::map<std::string, JudgedCounts>> counts;
    judgeEachSourceWithout(input, o, "heldOutRecordings",
                           [&](const Example& e, const std::string& heard, bool) {
                               counts[e.source][e.material].add(e.material, heard);
                           });
    return counts;
}

std::map<std::string, OneSourceFigures>
trainedOnEachSource(const std::vector<Example>& recordings, const std::vector<Example>& renders,
                    const std::vector<std::string>& renderMaterials, ListenerOptions o) {
    if (renders.size() != renderMaterials.size())
        throw std::invalid_argument(
            fmt::format("trainedOnEachSource: {} renders but {} render materials", renders.size(),
                        renderMaterials.size()));
    std::vector<Example> ex = recordings, synth = renders;
    if (o.centrePerSource) {
        centreBySource(ex);
        centreBySource(synth);
    }
    std::map<std::string, OneSourceFigures> out;
    for (const auto& only : twoSourcesOrMore(ex, "trainedOnEachSource")) {
        std::vector<Example> train;
        std::set<std::string> mats;
        for (const auto& e : ex)
            if (e.source == only) {
                train.push_back(e);
                mats.insert(e.material);
            }
        if (mats.size() < 2) continue; // a listener of one material hears nothing else
        Listener l(o);
        l.train(train);
        auto& f = out[only];
        for (const auto& e : ex)
            if (e.source != only && mats.count(e.material))
                f.recordings[e.material].add(e.material, l.classify(e.features));
        f.heard.assign(synth.size(), std::string());
        for (std::size_t i = 0; i < synth.size(); ++i) {
            if (!mats.count(renderMaterials[i])) continue;
            f.heard[i] = l.classify(synth[i].features);
            f.renders[renderMaterials[i]].add(renderMaterials[i], f.heard[i]);
        }
    }
    return out;
}

} // namespace underfoot::realism
