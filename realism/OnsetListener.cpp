// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/OnsetListener.h"

#include "realism/Distance.h"
#include "realism/OnsetFeatures.h"
#include "realism/Recordings.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace underfoot::realism {
namespace {

double floorOf(std::size_t k) {
    if (k < kDescriptorCount) return descriptorInfo(int(k)).floor;
    return onsetFeatureInfo().at(k - kDescriptorCount).floor;
}

double spreadOf(const std::vector<double>& v, std::size_t k) {
    return std::max((quantile(v, 0.75) - quantile(v, 0.25)) / 1.349, floorOf(k));
}

// Per-feature median over a file's steps.
std::vector<double> fileVector(const ListenerFile& f) {
    if (f.steps.empty()) throw std::invalid_argument(fmt::format("{}: no steps", f.name));
    std::vector<double> out(f.steps.front().size());
    for (std::size_t k = 0; k < out.size(); ++k) {
        std::vector<double> v;
        for (const auto& s : f.steps) v.push_back(s.at(k));
        out[k] = quantile(v, 0.5);
    }
    return out;
}

double distance2(const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0;
    for (std::size_t k = 0; k < a.size(); ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
    return d;
}

const char* toString(FeatureSet f) {
    switch (f) {
    case FeatureSet::Onset:
        return "onset";
    case FeatureSet::OnsetAndScalars:
        return "onset+scalars";
    case FeatureSet::Scalars:
        return "scalars";
    }
    return "?";
}

const char* toString(Decision d) {
    switch (d) {
    case Decision::Centroid:
        return "centroid";
    case Decision::Hierarchical:
        return "hierarchical";
    case Decision::NearestNeighbours:
        return "3-nn";
    case Decision::StepVote:
        return "step-vote";
    }
    return "?";
}

} // namespace

std::size_t listenerFeatureCount() {
    return kDescriptorCount + onsetFeatureInfo().size();
}

std::string listenerFeatureKey(std::size_t k) {
    if (k < kDescriptorCount) return descriptorInfo(int(k)).key;
    return onsetFeatureInfo().at(k - kDescriptorCount).key;
}

ListenerFile describeListenerFile(const std::string& name, const std::string& source,
                                  const std::string& material, const engine::AudioBuffer& audio,
                                  const AnalysisOptions& o) {
    ListenerFile f{name, source, material, {}};
    const auto x = analysisSignal(audio, o);
    for (const auto& span : segmentSteps(x, o.analysisRateHz, o)) {
        std::vector<double> v;
        try {
            const auto d = describeStep(x, o.analysisRateHz, span, o);
            for (int k = 0; k < kDescriptorCount; ++k)
                v.push_back(comparisonScale(k, d.value[static_cast<std::size_t>(k)]));
            const auto on = onsetFeatures(x, o.analysisRateHz, span, o);
            v.insert(v.end(), on.begin(), on.end());
        } catch (const std::invalid_argument&) {
            continue; // silent in the analysed band, as describeSteps
        }
        f.steps.push_back(std::move(v));
    }
    if (f.steps.empty()) throw std::invalid_argument(fmt::format("{}: no step found", name));
    return f;
}

std::string ListenerConfig::name() const {
    return fmt::format("{}/{}/{}", toString(features),
                       standardisePerSource ? "standardised" : "centred", toString(decision));
}

std::vector<ListenerConfig> listenerGrid() {
    std::vector<ListenerConfig> g;
    for (auto f : {FeatureSet::Onset, FeatureSet::OnsetAndScalars, FeatureSet::Scalars})
        for (bool z : {false, true})
            for (auto d : {Decision::Centroid, Decision::Hierarchical, Decision::NearestNeighbours,
                           Decision::StepVote})
                g.push_back({f, z, d});
    return g;
}

void normaliseBySource(std::vector<ListenerFile>& files, bool standardise) {
    std::set<std::string> sources;
    for (const auto& f : files) sources.insert(f.source);
    for (const auto& s : sources) {
        std::vector<std::vector<double>> vecs;
        for (const auto& f : files)
            if (f.source == s) vecs.push_back(fileVector(f));
        const std::size_t n = vecs.front().size();
        std::vector<double> med(n), sc(n, 1.0);
        for (std::size_t k = 0; k < n; ++k) {
            std::vector<double> v;
            for (const auto& x : vecs) v.push_back(x.at(k));
            med[k] = quantile(v, 0.5);
            if (standardise) sc[k] = spreadOf(v, k);
        }
        for (auto& f : files)
            if (f.source == s)
                for (auto& st : f.steps)
                    for (std::size_t k = 0; k < n; ++k) st.at(k) = (st.at(k) - med[k]) / sc[k];
    }
}

std::vector<double> OnsetListener::select(const std::vector<double>& v) const {
    if (v.size() != centre_.size())
        throw std::invalid_argument(fmt::format(
            "features of length {}, the listener was trained on {}", v.size(), centre_.size()));
    std::vector<double> z;
    for (std::size_t k : features_) z.push_back((v[k] - centre_[k]) / scale_[k]);
    return z;
}

void OnsetListener::train(const std::vector<ListenerFile>& files) {
    if (files.empty()) throw std::invalid_argument("the listener needs at least one example");
    const std::size_t n = files.front().steps.empty() ? 0 : files.front().steps.front().size();
    std::vector<std::vector<double>> vecs;
    for (const auto& f : files) {
        if (f.material.empty())
            throw std::invalid_argument(fmt::format("{}: no material label", f.name));
        for (const auto& s : f.steps)
            if (s.size() != n)
                throw std::invalid_argument(fmt::format("{}: steps of another length", f.name));
        vecs.push_back(fileVector(f));
    }
    features_.clear();
    for (std::size_t k = 0; k < n; ++k) {
        const bool scalar = k < kDescriptorCount;
        if ((cfg_.features == FeatureSet::Onset && !scalar) ||
            (cfg_.features == FeatureSet::Scalars && scalar) ||
            cfg_.features == FeatureSet::OnsetAndScalars)
            features_.push_back(k);
    }
    centre_.assign(n, 0.0);
    scale_.assign(n, 1.0);
    for (std::size_t k = 0; k < n; ++k) {
        std::vector<double> v;
        for (const auto& x : vecs) v.push_back(x[k]);
        centre_[k] = quantile(v, 0.5);
        scale_[k] = spreadOf(v, k);
    }
    std::vector<std::vector<double>> z;
    for (const auto& x : vecs) z.push_back(select(x));
    std::set<std::string> mats;
    std::set<std::pair<std::string, std::string>> groups, catGroups; // (label, source)
    for (const auto& f : files) {
        mats.insert(f.material);
        groups.insert({f.material, f.source});
        catGroups.insert({categoryOfMaterial(f.material), f.source});
    }
    materials_.assign(mats.begin(), mats.end());
    auto centroid = [&](auto belongs) {
        std::vector<double> c(features_.size());
        for (std::size_t k = 0; k < c.size(); ++k) {
            std::vector<double> v;
            for (std::size_t i = 0; i < files.size(); ++i)
                if (belongs(files[i])) v.push_back(z[i][k]);
            c[k] = quantile(v, 0.5);
        }
        return c;
    };
    centroids_.clear();
    // (the group's fields as plain references: clang 14 cannot capture structured bindings)
    for (const auto& group : groups) {
        const auto& m = group.first;
        const auto& src = group.second;
        centroids_.push_back({m, categoryOfMaterial(m), centroid([&](const ListenerFile& f) {
                                  return f.material == m && f.source == src;
                              })});
    }
    categoryCentroids_.clear();
    for (const auto& group : catGroups) {
        const auto& c = group.first;
        const auto& src = group.second;
        categoryCentroids_.push_back({"", c, centroid([&](const ListenerFile& f) {
                                          return categoryOfMaterial(f.material) == c &&
                                                 f.source == src;
                                      })});
    }
    train_.clear();
    for (std::size_t i = 0; i < files.size(); ++i) train_.push_back({files[i].material, z[i]});
}

std::pair<std::string, double> OnsetListener::nearest(const std::vector<double>& z,
                                                      const std::string& category) const {
    std::pair<std::string, double> best{"", 1e300};
    for (const auto& c : centroids_) {
        if (!category.empty() && c.category != category) continue;
        const double d = distance2(z, c.z);
        if (d < best.second) best = {c.material, d};
    }
    return best;
}

std::string OnsetListener::classify(const ListenerFile& file) const {
    if (materials_.empty()) throw std::logic_error("the listener is not trained");
    const auto z = select(fileVector(file));
    switch (cfg_.decision) {
    case Decision::Centroid:
        return nearest(z, "").first;
    case Decision::Hierarchical: {
        std::pair<std::string, double> cat{"", 1e300};
        for (const auto& c : categoryCentroids_) {
            const double d = distance2(z, c.z);
            if (d < cat.second) cat = {c.category, d};
        }
        return nearest(z, cat.first).first;
    }
    case Decision::NearestNeighbours: {
        std::vector<std::pair<double, std::size_t>> d;
        for (std::size_t i = 0; i < train_.size(); ++i)
            d.push_back({distance2(z, train_[i].second), i});
        std::sort(d.begin(), d.end());
        std::map<std::string, int> votes;
        const std::size_t k = std::min<std::size_t>(3, d.size());
        for (std::size_t i = 0; i < k; ++i) ++votes[train_[d[i].second].first];
        std::string best = train_[d[0].second].first; // ties: the nearest
        for (const auto& [m, v] : votes)
            if (v > votes[best]) best = m;
        return best;
    }
    case Decision::StepVote: {
        std::map<std::string, std::pair<int, double>> votes; // material -> (votes, sum distance)
        for (const auto& s : file.steps) {
            const auto [m, d] = nearest(select(s), "");
            ++votes[m].first;
            votes[m].second += std::sqrt(d);
        }
        std::string best;
        std::pair<int, double> bv{-1, 0};
        for (const auto& [m, v] : votes)
            if (v.first > bv.first || (v.first == bv.first && v.second < bv.second)) {
                best = m;
                bv = v;
            }
        return best;
    }
    }
    return {};
}

namespace {
// Trains on every (normalised) file but the held-out source's and scores those into r.
void scoreHeldOut(const std::vector<ListenerFile>& files, const std::string& held,
                  const ListenerConfig& c, LosoResult& r) {
    std::vector<ListenerFile> train;
    for (const auto& f : files)
        if (f.source != held) train.push_back(f);
    OnsetListener l(c);
    l.train(train);
    const auto& mats = l.materials();
    for (const auto& f : files) {
        if (f.source != held) continue;
        if (std::find(mats.begin(), mats.end(), f.material) == mats.end()) {
            ++r.unseenMaterialFiles;
            continue;
        }
        r.score(held, f.material, l.classify(f));
    }
}
} // namespace

LosoResult leaveOneSourceOut(const std::vector<ListenerFile>& input, const ListenerConfig& c) {
    std::vector<ListenerFile> files = input;
    normaliseBySource(files, c.standardisePerSource);
    std::set<std::string> sources;
    for (const auto& f : files) sources.insert(f.source);
    if (sources.size() < 2)
        throw std::invalid_argument(
            "leave-one-source-out needs recordings from two sources or more");
    LosoResult r;
    for (const auto& held : sources) scoreHeldOut(files, held, c, r);
    return r;
}

ListenerConfig chooseConfig(const std::vector<ListenerFile>& files,
                            const std::vector<ListenerConfig>& grid) {
    if (grid.empty()) throw std::invalid_argument("an empty grid of listener configurations");
    ListenerConfig best = grid.front();
    std::pair<int, int> bestScore{-1, -1};
    for (const auto& c : grid) {
        const auto r = leaveOneSourceOut(files, c);
        const std::pair<int, int> score{r.categoryCorrect, r.materialCorrect};
        if (score > bestScore) {
            bestScore = score;
            best = c;
        }
    }
    return best;
}

NestedResult nestedLeaveOneSourceOut(const std::vector<ListenerFile>& files,
                                     const std::vector<ListenerConfig>& grid) {
    std::set<std::string> sources;
    for (const auto& f : files) sources.insert(f.source);
    if (sources.size() < 3)
        throw std::invalid_argument("the nested estimate needs recordings from three sources or "
                                    "more (the configuration is chosen on two or more)");
    NestedResult out;
    for (const auto& held : sources) {
        std::vector<ListenerFile> inner;
        for (const auto& f : files)
            if (f.source != held) inner.push_back(f);
        const auto c = chooseConfig(inner, grid);
        out.chosen[held] = c;
        auto all = files; // normalised by source as leaveOneSourceOut does
        normaliseBySource(all, c.standardisePerSource);
        scoreHeldOut(all, held, c, out.heldOut);
    }
    return out;
}

} // namespace underfoot::realism
