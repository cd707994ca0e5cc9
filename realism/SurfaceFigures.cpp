// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/SurfaceFigures.h"

#include "engine/surfaces/Surface.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <iterator>
#include <set>
#include <stdexcept>

namespace underfoot::realism {

std::vector<SurfaceUnderTest> bundledSurfaces() {
    std::vector<SurfaceUnderTest> out;
    for (const auto& info : engine::listSurfaces())
        out.push_back({info.id, materialOfSurface(info.id), engine::toString(info.category)});
    return out;
}

void scoreNested(const std::vector<SurfaceUnderTest>& surfaces,
                 const std::map<std::string, std::vector<std::string>>& heard,
                 const std::map<std::string, std::set<std::string>>& recorded,
                 std::vector<SurfaceFigures>& out) {
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        auto& f = out.at(i);
        f.surface = surfaces[i].surface;
        f.material = surfaces[i].material;
        f.category = surfaces[i].category;
        f.sources = f.categoryRight = f.materialRight = 0;
        f.heardWithout.clear();
        const auto& mat = surfaces[i].material;
        for (const auto& [source, h] : heard) {
            const auto& verdict = h.at(i);
            const auto r = recorded.find(source);
            const bool scored = !mat.empty() && r != recorded.end() && r->second.count(mat) > 0;
            f.heardWithout.push_back({source, verdict, scored, {}});
            if (!scored) continue;
            ++f.sources;
            f.categoryRight += categoryOfMaterial(verdict) == surfaces[i].category;
            f.materialRight += verdict == mat;
        }
    }
}

void addHeldOutRecordings(const std::map<std::string, std::map<std::string, JudgedCounts>>& own,
                          std::vector<SurfaceFigures>& figures) {
    for (auto& f : figures)
        for (auto& v : f.heardWithout) {
            v.recordings = {};
            if (!v.scored) continue;
            const auto s = own.find(v.source);
            if (s == own.end()) continue;
            const auto m = s->second.find(f.material);
            if (m != s->second.end()) v.recordings = m->second;
        }
}

bool SurfaceOverSeeds::alwaysInCategory() const {
    for (const auto& s : sources)
        if (s.seedsInCategory != s.seeds) return false;
    return true;
}

bool SurfaceOverSeeds::atLeastAsOftenAsRecordings() const {
    for (const auto& s : sources)
        if (!s.atLeastAsOftenAsRecordings()) return false;
    return true;
}

std::vector<SurfaceOverSeeds> overSeeds(const std::vector<SurfaceFigures>& figures) {
    std::vector<SurfaceOverSeeds> out;
    for (const auto& f : figures) {
        auto it = std::find_if(out.begin(), out.end(),
                               [&](const SurfaceOverSeeds& s) { return s.surface == f.surface; });
        if (it == out.end()) {
            out.push_back({f.surface, {}});
            it = std::prev(out.end());
        }
        for (const auto& v : f.heardWithout) {
            if (!v.scored) continue;
            auto src =
                std::find_if(it->sources.begin(), it->sources.end(),
                             [&](const HeldOutOverSeeds& h) { return h.source == v.source; });
            if (src == it->sources.end()) {
                it->sources.push_back({v.source, 0, 0, v.recordings});
                src = std::prev(it->sources.end());
            }
            ++src->seeds;
            src->seedsInCategory += categoryOfMaterial(v.heard) == f.category;
        }
    }
    return out;
}

namespace {

double cpuSeconds() {
    return double(std::clock()) / CLOCKS_PER_SEC;
}

// The recordings of each material described once per room (a surface with a room hears them
// through it), with the band compareAudio uses for them: what `compare --all` computes, without
// describing every recording again for every surface.
class RecordedSteps {
  public:
    RecordedSteps(const std::vector<Recording>& recordings, double renderRateHz)
        : rate_(renderRateHz) {
        for (const auto& r : recordings) byMaterial_[r.material].push_back(r);
    }
    const std::map<std::string, std::vector<Recording>>& materials() const { return byMaterial_; }

    struct Described {
        AnalysisOptions options;
        std::vector<StepDescriptors> steps;
    };
    const Described& of(const std::string& material,
                        const std::optional<engine::ReverbSpec>& room) {
        const auto key =
            material + "\n" +
            (room ? fmt::format("{}|{}|{}", room->impulseResponse, room->wetDb, room->dryDb)
                  : std::string());
        auto it = cache_.find(key);
        if (it != cache_.end()) return it->second;
        Described d;
        const auto& recs = byMaterial_.at(material);
        d.options.maxHz = sharedMaxHz(recs, rate_);
        d.steps = describeRecordings(recs, d.options, room);
        if (d.steps.empty())
            throw std::runtime_error(
                fmt::format("no footstep found in the {} recordings (all silent?)", material));
        return cache_.emplace(key, std::move(d)).first->second;
    }

  private:
    double rate_;
    std::map<std::string, std::vector<Recording>> byMaterial_;
    std::map<std::string, Described> cache_;
};

} // namespace

std::vector<SurfaceFigures> surfaceFigures(const std::vector<SurfaceUnderTest>& surfaces,
                                           const std::vector<Recording>& recordings,
                                           const SurfaceFiguresOptions& o) {
    if (surfaces.empty()) throw std::invalid_argument("surfaceFigures: no surface to judge");
    if (o.seeds.empty()) throw std::invalid_argument("surfaceFigures: no render seed");
    // The listener's recordings: one feature vector per file on the band all of them share.
    AnalysisOptions listenerBand;
    listenerBand.maxHz = sharedMaxHz(recordings, o.spec.rateHz);
    // As `compare --listener`: a file in which no step is found is left out.
    const auto examples = recordingExamples(recordings, listenerBand);
    std::map<std::string, std::set<std::string>> recorded;
    for (const auto& e : examples) recorded[e.source].insert(e.material);
    if (recorded.size() < 2)
        throw std::invalid_argument("surfaceFigures: the recordings need two sources or more");
    RecordedSteps real(recordings, o.spec.rateHz);
    std::vector<std::optional<engine::ReverbSpec>> rooms;
    for (const auto& s : surfaces)
        rooms.push_back(o.dryRecordings ? std::nullopt : roomOfSurface(s.surface));

    const auto ownHeard = heldOutRecordings(examples, o.listener);
    std::vector<SurfaceFigures> all;
    for (const auto seed : o.seeds) {
        RenderSpec spec = o.spec;
        spec.seed = seed;
        std::vector<SurfaceFigures> figs(surfaces.size());
        std::vector<Example> renders;
        for (std::size_t i = 0; i < surfaces.size(); ++i) {
            const auto& s = surfaces[i];
            auto& f = figs[i];
            f.surface = s.surface;
            f.material = s.material;
            f.category = s.category;
            f.seed = seed;
            const double t0 = cpuSeconds();
            const auto audio = renderForComparison(s.surface, spec);
            f.nanosecondsPerFrame =
                1e9 * (cpuSeconds() - t0) / double(std::max<std::size_t>(audio.frames(), 1));
            const auto steps = describeSteps(audio, listenerBand);
            if (steps.empty())
                throw std::runtime_error(
                    fmt::format("{}: the render holds no footstep", s.surface));
            renders.push_back({s.surface, "synthetic", s.material, fileFeatures(steps)});
            if (s.material.empty() || !real.materials().count(s.material)) continue;
            // Distances to every recorded material, as `compare --all`.
            std::map<double, std::vector<StepDescriptors>> rendered; // by band limit
            f.hasRecordings = true;
            f.ownDistance = 0;
            f.nearestOtherDistance = 1e300;
            for (const auto& [mat, recs] : real.materials()) {
                const auto& d = real.of(mat, rooms[i]);
                auto& syn = rendered[d.options.maxHz];
                if (syn.empty()) syn = describeSteps(audio, d.options);
                if (syn.empty())
                    throw std::runtime_error(
                        fmt::format("{}: the render holds no footstep", s.surface));
                const auto c = compareSteps(syn, d.steps);
                if (mat == s.material) {
                    f.ownDistance = c.distance;
                    f.flatness = c.d[kFlatness];
                    f.centroid = c.d[kCentroid];
                } else if (c.distance < f.nearestOtherDistance) {
                    f.nearestOtherDistance = c.distance;
                    f.nearestOther = mat;
                }
            }
            if (f.nearestOther.empty()) f.nearestOtherDistance = 0;
        }
        scoreNested(surfaces, heardWithoutEachSource(examples, renders, o.listener), recorded,
                    figs);
        addHeldOutRecordings(ownHeard, figs);
        all.insert(all.end(), figs.begin(), figs.end());
    }
    return all;
}

} // namespace underfoot::realism
