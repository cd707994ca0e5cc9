// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/NestedFit.h"

#include "base/TomlReader.h"

#include "engine/surfaces/Surface.h"

#include <fmt/core.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

namespace underfoot::realism {
namespace fs = std::filesystem;

std::vector<Recording> withoutSource(const std::vector<Recording>& recordings,
                                     const std::string& source) {
    std::vector<Recording> out;
    for (const auto& r : recordings)
        if (r.source != source) out.push_back(r);
    return out;
}

std::vector<RefitJob> refitJobs(const std::vector<std::pair<std::string, std::string>>& fittable,
                                const std::vector<Recording>& recordings) {
    std::vector<RefitJob> jobs;
    for (const auto& [id, material] : fittable) {
        std::set<std::string> sources;
        for (const auto& r : recordings)
            if (r.material == material) sources.insert(r.source);
        if (sources.size() < 2) continue; // without its only source the material has no recording
        for (const auto& held : sources) {
            RefitJob j{id, material, held, {}, {}};
            for (const auto& r : withoutSource(recordings, held))
                (r.material == material ? j.own : j.others).push_back(r);
            jobs.push_back(std::move(j));
        }
    }
    return jobs;
}

std::vector<std::pair<std::string, std::string>>
fittableSurfaces(const std::vector<Recording>& recordings) {
    std::set<std::string> recorded;
    for (const auto& r : recordings) recorded.insert(r.material);
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& info : engine::listSurfaces()) {
        const auto m = materialOfSurface(info.id);
        if (m.empty() || !recorded.count(m)) continue;
        if (base::parseTomlFile(info.file).get("base")) continue; // inherits its base's fit
        out.emplace_back(info.id, m);
    }
    return out;
}

namespace {
// Every job's fit, `threads` at a time, in job order.
std::vector<FitResult> runFits(const std::vector<RefitJob>& jobs, const NestedRefitOptions& o) {
    std::vector<FitResult> fits(jobs.size());
    std::atomic<std::size_t> next{0};
    std::size_t done = 0;
    std::mutex m;
    std::exception_ptr failure;
    const auto dir = fs::path(engine::surfacesDirectory());
    auto work = [&] {
        for (std::size_t i = next++; i < jobs.size(); i = next++) {
            try {
                FitOptions fo = o.fit;
                fo.progress = nullptr;
                fo.ownMaterial = jobs[i].material;
                fo.others = fo.contrast > 0 ? jobs[i].others : std::vector<Recording>{};
                fits[i] = fitSurface((dir / (jobs[i].surface + ".toml")).string(), jobs[i].own, fo);
                const std::lock_guard lock(m);
                ++done;
                if (o.progress) o.progress(done, jobs.size(), jobs[i], fits[i]);
            } catch (...) {
                const std::lock_guard lock(m);
                if (!failure) failure = std::current_exception();
                next = jobs.size();
            }
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < std::max(o.threads, 1); ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    return fits;
}

// A copy of the bundled surfaces with the presets refitted without `held` in place of theirs.
fs::path refittedFolder(const NestedRefit& n, const std::string& held) {
    static std::atomic<long> count{0};
    const auto dir =
        fs::temp_directory_path() /
        fmt::format("underfoot-nested-{}-{}", static_cast<long>(::getpid()), count.fetch_add(1));
    fs::create_directories(dir);
    for (const auto& e : fs::directory_iterator(engine::surfacesDirectory()))
        if (e.path().extension() == ".toml")
            fs::copy_file(e.path(), dir / e.path().filename(),
                          fs::copy_options::overwrite_existing);
    for (std::size_t i = 0; i < n.jobs.size(); ++i)
        if (n.jobs[i].heldOut == held) {
            std::ofstream out(dir / (n.jobs[i].surface + ".toml"));
            out << n.fits[i].presetText;
            if (!out) throw std::runtime_error(fmt::format("cannot write {}", dir.string()));
        }
    return dir;
}
} // namespace

NestedRefit nestedRefit(const std::vector<Recording>& recordings,
                        const std::vector<Example>& examples, const AnalysisOptions& analysis,
                        const NestedRefitOptions& o) {
    NestedRefit n;
    n.jobs = refitJobs(fittableSurfaces(recordings), recordings);
    n.fits = runFits(n.jobs, o);
    std::set<std::string> sources;
    for (const auto& e : examples) sources.insert(e.source);
    const auto infos = engine::listSurfaces();
    for (const auto& held : sources) {
        const auto dir = refittedFolder(n, held);
        std::vector<Example> synth;
        std::vector<std::string> ids;
        for (const auto& info : infos) {
            auto e =
                renderExample(info.id, (dir / (info.id + ".toml")).string(), o.render, analysis);
            if (!e) continue;
            synth.push_back(std::move(*e));
            ids.push_back(info.id);
        }
        fs::remove_all(dir);
        if (n.surfaces.empty()) n.surfaces = ids;
        if (ids != n.surfaces)
            throw std::runtime_error(
                fmt::format("nested refit: without {} another set of renders has steps", held));
        n.heard[held] = heardWithoutSource(examples, synth, held, o.listener);
    }
    return n;
}

} // namespace underfoot::realism
