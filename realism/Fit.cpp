// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Fit.h"
#include "base/TomlReader.h"
#include "base/Version.h"
#include "realism/FitPreset.h"

#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"

#include <boost/random/sobol.hpp>
#include <fmt/core.h>
#include <nlopt.hpp>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace underfoot::realism {
namespace fs = std::filesystem;

namespace {

double peakOf(const engine::AudioBuffer& a) {
    double p = 0;
    for (float v : a.samples) p = std::max(p, std::fabs(double(v)));
    return p;
}

} // namespace

std::vector<std::vector<double>> fitStartPoints(int count, const std::vector<double>& lo,
                                                const std::vector<double>& hi) {
    if (count < 1) throw std::invalid_argument(fmt::format("fit: {} starts: expected >= 1", count));
    if (lo.size() != hi.size() || lo.empty())
        throw std::invalid_argument("fit: starting points need one [lo, hi] per knob");
    for (std::size_t i = 0; i < lo.size(); ++i)
        if (!(lo[i] <= 0 && 0 <= hi[i]))
            throw std::invalid_argument(
                fmt::format("fit: knob {}'s box [{}, {}] does not hold 0", i, lo[i], hi[i]));
    std::vector<std::vector<double>> points{std::vector<double>(lo.size(), 0.0)};
    if (count == 1) return points;
    boost::random::sobol sobol(lo.size()); // the first point is the box's centre
    const double range = static_cast<double>(sobol.max()) - static_cast<double>(sobol.min()) + 1;
    for (int p = 1; p < count; ++p) {
        std::vector<double> x(lo.size());
        for (std::size_t i = 0; i < lo.size(); ++i)
            x[i] = lo[i] + (hi[i] - lo[i]) * (static_cast<double>(sobol() - sobol.min()) / range);
        points.push_back(std::move(x));
    }
    return points;
}

double contrastiveObjective(double own, double nearest, double contrast, double margin) {
    if (contrast <= 0 || nearest < 0) return own;
    return own + contrast * std::max(0.0, own - nearest + margin);
}

std::string modalSeededPreset(const std::string& presetFile,
                              const std::vector<RecordedMode>& modes) {
    toml::table root = fitpreset::parsePreset(presetFile);
    if (!fitpreset::hasLayer(root, "impact"))
        throw std::invalid_argument(fmt::format("{}: no impact layer to seed", presetFile));
    if (modes.empty()) throw std::invalid_argument("modal seed: no recorded mode");
    fitpreset::seedImpactModes(root, modes, ModalSeedOptions{}.clusterOctaves);
    return fitpreset::toText(root);
}

FitResult fitSurface(const std::string& presetFile, const std::vector<Recording>& real,
                     const FitOptions& options) {
    const auto t0 = std::chrono::steady_clock::now();
    toml::table root = fitpreset::parsePreset(presetFile);
    if (root.get("base"))
        throw std::invalid_argument(fmt::format(
            "{}: a `base` preset; fit its base preset instead (it inherits the fit)", presetFile));
    fitpreset::Ranges ranges;
    const auto original = engine::Surface::load(presetFile); // keeps parameters() alive
    for (const auto& p : original->parameters()) ranges[p.path] = {p.minValue, p.maxValue};
    auto knobs = fitpreset::knobsFor(root);
    for (const auto& name : options.keep) {
        const auto it = std::find_if(knobs.begin(), knobs.end(),
                                     [&](const fitpreset::Knob& k) { return k.info.name == name; });
        if (it == knobs.end()) {
            std::string names;
            for (const auto& k : knobs) names += (names.empty() ? "" : ", ") + k.info.name;
            throw std::invalid_argument(fmt::format(
                "{}: no knob \"{}\" to keep (this preset's knobs: {})", presetFile, name, names));
        }
        knobs.erase(it);
    }
    if (knobs.empty())
        throw std::invalid_argument(
            options.keep.empty()
                ? fmt::format("{}: no impact, grains or bubbles layer to fit", presetFile)
                : fmt::format("{}: every knob is kept: nothing to fit", presetFile));

    // The render seeds of the objective (FitOptions::seeds): spec.seed alone by default.
    std::vector<std::uint64_t> seeds = options.seeds;
    if (seeds.empty()) seeds.push_back(options.spec.seed);
    if (seeds.size() > 32)
        throw std::invalid_argument(fmt::format(
            "{} render seeds: at most 32 (each evaluation renders once per seed)", seeds.size()));

    // A preset with a room ([reverb]) is fitted against the recordings heard through that room,
    // as `underfoot compare` compares it (describeRecordings, realism/Compare.h).
    const auto room = roomOfSurface(presetFile);
    AnalysisOptions ao;
    ao.maxHz = sharedMaxHz(real, options.spec.rateHz);
    const auto realSteps = describeRecordings(real, ao, room);
    if (realSteps.empty()) throw std::runtime_error("no footstep found in the recordings");

    const auto id = fs::path(presetFile).stem().string();
    // One folder per fit: fits of the same preset may run at once (fitsWithoutEachSource).
    static std::atomic<long> fitCount{0};
    const fs::path tmp = fs::temp_directory_path() / fmt::format("underfoot-fit-{}-{}-{}",
                                                                 static_cast<long>(::getpid()),
                                                                 fitCount.fetch_add(1), id);
    fs::create_directories(tmp);
    const auto tmpFile = (tmp / (id + ".toml")).string();

    auto build = [&](const std::vector<double>& x) {
        toml::table t = root;
        for (std::size_t i = 0; i < knobs.size(); ++i) knobs[i].apply(t, x[i], ranges);
        return t;
    };
    auto write = [&](const toml::table& t) { std::ofstream(tmpFile) << fitpreset::toText(t); };
    auto renderWritten = [&](std::uint64_t seed) { // the preset last written, with this seed
        RenderSpec spec = options.spec;
        spec.seed = seed;
        return renderForComparison(tmpFile, spec);
    };
    // The loudness calibration's render: the first seed's (spec.seed when no seeds are given).
    auto render = [&](const toml::table& t) {
        write(t);
        return renderWritten(seeds.front());
    };
    // Other materials (contrast): each compared on the band its recordings share with the
    // render, as `underfoot compare --all` does.
    struct Target {
        std::string material;
        AnalysisOptions ao;
        std::vector<StepDescriptors> steps;
    };
    std::vector<Target> others;
    if (options.contrast > 0) {
        std::map<std::string, std::vector<Recording>> byMaterial;
        for (const auto& r : options.others)
            if (!r.material.empty() && r.material != options.ownMaterial)
                byMaterial[r.material].push_back(r);
        for (const auto& [material, recs] : byMaterial) {
            Target t{material, {}, {}};
            t.ao.maxHz = sharedMaxHz(recs, options.spec.rateHz);
            t.steps = describeRecordings(recs, t.ao, room);
            if (!t.steps.empty()) others.push_back(std::move(t));
        }
    }
    // Distances of the written preset's render with one seed (the single-seed evaluation).
    auto evaluateSeed = [&](std::uint64_t seed) {
        FitDistances d;
        bool failed = false;
        try {
            const auto audio = renderWritten(seed);
            std::map<double, std::vector<StepDescriptors>> described; // by band limit
            auto stepsAt = [&](const AnalysisOptions& o) -> const std::vector<StepDescriptors>& {
                auto it = described.find(o.maxHz);
                if (it == described.end())
                    it = described.emplace(o.maxHz, describeSteps(audio, o)).first;
                return it->second;
            };
            const auto& own = stepsAt(ao);
            if (own.empty()) throw std::invalid_argument("the render holds no footstep");
            d.own = compareSteps(own, realSteps).distance;
            d.nearest = -1;
            for (const auto& o : others) {
                const double x = compareSteps(stepsAt(o.ao), o.steps).distance;
                if (d.nearest < 0 || x < d.nearest) {
                    d.nearest = x;
                    d.nearestMaterial = o.material;
                }
            }
        } catch (const engine::PresetError&) { // a knob combination the preset's ranges refuse
            failed = true;
        } catch (const std::invalid_argument&) { // a render without a footstep
            failed = true;
        }
        if (failed) {
            d.own = 100.0;
            d.nearest = others.empty() ? -1 : 0.0;
            d.nearestMaterial = others.empty() ? "" : "(none)";
        }
        d.objective = contrastiveObjective(d.own, d.nearest, options.contrast, options.margin);
        if (d.nearest < 0) d.nearest = 0;
        return d;
    };
    auto evaluate = [&](const toml::table& t) {
        write(t);
        if (seeds.size() == 1) return evaluateSeed(seeds.front());
        FitDistances mean;
        double thinnest = -1e300; // own - nearest of the seed with the thinnest margin
        for (const auto seed : seeds) {
            const FitDistances d = evaluateSeed(seed);
            mean.own += d.own;
            mean.nearest += d.nearest;
            mean.objective += d.objective;
            if (d.own - d.nearest > thinnest) {
                thinnest = d.own - d.nearest;
                mean.nearestMaterial = d.nearestMaterial;
            }
        }
        const double n = static_cast<double>(seeds.size());
        mean.own /= n;
        mean.nearest /= n;
        mean.objective /= n;
        return mean;
    };
    auto distanceOf = [&](const toml::table& t) { return evaluate(t).objective; };

    FitResult result;
    result.optimiser = "NLopt LN_BOBYQA";
    std::vector<double> x(knobs.size(), 0.0), lo, hi;
    for (const auto& k : knobs) {
        lo.push_back(k.info.lo);
        hi.push_back(k.info.hi);
    }
    result.before = evaluate(root);
    result.distanceBefore = result.before.own;
    result.contrastive = !others.empty();
    const toml::table originalTable = root; // loudness reference
    // Starting points: the preset itself, or (modal seed) the recordings' modes estimated on
    // the signal and on its first difference; each is refined, the better result is kept.
    struct Start {
        toml::table table;
        std::string name;
        std::vector<RecordedMode> modes;
        std::vector<std::string> skipped;
    };
    std::vector<Start> starts;
    // The preset itself is always a start: a seed whose refinement ends farther than the preset's
    // own modes would otherwise make the fit worse than no fit.
    starts.push_back({root, "the preset's own parameters", {}, {}});
    const bool seedTried = options.modalSeed && fitpreset::hasLayer(root, "impact");
    if (seedTried) {
        for (bool emphasis : {false, true}) {
            auto so = options.seed;
            so.maxModes = fitpreset::impactModeCount(root);
            so.preEmphasis = emphasis;
            Start s{
                root, emphasis ? "recorded modes (first difference)" : "recorded modes", {}, {}};
            s.modes = recordedModes(real, so, &s.skipped);
            fitpreset::seedImpactModes(s.table, s.modes, so.clusterOctaves);
            starts.push_back(std::move(s));
        }
    }
    const auto points = fitStartPoints(options.starts, lo, hi);
    result.startPoints = static_cast<int>(points.size());
    const int runs = static_cast<int>(starts.size() * points.size());
    int evals = 0;
    double best = 0, overall = 1e300;
    std::vector<double> bestX = x, overallX = x;
    std::size_t overallStart = 0, overallPoint = 0;
    std::vector<double> tableD0(starts.size(), 0.0); // objective of each starting preset
    struct Ctx {
        std::function<double(const std::vector<double>&)> f;
    } ctx{[&](const std::vector<double>& xv) {
        const double d = distanceOf(build(xv));
        ++evals;
        if (d < best) {
            best = d;
            bestX = xv;
        }
        if (options.progress &&
            !options.progress(evals, options.maxEvaluations * runs, d, std::min(best, overall)))
            throw nlopt::forced_stop();
        return d;
    }};
    bool stopped = false;
    for (std::size_t run = 0; run < starts.size() * points.size() && !stopped; ++run) {
        const std::size_t si = run / points.size(), pi = run % points.size();
        root = starts[si].table; // `build` applies the knobs to `root`
        double d0 = 1e300;
        if (pi == 0) { // the starting preset itself
            d0 = starts[si].modes.empty() ? result.before.objective : distanceOf(root);
            best = d0;
            tableD0[si] = d0;
        } else {
            best = 1e300; // BOBYQA evaluates its starting point first
        }
        x = points[pi];
        bestX = x;
        nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(knobs.size()));
        opt.set_lower_bounds(lo);
        opt.set_upper_bounds(hi);
        std::vector<double> step;
        for (std::size_t i = 0; i < knobs.size(); ++i) step.push_back(0.25 * (hi[i] - lo[i]));
        opt.set_initial_step(step);
        opt.set_maxeval(options.maxEvaluations);
        opt.set_xtol_abs(1e-3);
        opt.set_min_objective([](const std::vector<double>& xv, std::vector<double>&,
                                 void* data) { return static_cast<Ctx*>(data)->f(xv); },
                              &ctx);
        double fmin = 0;
        try {
            opt.optimize(x, fmin);
        } catch (const nlopt::forced_stop&) {
            stopped = true;
        } catch (const nlopt::roundoff_limited&) {
        }
        result.startObjectives.push_back(best);
        if (best < overall) {
            overall = best;
            overallX = bestX;
            overallStart = si;
            overallPoint = pi;
            result.distanceSeeded = tableD0[si];
        }
    }
    result.bestStartPoint = static_cast<int>(overallPoint);
    root = starts[overallStart].table;
    bestX = overallX;
    result.seedTried = seedTried;
    result.seedStart = starts[overallStart].name;
    if (seedTried && overallStart > 0) {
        result.modalSeeded = true;
        result.seededModes = starts[overallStart].modes;
        result.seedSkipped = starts[overallStart].skipped;
    }
    // Keep the original's loudness: the render's peak equals the original's.
    toml::table fitted = build(bestX);
    const double peakBefore = peakOf(render(originalTable));
    const double peakAfter = peakOf(render(fitted));
    if (peakBefore > 0 && peakAfter > 0) {
        const double g = originalTable["gain_db"].value<double>().value_or(0.0) +
                         20.0 * std::log10(peakBefore / peakAfter);
        fitted.insert_or_assign("gain_db", std::round(g * 10.0) / 10.0);
    }
    result.after = evaluate(fitted);
    result.distanceAfter = result.after.own;
    fs::remove_all(tmp);
    result.evaluations = evals;
    for (std::size_t i = 0; i < knobs.size(); ++i) {
        knobs[i].info.value = bestX[i];
        result.knobs.push_back(knobs[i].info);
    }

    toml::table prov;
    toml::array files, licences, sources;
    for (const auto& r : real) {
        files.push_back(r.file);
        if (std::find_if(licences.begin(), licences.end(), [&](const toml::node& n) {
                return n.value<std::string>() == r.licence;
            }) == licences.end())
            licences.push_back(r.licence);
        if (std::find_if(sources.begin(), sources.end(), [&](const toml::node& n) {
                return n.value<std::string>() == r.package;
            }) == sources.end())
            sources.push_back(r.package);
    }
    prov.insert("tool", fmt::format("underfoot fit {}", underfoot::base::version()));
    prov.insert("optimiser", result.optimiser);
    prov.insert("recordings", files);
    prov.insert("sources", sources);
    prov.insert("licences", licences);
    prov.insert("distance_before", std::round(result.distanceBefore * 1000) / 1000);
    prov.insert("distance_after", std::round(result.distanceAfter * 1000) / 1000);
    prov.insert("walker", options.spec.walker);
    prov.insert("seconds", options.spec.seconds);
    if (seeds.size() == 1) {
        prov.insert("seed", static_cast<std::int64_t>(seeds.front()));
    } else {
        toml::array seedList; // the objective is the mean over these renders (see Fit.h)
        for (const auto seed : seeds) seedList.push_back(static_cast<std::int64_t>(seed));
        prov.insert("seeds", seedList);
    }
    prov.insert("evaluations", evals);
    toml::table kt;
    for (const auto& k : result.knobs) kt.insert(k.name, std::round(k.value * 1000) / 1000);
    prov.insert("knobs", kt);
    if (options.starts > 1) {
        toml::table st;
        st.insert("points", static_cast<std::int64_t>(points.size()));
        st.insert("method", "the preset's own knobs and the first points - 1 points of the Sobol "
                            "sequence (Boost.Random sobol) scaled into the knobs' box, each "
                            "refined by BOBYQA");
        st.insert("evaluations_per_start", options.maxEvaluations);
        st.insert("best", static_cast<std::int64_t>(overallPoint));
        toml::array reached;
        for (double o : result.startObjectives) reached.push_back(std::round(o * 1000) / 1000);
        st.insert("objectives", reached);
        prov.insert("starts", st);
    }
    if (!options.keep.empty()) {
        toml::array kept;
        for (const auto& k : options.keep) kept.push_back(k);
        prov.insert("knobs_kept", kept);
    }
    if (result.contrastive) {
        toml::table ct;
        ct.insert("objective", "d_own + contrast x max(0, d_own - nearest other + margin)");
        ct.insert("contrast", options.contrast);
        ct.insert("margin", options.margin);
        toml::array materials;
        for (const auto& o : others) materials.push_back(o.material);
        ct.insert("other_materials", materials);
        ct.insert("nearest_other_before", result.before.nearestMaterial);
        ct.insert("nearest_other_distance_before", std::round(result.before.nearest * 1000) / 1000);
        ct.insert("nearest_other_after", result.after.nearestMaterial);
        ct.insert("nearest_other_distance_after", std::round(result.after.nearest * 1000) / 1000);
        prov.insert("contrast", ct);
    }
    if (seedTried) {
        toml::table seed;
        seed.insert("method", "matrix pencil on the strongest steps, clustered across files "
                              "and sources (realism/ModalSeed.h)");
        seed.insert("start", result.seedStart);
        seed.insert("modes", static_cast<std::int64_t>(result.seededModes.size()));
        seed.insert("modes_per_step", options.seed.modesPerStep);
        seed.insert("steps_per_file", options.seed.stepsPerFile);
        seed.insert("starts_tried", static_cast<std::int64_t>(starts.size()));
        if (result.modalSeeded)
            seed.insert("distance", std::round(result.distanceSeeded * 1000) / 1000);
        prov.insert("modal_seed", seed);
    }
    fitted.insert_or_assign("provenance", prov);
    result.presetText = fitpreset::toText(fitted);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

} // namespace underfoot::realism
