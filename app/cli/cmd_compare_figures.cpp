// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot compare --figures [--seeds 3,7,11] [--markdown] [-o report.html]`: per surface and
// render seed, the figures its realism is judged by (realism/SurfaceFigures.h): the nested
// listener's verdicts, the distance to its own recordings and the nearest other material's,
// flatness and centroid against its recordings, and the render's cost in this run.
#include "app/cli/CommandRegistry.h"
#include "app/cli/CompareShared.h"
#include "base/Plural.h"
#include "realism/SurfaceFigures.h"

#include <fmt/core.h>

#include <fstream>
#include <string>

namespace underfoot::cli::compare_command {
namespace {

bool inside(const realism::DescriptorComparison& d) {
    return d.synthetic >= d.realQ1 && d.synthetic <= d.realQ3;
}

// "value (Q1..Q3)", then " outside" when the unrounded value lies outside the range: a value at
// the range's edge prints like its bound, and the marker says on which side it is.
std::string withRange(const realism::DescriptorComparison& d, const char* format) {
    return fmt::format(fmt::runtime(format), d.synthetic) + " (" +
           fmt::format(fmt::runtime(format), d.realQ1) + ".." +
           fmt::format(fmt::runtime(format), d.realQ3) + ")" + (inside(d) ? "" : " outside");
}

} // namespace

int runFigures(const CompareArgs& a) {
    const auto recs = manifest(a);
    realism::SurfaceFiguresOptions o;
    o.spec = a.spec;
    o.seeds = a.seeds;
    o.dryRecordings = a.dryRecordings;
    const auto surfaces = realism::bundledSurfaces();
    const auto figs = realism::surfaceFigures(surfaces, recs, o);

    Out out{a.markdown, {}};
    std::string seeds;
    for (auto s : a.seeds) seeds += (seeds.empty() ? "" : ",") + std::to_string(s);
    out.line(fmt::format(
        "Per surface and render seed (walker {}, {} s, seeds {}): nested listener (trained "
        "without each source that recorded the surface's material: category and material right, "
        "and the sources whose listener put it in another category, with how often that listener "
        "put the source's own recordings of the material in its category), distance to its own "
        "recordings and to the nearest other material, flatness and centroid with the "
        "recordings' interquartile range, CPU time per rendered frame in this run.",
        a.spec.walker, a.spec.seconds, seeds));
    Table t{{"surface", "seed", "nested category", "material", "other category without",
             "own distance", "nearest other", "flatness dB (IQR)", "centroid Hz (IQR)", "ns/frame"},
            {},
            4};
    int catRight = 0, catN = 0, matRight = 0, flatIn = 0, flatN = 0, ownClosest = 0, ownN = 0;
    for (const auto& f : figs) {
        std::string wrong;
        for (const auto& v : f.heardWithout)
            if (v.scored && realism::categoryOfMaterial(v.heard) != f.category)
                wrong += fmt::format("{}{}:{} ({}/{})", wrong.empty() ? "" : " ", v.source, v.heard,
                                     v.recordings.categoryRight, v.recordings.files);
        catRight += f.categoryRight;
        matRight += f.materialRight;
        catN += f.sources;
        std::vector<std::string> row{
            f.surface, std::to_string(f.seed),
            f.sources ? fmt::format("{}/{}", f.categoryRight, f.sources) : "-",
            f.sources ? fmt::format("{}/{}", f.materialRight, f.sources) : "-",
            wrong.empty() ? "-" : wrong};
        if (f.hasRecordings) {
            ++ownN;
            ownClosest += f.nearestOther.empty() || f.ownDistance < f.nearestOtherDistance;
            ++flatN;
            flatIn += inside(f.flatness);
            row.push_back(fmt::format("{:.2f}", f.ownDistance));
            row.push_back(f.nearestOther.empty()
                              ? "-"
                              : fmt::format("{} {:.2f}", f.nearestOther, f.nearestOtherDistance));
            row.push_back(withRange(f.flatness, "{:.1f}"));
            row.push_back(withRange(f.centroid, "{:.0f}"));
        } else {
            row.insert(row.end(), {"-", "-", "-", "-"});
        }
        row.push_back(fmt::format("{:.0f}", f.nanosecondsPerFrame));
        t.rows.push_back(std::move(row));
    }
    out.table(t);
    int always = 0, atPar = 0, scoredSurfaces = 0;
    std::string below;
    for (const auto& s : realism::overSeeds(figs)) {
        if (s.sources.empty()) continue;
        ++scoredSurfaces;
        always += s.alwaysInCategory();
        atPar += s.atLeastAsOftenAsRecordings();
        for (const auto& h : s.sources)
            if (!h.atLeastAsOftenAsRecordings())
                below +=
                    fmt::format("{}{} without {} ({}/{} seeds; its recordings {}/{})",
                                below.empty() ? "" : ", ", s.surface, h.source, h.seedsInCategory,
                                h.seeds, h.recordings.categoryRight, h.recordings.files);
    }
    out.line(fmt::format(
        "nested, over {}: category right {}/{}, material right {}/{}; surfaces in their "
        "category for every held-out source that recorded their material, at every seed: {}/{}; "
        "in their category at least as often as each such source's own recordings: {}/{}; "
        "own material closest {}/{}; flatness inside the recordings' IQR {}/{}",
        counted(a.seeds.size(), "seed"), catRight, catN, matRight, catN, always, scoredSurfaces,
        atPar, scoredSurfaces, ownClosest, ownN, flatIn, flatN));
    out.line("heard in their category less often than the held-out source's own recordings: " +
             (below.empty() ? std::string("none") : below));
    if (!a.output.empty()) {
        std::ofstream html(a.output);
        if (!html) throw UserError(fmt::format("-o {}: cannot write this file", a.output));
        html << "<!doctype html><meta charset=\"utf-8\"><title>Underfoot compare --figures</title>"
             << out.body;
    }
    return 0;
}

} // namespace underfoot::cli::compare_command
