// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot compare`: how close a surface's footsteps are to recorded ones
// (docs/explanation/realism.md).
//   compare --surface gravel [--real FILES_OR_DIRS...] [-o report.html]
//   compare --all [-o report.html]          every surface with recordings of its material
//   compare --listener [-o report.html]     the listener's real baseline and its verdicts
//           [--classic-listener | --onset-listener [--listener-grid]]   other listeners
// Without --real, recordings come from the cache of scripts/fetch-recordings.sh
// (--recordings DIR, default $UNDERFOOT_RECORDINGS or build/recordings).
#include "app/cli/CommandRegistry.h"
#include "engine/control/VirtualWalker.h"
#include "engine/surfaces/Surface.h"
#include "realism/Compare.h"
#include "realism/Listener.h"
#include "realism/OnsetListener.h"

#include <fmt/core.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>

namespace underfoot::cli::compare_command {
namespace {
namespace eng = underfoot::engine;
namespace rl = underfoot::realism;
namespace fs = std::filesystem;

struct CompareArgs {
    std::string surface;
    std::vector<std::string> real;
    std::string recordings;
    bool all = false;
    bool listener = false;
    std::string output;
    std::string features;         ///< --features: CSV of every file's listener features
    bool classicListener = false; ///< --classic-listener: no centring, bands, one centroid
    bool onsetListener = false;   ///< --onset-listener: onset features, configuration grid
    bool listenerGrid = false;    ///< --listener-grid: every configuration's figures
    bool dryRecordings = false;   ///< --dry-recordings: no room on the recordings
    rl::RenderSpec spec;
};

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

std::vector<rl::Recording> manifest(const CompareArgs& a) {
    const auto dir = a.recordings.empty() ? rl::defaultRecordingsDir() : a.recordings;
    try {
        return rl::loadManifest(dir);
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
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
    fmt::print("{} vs {} recording(s) ({}), walker {}, {} s, seed {}\n", a.surface, real.size(),
               c.material.empty() ? "user files" : c.material, a.spec.walker, a.spec.seconds,
               a.spec.seed);
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

// Prints (and appends to the HTML body) a leave-one-source-out result: totals, per held-out
// source, confusion table.
void printLoso(const rl::LosoResult& loso, std::size_t recordings, const std::string& what,
               std::string& body) {
    fmt::print("{}, leave-one-source-out over {} recordings: material {}/{} ({:.0f} %), "
               "category {}/{} ({:.0f} %); {} held-out files of a material no other source has "
               "were not scored\n",
               what, recordings, loso.materialCorrect, loso.files,
               100.0 * loso.materialCorrect / std::max(loso.files, 1), loso.categoryCorrect,
               loso.files, 100.0 * loso.categoryCorrect / std::max(loso.files, 1),
               loso.unseenMaterialFiles);
    body += fmt::format("<p>{}, leave-one-source-out: material {}/{}, category {}/{}.</p><ul>",
                        what, loso.materialCorrect, loso.files, loso.categoryCorrect, loso.files);
    for (const auto& [src, mf] : loso.perSource) {
        const auto it = loso.perSourceCategory.find(src);
        const int cat = it == loso.perSourceCategory.end() ? 0 : it->second;
        fmt::print("  held out {:<10} material {:>2}/{:<2}  category {:>2}/{}\n", src, mf.first,
                   mf.second, cat, mf.second);
        body += fmt::format("<li>held out {}: material {}/{}, category {}/{}</li>", src, mf.first,
                            mf.second, cat, mf.second);
    }
    body += "</ul><table><tr><th>true \\ heard</th>";
    std::set<std::string> cols;
    for (const auto& [t, row] : loso.confusion)
        for (const auto& [p, n] : row) cols.insert(p), cols.insert(t);
    for (const auto& c : cols) body += "<th>" + c + "</th>";
    body += "</tr>";
    fmt::print("confusion (rows: true material, columns: heard):\n{:<8}", "");
    for (const auto& c : cols) fmt::print(" {:>6}", c);
    fmt::print("\n");
    for (const auto& t : cols) {
        if (!loso.confusion.count(t)) continue;
        fmt::print("{:<8}", t);
        body += "<tr><th>" + t + "</th>";
        for (const auto& c : cols) {
            const auto& row = loso.confusion.at(t);
            const int n = row.count(c) ? row.at(c) : 0;
            fmt::print(" {:>6}", n);
            body += fmt::format("<td>{}</td>", n);
        }
        fmt::print("\n");
        body += "</tr>";
    }
    body += "</table>";
}

// The verdict on every surface's render (heard[i] is the material heard in infos[i]'s render).
void printVerdicts(const std::vector<eng::SurfaceInfo>& infos,
                   const std::vector<std::string>& heard, std::string& body) {
    fmt::print("\nseen sources (the listener trained on every recording, the presets' fit data "
               "among them):\n");
    fmt::print("{:<22} {:<9} {:<9} {:<9} {:<9} {}\n", "surface", "category", "heard cat",
               "material", "heard", "verdict");
    body += "<h2>Seen sources: verdict on every surface (listener trained on all recordings, "
            "those the presets were fitted to among them)</h2><table><tr><th>"
            "surface</th><th>category</th><th>heard category</th><th>material</th><th>heard as</th>"
            "</tr>\n";
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
        fmt::print("{:<22} {:<9} {:<9} {:<9} {:<9} {}{}\n", info.id, cat, heardCat,
                   mat.empty() ? "-" : mat, heard[i],
                   heardCat == cat ? "category ok" : "WRONG category",
                   mat.empty() ? "" : (heard[i] == mat ? ", material ok" : ", wrong material"));
        body += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                            info.id, cat, heardCat, mat.empty() ? "-" : mat, heard[i]);
    }
    fmt::print("seen sources: category right for {}/{}, material right for {}/{} surfaces with a "
               "recorded material\n",
               catOk, n, matOk, matN);
    body += fmt::format("</table><p>Category right for {}/{}; material right for {}/{}.</p>", catOk,
                        n, matOk, matN);
}

// The renders judged by listeners that never heard a source (heardWithoutEachSource): per
// held-out source, the surfaces of a material that source recorded (their category and material
// right or not) and every surface's category; then per surface over those sources.
void printNested(const std::vector<eng::SurfaceInfo>& infos, const std::vector<rl::Example>& recs,
                 const std::vector<rl::Example>& synth, const rl::ListenerOptions& lo,
                 std::string& body) {
    const auto heard = rl::heardWithoutEachSource(recs, synth, lo);
    std::map<std::string, std::set<std::string>> recorded; // source -> materials
    for (const auto& e : recs) recorded[e.source].insert(e.material);
    fmt::print("\nnested (listener trained without the held-out source; the presets are NOT "
               "refitted without it):\n{:<14} {:>14} {:>22}\n",
               "held out", "category (all)", "its materials: cat / mat");
    body += "<h2>Nested: listener trained without each source</h2><p>The presets are not refitted "
            "without the held-out source.</p><table><tr><th>held out</th><th>category, every "
            "surface</th><th>category, surfaces of a material it recorded</th><th>material</th>"
            "</tr>\n";
    std::map<std::string, std::array<int, 3>> perSurface; // id -> (sources, cat ok, mat ok)
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
            auto& ps = perSurface[infos[i].id];
            ++ps[0];
            ps[1] += catOk;
            ps[2] += h[i] == mat;
        }
        fmt::print("{:<14} {:>11}/{:<2} {:>15}/{:<2} {:>2}/{:<2}\n", src, catAll, infos.size(),
                   catOwn, n, matOwn, n);
        body += fmt::format("<tr><td>{}</td><td>{}/{}</td><td>{}/{}</td><td>{}/{}</td></tr>\n", src,
                            catAll, infos.size(), catOwn, n, matOwn, n);
    }
    body += "</table><table><tr><th>surface</th><th>held-out sources that recorded its "
            "material</th><th>category right</th><th>material right</th><th>heard (by held-out "
            "source)</th></tr>\n";
    fmt::print("{:<22} {:>7} {:>8} {:>8}  heard without each source\n", "surface", "sources",
               "category", "material");
    for (std::size_t i = 0; i < infos.size(); ++i) {
        std::string list;
        for (const auto& [src, h] : heard)
            list += fmt::format("{}{}:{}", list.empty() ? "" : " ", src, h[i]);
        const auto it = perSurface.find(infos[i].id);
        const std::array<int, 3> ps =
            it == perSurface.end() ? std::array<int, 3>{0, 0, 0} : it->second;
        fmt::print("{:<22} {:>7} {:>6}/{:<1} {:>6}/{:<1}  {}\n", infos[i].id, ps[0], ps[1], ps[0],
                   ps[2], ps[0], list);
        body += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                            infos[i].id, ps[0], ps[1], ps[2], list);
    }
    body += "</table>";
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
    std::string body = fmt::format(
        "<p>Onset listener (realism/OnsetListener.h), configuration {} chosen among {} by "
        "leave-one-source-out (band {:.0f}-{:.0f} Hz), trained on recordings only.</p>",
        cfg.name(), grid.size(), o.minHz, o.maxHz);
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
    printLoso(rl::leaveOneSourceOut(files, cfg), files.size(), "onset listener " + cfg.name(),
              body);
    const auto nested = rl::nestedLeaveOneSourceOut(files, grid);
    for (const auto& [src, c] : nested.chosen)
        fmt::print("nested: held out {}: chose {} on the other sources\n", src, c.name());
    printLoso(nested.heldOut, files.size(),
              fmt::format("nested estimate (configuration chosen among {} without the held-out "
                          "source)",
                          grid.size()),
              body);
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
    printVerdicts(infos, heard, body);
    if (!a.output.empty()) writeHtml(a.output, "Underfoot listener", body);
    return 0;
}

// The default listener and the first one (realism/Listener.h, --classic-listener).
int runListener(const CompareArgs& a) {
    if (a.onsetListener) return runOnsetListener(a);
    const auto recs = manifest(a);
    rl::AnalysisOptions o;
    o.maxHz = rl::sharedMaxHz(recs, a.spec.rateHz);
    std::vector<rl::Example> ex;
    for (const auto& r : recs) {
        auto steps = rl::describeFile(r.path, o);
        if (steps.empty()) {
            fmt::print("warning: {}: no step found, left out\n", r.file);
            continue;
        }
        ex.push_back({r.file, r.source, r.material, rl::fileFeatures(steps)});
    }
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
    std::string body = fmt::format(
        "<p>Nearest-centroid listener on {} descriptors{} (band {:.0f}-{:.0f} Hz), {}, trained on "
        "recordings only.</p>",
        int(rl::kDescriptorCount),
        lo.scalarsOnly
            ? std::string()
            : fmt::format(" and {} third-octave bands", rl::thirdOctaveCentres(o.maxHz).size()),
        o.minHz, o.maxHz,
        lo.centrePerSource ? "every source centred on its own median, one centroid per source "
                             "and material"
                           : "one centroid per material");
    printLoso(rl::leaveOneSourceOut(ex, lo), ex.size(),
              a.classicListener ? "first listener" : "listener", body);
    rl::Listener l(lo);
    auto trainSet = ex;
    if (lo.centrePerSource) rl::centreBySource(trainSet);
    l.train(trainSet);
    // The renders are one more source: described first, centred on their own median.
    std::vector<rl::Example> synth;
    std::vector<eng::SurfaceInfo> infos;
    for (const auto& info : eng::listSurfaces()) {
        const auto audio = rl::renderForComparison(info.id, a.spec);
        const auto steps = rl::describeSteps(audio, o);
        if (steps.empty()) continue;
        synth.push_back(
            {info.id, "synthetic", rl::materialOfSurface(info.id), rl::fileFeatures(steps)});
        infos.push_back(info);
        if (csv.is_open()) csv << featureLine(synth.back());
    }
    const auto synthUncentred = synth;
    if (lo.centrePerSource) rl::centreBySource(synth);
    std::vector<std::string> heard;
    for (const auto& e : synth) heard.push_back(l.classify(e.features));
    printVerdicts(infos, heard, body);
    // centreBySource above changed synth: heardWithoutEachSource centres its own copies.
    printNested(infos, ex, synthUncentred, lo, body);
    if (!a.output.empty()) writeHtml(a.output, "Underfoot listener", body);
    return 0;
}

int runCompare(const CompareArgs& a) {
    const int modes = int(!a.surface.empty()) + int(a.all) + int(a.listener);
    if (modes != 1)
        throw UserError("compare: give exactly one of --surface S, --all or --listener");
    if (a.classicListener && a.onsetListener)
        throw UserError("compare: give at most one of --classic-listener and --onset-listener");
    if (a.listenerGrid && !a.onsetListener)
        throw UserError("compare: --listener-grid goes with --onset-listener");
    if (!a.real.empty() && a.surface.empty())
        throw UserError("compare: --real goes with --surface");
    try {
        eng::WalkerParameters::parse(a.spec.walker).validate();
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("--walker: ") + e.what());
    }
    if (!a.surface.empty()) return runOne(a);
    try {
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
    cmd->add_option("--walker", args->spec.walker, "virtual walker of the render")
        ->capture_default_str();
    cmd->add_option("--seconds", args->spec.seconds, "length of the render")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 600.0));
    cmd->add_option("--seed", args->spec.seed, "seed of the render")->capture_default_str();
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
    cmd->add_option("--features", args->features,
                    "with --listener: write the listener's features (CSV: name, source, material, "
                    "then one column per feature; with --onset-listener every step of every "
                    "recording, otherwise every file and render)");
    cmd->callback([args, &exitCode] { exitCode = runCompare(*args); });
});

} // namespace
} // namespace underfoot::cli::compare_command
