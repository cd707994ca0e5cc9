// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot compare`: how close a surface's footsteps are to recorded ones
// (docs/explanation/realism.md).
//   compare --surface gravel [--real FILES_OR_DIRS...] [-o report.html]
//   compare --all [-o report.html]          every surface with recordings of its material
//   compare --listener [-o report.html]     the listener's real baseline and its verdicts
//           [--markdown]                    tables as Markdown (docs/reference/realism-figures.md)
//           [--refit [--evaluations N] [--threads T]]   nested estimate, presets refitted
//           [--classic-listener | --onset-listener [--listener-grid]]   other listeners
//   compare --figures [--seeds 3,7,11] [--markdown] [-o report.html]   per surface and seed:
//           nested listener, distances, flatness, centroid, cost (cmd_compare_figures.cpp)
// Without --real, recordings come from the cache of scripts/fetch-recordings.sh
// (--recordings DIR, default $UNDERFOOT_RECORDINGS or build/recordings).
#include "app/cli/CommandRegistry.h"
#include "app/cli/CompareShared.h"
#include "base/Plural.h"
#include "engine/control/VirtualWalker.h"
#include "engine/surfaces/Surface.h"
#include "realism/Compare.h"
#include "realism/Listener.h"
#include "realism/NestedFit.h"
#include "realism/OnsetListener.h"
#include "realism/SurfaceFigures.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>

namespace underfoot::cli::compare_command {
namespace {
namespace eng = underfoot::engine;
namespace rl = underfoot::realism;
namespace fs = std::filesystem;

// One CSV line of listener features (names carry no commas: manifest paths and surface ids).
std::string featureLine(const rl::Example& e) {
    std::string s =
        fmt::format("{},{},{}", e.name, e.source, e.material.empty() ? "-" : e.material);
    for (double v : e.features) s += fmt::format(",{:.6g}", v);
    return s + "\n";
}

// The room the recordings are heard through for this surface: its own (none without a
// [reverb], or with --dry-recordings).
std::optional<eng::ReverbSpec> recordingsRoom(const CompareArgs& a, const std::string& surface) {
    return a.dryRecordings ? std::nullopt : rl::roomOfSurface(surface);
}

std::string roomNote(const std::optional<eng::ReverbSpec>& room) {
    return room ? fmt::format("recordings heard through the surface's room ({}, wet {:+.1f} dB, "
                              "dry {:+.1f} dB)",
                              room->impulseResponse, room->wetDb, room->dryDb)
                : std::string();
}

std::vector<rl::Recording> ofMaterial(const std::vector<rl::Recording>& all, const std::string& m) {
    std::vector<rl::Recording> out;
    for (const auto& r : all)
        if (r.material == m) out.push_back(r);
    return out;
}

const char* kStyle =
    "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:"
    "collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}"
    ".far{background:#fdd}figure{display:inline-block;margin:4px}</style>";

// Writes the pictures of one comparison beside the report and returns their HTML.
std::string figures(const rl::SurfaceComparison& c, const fs::path& dir) {
    fs::create_directories(dir);
    const auto id = fs::path(c.surface).stem().string();
    std::string html;
    auto put = [&](const std::string& name, const std::string& svg) {
        std::ofstream(dir / name) << svg;
        html += "<figure>" + svg + "<figcaption>" + (dir.filename() / name).string() +
                "</figcaption></figure>\n";
    };
    put(id + "_bands.svg", rl::bandPlotSvg(c));
    put(id + "_recorded_step.svg",
        rl::spectrogramSvg(c.realExample, c.options.analysisRateHz, c.options.maxHz,
                           "recorded " + c.material + " step"));
    put(id + "_synthetic_step.svg",
        rl::spectrogramSvg(c.syntheticExample, c.options.analysisRateHz, c.options.maxHz,
                           "synthetic " + id + " step"));
    return html;
}

void writeHtml(const std::string& path, const std::string& title, const std::string& body) {
    std::ofstream out(path);
    if (!out) throw UserError(fmt::format("-o {}: cannot write this file", path));
    out << "<!doctype html><html><head><meta charset=\"utf-8\"><title>" << title << "</title>"
        << kStyle << "</head><body><h1>" << title << "</h1>\n"
        << body << "</body></html>\n";
    fmt::print("report -> {}\n", path);
}

fs::path figureDir(const std::string& output) {
    const fs::path p(output);
    return p.parent_path() / (p.stem().string() + "_figures");
}

std::string definitionHtml() {
    return "<p>Distance: for every descriptor, z = |synthetic median − recorded median| / "
           "max(recorded IQR / 1.349, floor), on octaves for frequencies, rates and times and on "
           "dB otherwise; the distance is the mean z over the descriptors "
           "(docs/explanation/realism.md).</p>\n";
}

int runOne(const CompareArgs& a) {
    std::vector<rl::Recording> real;
    try {
        if (!a.real.empty())
            real = rl::collectRecordings(a.real);
        else {
            const auto m = rl::materialOfSurface(a.surface);
            if (m.empty())
                throw UserError(fmt::format("compare: no recorded material is known for \"{}\"; "
                                            "name recordings with --real",
                                            a.surface));
            real = ofMaterial(manifest(a), m);
            if (real.empty())
                throw UserError(fmt::format("compare: the recordings cache has no {} recordings; "
                                            "name some with --real",
                                            m));
        }
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    rl::SurfaceComparison c;
    try {
        c = rl::compareSurface(a.surface, real, a.spec, recordingsRoom(a, a.surface));
    } catch (const eng::PresetError& e) {
        throw UserError(e.what());
    } catch (const eng::FileError& e) {
        throw UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("compare: ") + e.what());
    }
    fmt::print("{} vs {} ({}), walker {}, {} s, seed {}\n", a.surface,
               counted(real.size(), "recording"), c.material.empty() ? "user files" : c.material,
               a.spec.walker, a.spec.seconds, a.spec.seed);
    if (c.room) fmt::print("{}\n", roomNote(c.room));
    fmt::print("{}", rl::descriptorTableText(c));
    if (!a.output.empty()) {
        std::string body = definitionHtml() + "<p>Recordings: ";
        for (const auto& f : c.realFiles) body += f + " ";
        if (c.room) body += "</p><p>" + roomNote(c.room) + ".";
        body += "</p>" + rl::descriptorTableHtml(c) + figures(c, figureDir(a.output));
        writeHtml(a.output, "Underfoot compare: " + a.surface, body);
    }
    return 0;
}

int runAll(const CompareArgs& a) {
    const auto recs = manifest(a);
    std::set<std::string> recorded;
    for (const auto& r : recs) recorded.insert(r.material);
    std::string body = definitionHtml() +
                       "<table><tr><th>surface</th><th>material</th><th>distance to its "
                       "recordings</th><th>nearest other material</th><th>its distance</th><th>"
                       "closer to its own</th></tr>\n";
    std::string figs;
    fmt::print("{:<22} {:<7} {:>9} {:>14} {:>9}  {}\n", "surface", "material", "distance",
               "nearest other", "distance", "own closest");
    int closer = 0, compared = 0;
    std::vector<std::string> roomed; // surfaces compared with the recordings in their room
    for (const auto& info : eng::listSurfaces()) {
        const auto m = rl::materialOfSurface(info.id);
        if (m.empty() || !recorded.count(m)) {
            fmt::print("{:<22} {:<7} (no recordings of its material)\n", info.id,
                       m.empty() ? "-" : m);
            continue;
        }
        const auto audio = rl::renderForComparison(info.id, a.spec);
        const auto room = recordingsRoom(a, info.id);
        if (room) roomed.push_back(info.id);
        std::map<std::string, double> dist;
        rl::SurfaceComparison own;
        for (const auto& mat : recorded) {
            auto c = rl::compareAudio(info.id, audio, ofMaterial(recs, mat), room);
            dist[mat] = c.comparison.distance;
            if (mat == m) own = std::move(c);
        }
        std::string other;
        double otherD = 1e300;
        for (const auto& [mat, d] : dist)
            if (mat != m && d < otherD) {
                other = mat;
                otherD = d;
            }
        const bool ok = dist[m] < otherD;
        closer += ok;
        ++compared;
        fmt::print("{:<22} {:<7} {:>9.2f} {:>14} {:>9.2f}  {}\n", info.id, m, dist[m], other,
                   otherD, ok ? "yes" : "no");
        body += fmt::format("<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{}</td><td>{:.2f}</td>"
                            "<td>{}</td></tr>\n",
                            info.id, m, dist[m], other, otherD, ok ? "yes" : "no");
        if (!a.output.empty())
            figs += "<h2>" + info.id + "</h2>" + rl::descriptorTableHtml(own) +
                    figures(own, figureDir(a.output));
    }
    fmt::print("{} of {} compared surfaces are closer to their own material's recordings than to "
               "any other's\n",
               closer, compared);
    std::string roomedList;
    for (const auto& id : roomed) roomedList += (roomedList.empty() ? "" : ", ") + id;
    if (!roomed.empty()) {
        fmt::print("{} (rendered with a room) were compared with every material's recordings heard "
                   "through the same room; --dry-recordings compares them with the dry "
                   "recordings\n",
                   roomedList);
    }
    body += "</table>\n";
    if (!roomed.empty())
        body += fmt::format("<p>{} (rendered with a room) were compared with every material's "
                            "recordings heard through the same room.</p>\n",
                            roomedList);
    body += figs;
    if (!a.output.empty()) writeHtml(a.output, "Underfoot compare --all", body);
    return 0;
}

std::string ratio(int ok, int n) {
    return fmt::format("{}/{}", ok, n);
}
std::string percent(int ok, int n) {
    return fmt::format("{}/{} ({:.0f} %)", ok, n, 100.0 * ok / std::max(n, 1));
}

// A leave-one-source-out result: totals, per held-out source, confusion table.
void printLoso(const rl::LosoResult& loso, std::size_t recordings, const std::string& what,
               Out& out) {
    out.line(fmt::format("{}, leave-one-source-out over {} recordings: material {}, category {}; "
                         "{} held-out files of a material no other source has were not scored",
                         what, recordings, percent(loso.materialCorrect, loso.files),
                         percent(loso.categoryCorrect, loso.files), loso.unseenMaterialFiles));
    Table perSource{{"held out", "material", "category"}, {}};
    for (const auto& [src, mf] : loso.perSource) {
        const auto it = loso.perSourceCategory.find(src);
        const int cat = it == loso.perSourceCategory.end() ? 0 : it->second;
        perSource.rows.push_back({src, ratio(mf.first, mf.second), ratio(cat, mf.second)});
    }
    out.table(perSource);
    std::set<std::string> cols;
    for (const auto& [t, row] : loso.confusion)
        for (const auto& [p, n] : row) cols.insert(p), cols.insert(t);
    out.line("confusion (rows: true material, columns: heard):");
    Table confusion{{"true \\ heard"}, {}};
    confusion.head.insert(confusion.head.end(), cols.begin(), cols.end());
    for (const auto& t : cols) {
        if (!loso.confusion.count(t)) continue;
        const auto& row = loso.confusion.at(t);
        std::vector<std::string> r{t};
        for (const auto& c : cols) r.push_back(std::to_string(row.count(c) ? row.at(c) : 0));
        confusion.rows.push_back(std::move(r));
    }
    out.table(confusion);
}

// The verdict on every surface's render (heard[i] is the material heard in infos[i]'s render).
void printVerdicts(const std::vector<eng::SurfaceInfo>& infos,
                   const std::vector<std::string>& heard, Out& out) {
    out.heading("Seen sources (the listener trained on every recording, the presets' fit data "
                "among them: not evidence)");
    Table t{{"surface", "category", "heard cat", "material", "heard", "verdict"}, {}, 1};
    int catOk = 0, matOk = 0, matN = 0, n = 0;
    for (std::size_t i = 0; i < infos.size(); ++i) {
        const auto& info = infos[i];
        const auto cat = std::string(eng::toString(info.category));
        const auto heardCat = rl::categoryOfMaterial(heard[i]);
        const auto mat = rl::materialOfSurface(info.id);
        ++n;
        catOk += heardCat == cat;
        if (!mat.empty()) {
            ++matN;
            matOk += heard[i] == mat;
        }
        t.rows.push_back(
            {info.id, cat, heardCat, mat.empty() ? "-" : mat, heard[i],
             std::string(heardCat == cat ? "category ok" : "WRONG category") +
                 (mat.empty() ? "" : (heard[i] == mat ? ", material ok" : ", wrong material"))});
    }
    out.table(t);
    out.line(fmt::format("seen sources: category right for {}, material right for {} surfaces "
                         "with a recorded material",
                         ratio(catOk, n), ratio(matOk, matN)));
}

// Renders judged by listeners that never heard a source: heard[S][i] is the material heard in
// infos[i]'s render without S. Per held-out source: its recordings' leave-one-source-out score
// (loso), every surface's category, and the surfaces of a material S recorded (category and
// material right or not); then per surface over the sources that recorded its material, with how
// the same listener heard the source's own recordings of it where the render was put in another
// category.
void printNested(const std::vector<eng::SurfaceInfo>& infos, const std::vector<rl::Example>& recs,
                 const std::map<std::string, std::vector<std::string>>& heard,
                 const rl::LosoResult& loso, const rl::ListenerOptions& lo,
                 const std::string& title, Out& out) {
    std::map<std::string, std::set<std::string>> recorded; // source -> materials
    for (const auto& e : recs) recorded[e.source].insert(e.material);
    out.heading(title);
    Table perSource{{"held out", "its recordings: material", "category", "renders: category (all)",
                     "its materials: category", "material"},
                    {}};
    int totals[4] = {0, 0, 0, 0}; // cat all, n all, own n, own cat
    int totalMat = 0;
    for (const auto& [src, h] : heard) {
        int catAll = 0, n = 0, catOwn = 0, matOwn = 0;
        for (std::size_t i = 0; i < infos.size(); ++i) {
            const auto cat = std::string(eng::toString(infos[i].category));
            const bool catOk = rl::categoryOfMaterial(h[i]) == cat;
            catAll += catOk;
            const auto mat = rl::materialOfSurface(infos[i].id);
            if (mat.empty() || !recorded[src].count(mat)) continue;
            ++n;
            catOwn += catOk;
            matOwn += h[i] == mat;
        }
        totals[0] += catAll;
        totals[1] += int(infos.size());
        totals[2] += n;
        totals[3] += catOwn;
        totalMat += matOwn;
        const auto it = loso.perSource.find(src);
        const auto cit = loso.perSourceCategory.find(src);
        const auto files = it == loso.perSource.end() ? std::pair<int, int>{0, 0} : it->second;
        const int filesCat = cit == loso.perSourceCategory.end() ? 0 : cit->second;
        perSource.rows.push_back({src, ratio(files.first, files.second),
                                  ratio(filesCat, files.second), ratio(catAll, int(infos.size())),
                                  ratio(catOwn, n), ratio(matOwn, n)});
    }
    perSource.rows.push_back({"all", ratio(loso.materialCorrect, loso.files),
                              ratio(loso.categoryCorrect, loso.files),
                              percent(totals[0], totals[1]), percent(totals[3], totals[2]),
                              percent(totalMat, totals[2])});
    out.table(perSource);
    Table perSurf{
        {"surface", "sources", "category", "material", "heard without each source"}, {}, 4};
    std::vector<rl::SurfaceUnderTest> surfaces;
    for (const auto& info : infos)
        surfaces.push_back(
            {info.id, rl::materialOfSurface(info.id), std::string(eng::toString(info.category))});
    std::vector<rl::SurfaceFigures> scored(infos.size());
    rl::scoreNested(surfaces, heard, recorded, scored);
    rl::addHeldOutRecordings(rl::heldOutRecordings(recs, lo), scored);
    for (const auto& f : scored) {
        std::string list;
        for (const auto& v : f.heardWithout) {
            list += fmt::format("{}{}:{}", list.empty() ? "" : " ", v.source, v.heard);
            if (v.scored && rl::categoryOfMaterial(v.heard) != f.category)
                list += fmt::format(" ({}/{})", v.recordings.categoryRight, v.recordings.files);
        }
        perSurf.rows.push_back({f.surface, std::to_string(f.sources),
                                ratio(f.categoryRight, f.sources),
                                ratio(f.materialRight, f.sources), list});
    }
    out.line("per surface (sources: held-out sources that recorded its material; category and "
             "material right without those sources; after a verdict in another category, how "
             "often that listener put the source's own recordings of the material in its "
             "category):");
    out.table(perSurf);
    int atPar = 0, withSources = 0;
    for (const auto& s : rl::overSeeds(scored)) {
        if (s.sources.empty()) continue;
        ++withSources;
        atPar += s.atLeastAsOftenAsRecordings();
    }
    out.line(fmt::format("surfaces heard in their category at least as often as each held-out "
                         "source's own recordings of their material: {}/{}",
                         atPar, withSources));
}

// The nested figures turned round (rl::trainedOnEachSource): per source that recorded two
// materials or more and per material it recorded, a listener trained on that source alone
// judging the other sources' recordings of the material and the renders of it.
void printOneSource(const std::vector<eng::SurfaceInfo>& infos,
                    const std::vector<rl::Example>& recs, const std::vector<rl::Example>& synth,
                    const rl::ListenerOptions& lo, Out& out) {
    std::vector<std::string> mats;
    for (const auto& info : infos) mats.push_back(rl::materialOfSurface(info.id));
    const auto figs = rl::trainedOnEachSource(recs, synth, mats, lo);
    out.heading("Each source alone: listener trained on one source's recordings, judging the "
                "other sources' recordings and the renders of the materials it recorded");
    Table t{{"trained on", "material", "others' recordings: material", "category",
             "renders: material", "category", "renders in another category"},
            {},
            6};
    rl::JudgedCounts rec, ren;
    std::string atPar; // per source: rows whose renders are placed as often as the recordings
    int parCat = 0, parMat = 0, rows = 0;
    for (const auto& [src, f] : figs) {
        int srcRows = 0, srcCat = 0, srcMat = 0;
        for (const auto& [mat, r] : f.recordings) {
            const auto it = f.renders.find(mat);
            const rl::JudgedCounts c = it == f.renders.end() ? rl::JudgedCounts{} : it->second;
            std::string wrong;
            for (std::size_t i = 0; i < infos.size(); ++i)
                if (mats[i] == mat && !f.heard[i].empty() &&
                    rl::categoryOfMaterial(f.heard[i]) != rl::categoryOfMaterial(mat))
                    wrong +=
                        fmt::format("{}{}:{}", wrong.empty() ? "" : " ", infos[i].id, f.heard[i]);
            t.rows.push_back(
                {src, mat, ratio(r.materialRight, r.files), ratio(r.categoryRight, r.files),
                 c.files ? ratio(c.materialRight, c.files) : "-",
                 c.files ? ratio(c.categoryRight, c.files) : "-", wrong.empty() ? "-" : wrong});
            rec.files += r.files;
            rec.materialRight += r.materialRight;
            rec.categoryRight += r.categoryRight;
            ren.files += c.files;
            ren.materialRight += c.materialRight;
            ren.categoryRight += c.categoryRight;
            if (c.files == 0) continue;
            ++srcRows; // shares compared without rounding: a/b >= c/d as a*d >= c*b
            srcCat += c.categoryRight * r.files >= r.categoryRight * c.files;
            srcMat += c.materialRight * r.files >= r.materialRight * c.files;
        }
        if (srcRows == 0) continue;
        atPar += fmt::format("{}{} {}/{} and {}/{}", atPar.empty() ? "" : ", ", src, srcCat,
                             srcRows, srcMat, srcRows);
        rows += srcRows;
        parCat += srcCat;
        parMat += srcMat;
    }
    t.rows.push_back({"all", "", percent(rec.materialRight, rec.files),
                      percent(rec.categoryRight, rec.files), percent(ren.materialRight, ren.files),
                      percent(ren.categoryRight, ren.files), ""});
    out.table(t);
    out.line(fmt::format("renders placed at least as often as the other sources' recordings, in "
                         "category and in material, per source and material they share: {} "
                         "({}/{} and {}/{})",
                         atPar, parCat, rows, parMat, rows));
    out.line("A source that recorded one material only teaches nothing to tell apart and has no "
             "row, nor has a material no other source recorded.");
}

// The onset listener (realism/OnsetListener.h): its configuration chosen from a fixed grid by
// leave-one-source-out on the recordings; prints its figures, the nested estimate and the
// renders' verdict.
int runOnsetListener(const CompareArgs& a) {
    const auto recs = manifest(a);
    rl::AnalysisOptions o;
    o.maxHz = rl::sharedMaxHz(recs, a.spec.rateHz);
    std::vector<rl::ListenerFile> files;
    for (const auto& r : recs) {
        try {
            files.push_back(rl::describeListenerFile(r.file, r.source, r.material,
                                                     eng::readAudioFile(r.path), o));
        } catch (const std::invalid_argument&) {
            fmt::print("warning: {}: no step found, left out\n", r.file);
        }
    }
    if (!a.features.empty()) { // every step's features, before normalisation by source
        std::ofstream csv(a.features);
        if (!csv) throw UserError(fmt::format("--features {}: cannot write this file", a.features));
        csv << "name,source,material,step";
        for (std::size_t k = 0; k < rl::listenerFeatureCount(); ++k)
            csv << "," << rl::listenerFeatureKey(k);
        csv << "\n";
        for (const auto& f : files)
            for (std::size_t s = 0; s < f.steps.size(); ++s) {
                csv << fmt::format("{},{},{},{}", f.name, f.source, f.material, s);
                for (double v : f.steps[s]) csv << fmt::format(",{:.6g}", v);
                csv << "\n";
            }
    }
    const auto grid = rl::listenerGrid();
    const auto cfg = rl::chooseConfig(files, grid);
    Out out{a.markdown, {}};
    out.line(
        fmt::format("Onset listener (realism/OnsetListener.h), configuration {} chosen among {} by "
                    "leave-one-source-out (band {:.0f}-{:.0f} Hz), trained on recordings only.",
                    cfg.name(), grid.size(), o.minHz, o.maxHz));
    if (a.listenerGrid) {
        fmt::print("every configuration, leave-one-source-out over {} recordings (material, "
                   "category):\n",
                   files.size());
        for (const auto& c : grid) {
            const auto r = rl::leaveOneSourceOut(files, c);
            fmt::print("  {:<36} {:>2}/{}  {:>2}/{}\n", c.name(), r.materialCorrect, r.files,
                       r.categoryCorrect, r.files);
        }
        fmt::print("chosen on all sources: {}\n", cfg.name());
    }
    printLoso(rl::leaveOneSourceOut(files, cfg), files.size(), "onset listener " + cfg.name(), out);
    const auto nested = rl::nestedLeaveOneSourceOut(files, grid);
    for (const auto& [src, c] : nested.chosen)
        fmt::print("nested: held out {}: chose {} on the other sources\n", src, c.name());
    printLoso(nested.heldOut, files.size(),
              fmt::format("nested estimate (configuration chosen among {} without the held-out "
                          "source)",
                          grid.size()),
              out);
    auto trainSet = files;
    rl::normaliseBySource(trainSet, cfg.standardisePerSource);
    rl::OnsetListener l(cfg);
    l.train(trainSet);
    std::vector<rl::ListenerFile> synth;
    std::vector<eng::SurfaceInfo> infos;
    for (const auto& info : eng::listSurfaces()) {
        try {
            synth.push_back(rl::describeListenerFile(info.id, "synthetic", "",
                                                     rl::renderForComparison(info.id, a.spec), o));
        } catch (const std::invalid_argument&) {
            continue; // no step in the render
        }
        infos.push_back(info);
    }
    rl::normaliseBySource(synth, cfg.standardisePerSource); // the renders are one more source
    std::vector<std::string> heard;
    for (const auto& f : synth) heard.push_back(l.classify(f));
    printVerdicts(infos, heard, out);
    if (!a.output.empty()) writeHtml(a.output, "Underfoot listener", out.body);
    return 0;
}

// The nested estimate with the presets refitted without each source (realism/NestedFit.h).
void printRefitNested(const CompareArgs& a, const std::vector<rl::Recording>& recs,
                      const std::vector<rl::Example>& ex, const rl::AnalysisOptions& o,
                      const rl::ListenerOptions& lo, const rl::LosoResult& loso, Out& out) {
    rl::NestedRefitOptions no;
    no.fit.maxEvaluations = a.evaluations;
    no.fit.contrast = 2.0; // `underfoot fit`'s defaults
    no.fit.margin = 0.1;
    no.threads = a.threads;
    no.render = a.spec;
    no.listener = lo;
    no.progress = [](std::size_t done, std::size_t total, const rl::RefitJob& j,
                     const rl::FitResult& r) {
        fmt::print(stderr,
                   "refit {}/{}: {} without {} ({} recordings): distance {:.3f} -> {:.3f} "
                   "in {:.0f} s\n",
                   done, total, j.surface, j.heldOut, j.own.size(), r.distanceBefore,
                   r.distanceAfter, r.seconds);
    };
    const auto t0 = std::chrono::steady_clock::now();
    const auto n = rl::nestedRefit(recs, ex, o, no);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::map<std::string, std::vector<std::string>> refitted; // source -> surfaces
    for (const auto& j : n.jobs) refitted[j.heldOut].push_back(j.surface);
    std::string list;
    for (const auto& [src, ids] : refitted)
        list += fmt::format("{}{}: {}", list.empty() ? "" : "; ", src, fmt::join(ids, ", "));
    std::vector<eng::SurfaceInfo> infos;
    for (const auto& info : eng::listSurfaces())
        if (std::find(n.surfaces.begin(), n.surfaces.end(), info.id) != n.surfaces.end())
            infos.push_back(info);
    printNested(infos, ex, n.heard, loso, lo,
                "Nested, presets refitted: listener trained and presets fitted without the "
                "held-out source",
                out);
    out.line(fmt::format(
        "{} ({} each at most, contrast 2, margin 0.1, {}) in {:.0f} s. "
        "Refitted without each source: {}. A preset of a material the held-out source did not "
        "record, or recorded alone, keeps its shipped (all-source) fit; a preset with a base "
        "inherits its base's refit.",
        counted(n.jobs.size(), "fit"), counted(a.evaluations, "evaluation"),
        counted(a.threads, "thread"), seconds, list));
}

// The default listener and the first one (realism/Listener.h, --classic-listener).
int runListener(const CompareArgs& a) {
    if (a.onsetListener) return runOnsetListener(a);
    const auto recs = manifest(a);
    rl::AnalysisOptions o;
    o.maxHz = rl::sharedMaxHz(recs, a.spec.rateHz);
    std::vector<std::string> silent;
    const auto ex = rl::recordingExamples(recs, o, &silent);
    for (const auto& f : silent) fmt::print("warning: {}: no step found, left out\n", f);
    std::ofstream csv;
    if (!a.features.empty()) {
        csv.open(a.features);
        if (!csv) throw UserError(fmt::format("--features {}: cannot write this file", a.features));
        csv << "name,source,material";
        for (int d = 0; d < rl::kDescriptorCount; ++d) csv << "," << rl::descriptorInfo(d).key;
        for (double c : rl::thirdOctaveCentres(o.maxHz)) csv << fmt::format(",to{:.0f}", c);
        csv << "\n";
        for (const auto& e : ex) csv << featureLine(e);
    }
    rl::ListenerOptions lo;
    if (a.classicListener) lo = {false, false, false};
    Out out{a.markdown, {}};
    out.line(fmt::format(
        "Nearest-centroid listener on {} descriptors{} (band {:.0f}-{:.0f} Hz), {}, trained on "
        "recordings only.",
        int(rl::kDescriptorCount),
        lo.scalarsOnly
            ? std::string()
            : fmt::format(" and {} third-octave bands", rl::thirdOctaveCentres(o.maxHz).size()),
        o.minHz, o.maxHz,
        lo.centrePerSource ? "every source centred on its own median, one centroid per source "
                             "and material"
                           : "one centroid per material"));
    const auto loso = rl::leaveOneSourceOut(ex, lo);
    printLoso(loso, ex.size(), a.classicListener ? "first listener" : "listener", out);
    rl::Listener l(lo);
    auto trainSet = ex;
    if (lo.centrePerSource) rl::centreBySource(trainSet);
    l.train(trainSet);
    // The renders are one more source: described first, centred on their own median.
    std::vector<rl::Example> synth;
    std::vector<eng::SurfaceInfo> infos;
    for (const auto& info : eng::listSurfaces()) {
        auto e = rl::renderExample(info.id, info.id, a.spec, o);
        if (!e) continue;
        synth.push_back(std::move(*e));
        infos.push_back(info);
        if (csv.is_open()) csv << featureLine(synth.back());
    }
    const auto synthUncentred = synth;
    if (lo.centrePerSource) rl::centreBySource(synth);
    std::vector<std::string> heard;
    for (const auto& e : synth) heard.push_back(l.classify(e.features));
    // centreBySource above changed synth: heardWithoutEachSource centres its own copies.
    printNested(infos, ex, rl::heardWithoutEachSource(ex, synthUncentred, lo), loso, lo,
                "Nested, presets not refitted: listener trained without the held-out source, "
                "presets as shipped (fitted with it)",
                out);
    if (a.refit) printRefitNested(a, recs, ex, o, lo, loso, out);
    printOneSource(infos, ex, synthUncentred, lo, out);
    printVerdicts(infos, heard, out);
    if (!a.output.empty()) writeHtml(a.output, "Underfoot listener", out.body);
    return 0;
}

int runCompare(const CompareArgs& a) {
    const int modes = int(!a.surface.empty()) + int(a.all) + int(a.listener) + int(a.figures);
    if (modes != 1)
        throw UserError("compare: give exactly one of --surface S, --all, --listener or --figures");
    if (a.classicListener && a.onsetListener)
        throw UserError("compare: give at most one of --classic-listener and --onset-listener");
    if (a.listenerGrid && !a.onsetListener)
        throw UserError("compare: --listener-grid goes with --onset-listener");
    if (!a.real.empty() && a.surface.empty())
        throw UserError("compare: --real goes with --surface");
    if (a.refit && !a.listener) throw UserError("compare: --refit goes with --listener");
    if (a.markdown && !a.listener && !a.figures)
        throw UserError("compare: --markdown goes with --listener or --figures");
    if (a.seedGiven && a.figures)
        throw UserError("compare: --figures renders every seed of --seeds; give --seeds N");
    if (a.seedsGiven && !a.figures)
        throw UserError("compare: --seeds goes with --figures (--seed sets one render's seed)");
    if (a.refit && (a.onsetListener || a.classicListener))
        throw UserError("compare: --refit goes with the default listener");
    try {
        eng::WalkerParameters::parse(a.spec.walker).validate();
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("--walker: ") + e.what());
    }
    if (!a.surface.empty()) return runOne(a);
    try {
        if (a.figures) return runFigures(a);
        return a.all ? runAll(a) : runListener(a);
    } catch (const eng::FileError& e) {
        throw UserError(e.what());
    }
}

CommandRegistrar reg("compare", [](CLI::App& app, int& exitCode) {
    auto args = std::make_shared<CompareArgs>();
    auto* cmd = app.add_subcommand(
        "compare", "Compare a surface's footsteps with recorded footsteps (descriptors, distance, "
                   "listener; see docs/explanation/realism.md)");
    cmd->add_option("-s,--surface", args->surface, "surface id or preset .toml");
    cmd->add_option("--real", args->real,
                    "recorded footsteps: audio files or folders (default: the recordings cache, "
                    "material of the surface)");
    cmd->add_option(
        "--recordings", args->recordings,
        "recordings cache of scripts/fetch-recordings.sh (default $UNDERFOOT_RECORDINGS "
        "or build/recordings)");
    cmd->add_flag("--all", args->all, "compare every surface that has recordings of its material");
    cmd->add_flag("--dry-recordings", args->dryRecordings,
                  "a surface with a room ([reverb]) is compared with the recordings as they are "
                  "(dry) instead of with the recordings heard through the same room");
    cmd->add_flag("--listener", args->listener,
                  "the listener: leave-one-source-out baseline and its verdict on every surface");
    cmd->add_flag("--figures", args->figures,
                  "per surface and render seed: the nested listener's verdicts (beside how it "
                  "heard the held-out source's own recordings), the distance to its own "
                  "recordings and the nearest other material, flatness and centroid against its "
                  "recordings, CPU time per frame (docs/explanation/realism.md)");
    cmd->add_option("--seeds", args->seeds, "with --figures: the render seeds")
        ->delimiter(',')
        ->capture_default_str()
        ->each([args](const std::string&) { args->seedsGiven = true; });
    cmd->add_option("--walker", args->spec.walker, "virtual walker of the render")
        ->capture_default_str();
    cmd->add_option("--seconds", args->spec.seconds, "length of the render")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 600.0));
    cmd->add_option("--seed", args->spec.seed, "seed of the render")
        ->capture_default_str()
        ->each([args](const std::string&) { args->seedGiven = true; });
    cmd->add_option("-o,--output", args->output, "HTML report (SVG figures beside it)");
    cmd->add_flag("--classic-listener", args->classicListener,
                  "with --listener: the first listener (one centroid per material on all "
                  "features, no centring by source), for comparison");
    cmd->add_flag("--onset-listener", args->onsetListener,
                  "with --listener: the onset listener (features of the first 30/80/150 ms after "
                  "the contact and the whole-step descriptors, configuration chosen from a fixed "
                  "grid by leave-one-source-out) with its nested estimate");
    cmd->add_flag("--listener-grid", args->listenerGrid,
                  "with --onset-listener: print every configuration's leave-one-source-out "
                  "figures");
    cmd->add_flag("--markdown", args->markdown,
                  "with --listener or --figures: print the tables as Markdown (pasted verbatim "
                  "into docs/reference/realism-figures.md)");
    cmd->add_flag("--refit", args->refit,
                  "with --listener: the nested estimate with the presets refitted (as `underfoot "
                  "fit` does) without each held-out source; slow: one fit per preset and source "
                  "that recorded its material");
    cmd->add_option("--evaluations", args->evaluations,
                    "with --refit: renders the optimiser may try per fit")
        ->capture_default_str()
        ->check(CLI::Range(5, 2000));
    cmd->add_option("--threads", args->threads, "with --refit: fits run at once")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--features", args->features,
                    "with --listener: write the listener's features (CSV: name, source, material, "
                    "then one column per feature; with --onset-listener every step of every "
                    "recording, otherwise every file and render)");
    cmd->callback([args, &exitCode] { exitCode = runCompare(*args); });
});

} // namespace
} // namespace underfoot::cli::compare_command
