// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What the parts of `underfoot compare` share (cmd_compare.cpp, cmd_compare_figures.cpp): the
// command's arguments and its tables, printed aligned on the terminal or as Markdown (pasted
// verbatim into docs/reference/realism-figures.md) and appended to the HTML report.
#include "app/cli/CommandRegistry.h"
#include "realism/Compare.h"
#include "realism/Recordings.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::cli::compare_command {

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
    bool markdown = false;        ///< --markdown: the listener's tables as Markdown
    bool refit = false;           ///< --refit: the nested estimate with refitted presets
    bool figures = false;         ///< --figures: per surface and seed, every realism figure
    std::vector<std::uint64_t> seeds{3, 7, 11}; ///< --seeds: the render seeds of --figures
    bool seedsGiven = false;                    ///< --seeds was on the command line
    bool seedGiven = false;                     ///< --seed was on the command line
    int evaluations = 80;                       ///< --evaluations: renders per refit (as fit)
    int threads = 1;                            ///< --threads: refits at once
    realism::RenderSpec spec;
};

// A table printed on the terminal (aligned, or Markdown with --markdown, to paste into the
// docs verbatim) and appended to the HTML report.
struct Table {
    std::vector<std::string> head;
    std::vector<std::vector<std::string>> rows;
    std::size_t leftFrom = 1000; ///< columns from this one on are text, aligned left

    std::string text(bool markdown) const {
        std::vector<std::size_t> w(head.size());
        for (std::size_t c = 0; c < head.size(); ++c) w[c] = head[c].size();
        for (const auto& r : rows)
            for (std::size_t c = 0; c < r.size() && c < w.size(); ++c)
                w[c] = std::max(w[c], r[c].size());
        auto line = [&](const std::vector<std::string>& cells) {
            std::string out = markdown ? "|" : "";
            for (std::size_t c = 0; c < head.size(); ++c) {
                const auto& v = c < cells.size() ? cells[c] : std::string();
                const auto cell =
                    c == 0 ? fmt::format("{:<{}}", v, w[c]) : fmt::format("{:>{}}", v, w[c]);
                out += markdown ? " " + cell + " |" : (c == 0 ? "" : "  ") + cell;
            }
            return out + "\n";
        };
        std::string out = line(head);
        if (markdown) {
            out += "|";
            for (std::size_t c = 0; c < head.size(); ++c) {
                const bool left = c == 0 || c >= leftFrom;
                out += (left ? " :" : " ") + std::string(w[c] - 1, '-') + (left ? " |" : ": |");
            }
            out += "\n";
        }
        for (const auto& r : rows) out += line(r);
        return out;
    }
    std::string html() const {
        std::string out = "<table><tr>";
        for (const auto& h : head) out += "<th>" + h + "</th>";
        out += "</tr>\n";
        for (const auto& r : rows) {
            out += "<tr>";
            for (const auto& v : r) out += "<td>" + v + "</td>";
            out += "</tr>\n";
        }
        return out + "</table>\n";
    }
};

// The listener's output: lines and tables on the terminal (Markdown with --markdown) and in the
// HTML body.
struct Out {
    bool markdown = false;
    std::string body;
    void heading(const std::string& h) {
        if (markdown)
            fmt::print("\n#### {}\n\n", h);
        else
            fmt::print("\n{}:\n", h);
        body += "<h2>" + h + "</h2>\n";
    }
    void line(const std::string& l) {
        fmt::print("{}\n{}", l, markdown ? "\n" : "");
        body += "<p>" + l + "</p>\n";
    }
    void table(const Table& t) {
        fmt::print("{}", t.text(markdown));
        if (markdown) fmt::print("\n");
        body += t.html();
    }
};

/// The recordings cache (--recordings, $UNDERFOOT_RECORDINGS or build/recordings).
inline std::vector<realism::Recording> manifest(const CompareArgs& a) {
    const auto dir = a.recordings.empty() ? realism::defaultRecordingsDir() : a.recordings;
    try {
        return realism::loadManifest(dir);
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
}

/// `compare --figures`: per surface and seed, the nested listener, the distances, flatness,
/// centroid and cost (realism/SurfaceFigures.h).
int runFigures(const CompareArgs& a);

} // namespace underfoot::cli::compare_command
