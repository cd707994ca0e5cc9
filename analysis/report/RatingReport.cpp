// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/RatingReport.h"

#include "analysis/io/Csv.h"

#include "analysis/report/Markup.h"
#include "analysis/report/Words.h"
#include "analysis/stats/Numerics.h"
#include "base/Plural.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace underfoot::analysis {

MeanInterval cellMeanInterval(const RatingCell& cell) {
    MeanInterval m;
    m.n = cell.values.size();
    if (m.n == 0) return m;
    double sum = 0;
    for (const auto& [who, v] : cell.values) sum += v;
    m.mean = sum / static_cast<double>(m.n);
    if (m.n < 2) return m;
    double ss = 0;
    for (const auto& [who, v] : cell.values) ss += (v - m.mean) * (v - m.mean);
    const double se = std::sqrt(ss / static_cast<double>(m.n - 1) / static_cast<double>(m.n));
    const double t = numerics::qt(0.975, static_cast<double>(m.n - 1));
    m.lower = m.mean - t * se;
    m.upper = m.mean + t * se;
    return m;
}

const char* significanceStars(double p) {
    if (std::isnan(p)) return "";
    if (p < 0.001) return "***";
    if (p < 0.01) return "**";
    if (p < 0.05) return "*";
    return "";
}

namespace {

std::string num(double v, int digits = 3) {
    if (std::isnan(v)) return "NA";
    return fmt::format("{:.{}f}", v, digits);
}

std::string pText(double p) {
    if (std::isnan(p)) return "NA";
    if (p < 0.001) return "< 0.001";
    return fmt::format("{:.3f}", p);
}

using markup::latexEscape;
using markup::markdownCell;
using markup::simulatedBannerHtml;
using markup::simulatedNotice;
using markup::xmlEscape;

std::string factorsText(const std::map<std::string, std::string>& factors) {
    std::string out;
    for (const auto& [f, l] : factors) out += fmt::format("{}{}={}", out.empty() ? "" : ", ", f, l);
    return out;
}

std::string statisticText(const TestResult& t) {
    return testInWords(t);
}

/// Markdown table helper.
struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::string markdown() const {
        std::string out = "|";
        for (const auto& h : header) out += " " + markdownCell(h) + " |";
        out += "\n|";
        for (std::size_t i = 0; i < header.size(); ++i) out += " --- |";
        out += "\n";
        for (const auto& r : rows) {
            out += "|";
            for (const auto& c : r) out += " " + markdownCell(c) + " |";
            out += "\n";
        }
        return out;
    }
    std::string html() const {
        std::string out = "<table><thead><tr>";
        for (const auto& h : header) out += "<th>" + xmlEscape(h) + "</th>";
        out += "</tr></thead><tbody>";
        for (const auto& r : rows) {
            out += "<tr>";
            for (const auto& c : r) out += "<td>" + xmlEscape(c) + "</td>";
            out += "</tr>";
        }
        return out + "</tbody></table>\n";
    }
    std::string latex() const {
        std::string out = "\\begin{tabular}{" + std::string(header.size(), 'l') + "}\n\\toprule\n";
        for (std::size_t i = 0; i < header.size(); ++i)
            out += (i ? " & " : "") + latexEscape(header[i]);
        out += " \\\\\n\\midrule\n";
        for (const auto& r : rows) {
            for (std::size_t i = 0; i < r.size(); ++i) out += (i ? " & " : "") + latexEscape(r[i]);
            out += " \\\\\n";
        }
        return out + "\\bottomrule\n\\end{tabular}\n";
    }
};

Table cellTable(const ScaleAnalysis& s, const RatingLabels& labels) {
    Table t{{"condition", "id", "factors", "n", "mean [95% CI]", "median", "IQR (Q1-Q3)",
             "Shapiro-Wilk p"},
            {}};
    for (const auto& c : s.cells) {
        const auto m = cellMeanInterval(c);
        t.rows.push_back(
            {labels.stimulus(c.stimulus), c.stimulus, factorsText(c.factors),
             std::to_string(c.box.n),
             fmt::format("{} [{}, {}]", num(m.mean, 2), num(m.lower, 2), num(m.upper, 2)),
             num(c.box.median, 2), fmt::format("{}-{}", num(c.box.q1, 2), num(c.box.q3, 2)),
             c.shapiro.ok() ? pText(c.shapiro.p) : "NA"});
    }
    return t;
}

Table pairTable(const std::vector<PairedComparison>& pairs, const RatingLabels& labels) {
    Table t{{"comparison", "context", "medians", "pairs", "Z", "p", "p (Holm)", "", "in words"},
            {}};
    for (const auto& p : pairs)
        t.rows.push_back(
            {labels.stimulus(p.first) + " vs " + labels.stimulus(p.second), p.context,
             num(p.medianFirst, 2) + " / " + num(p.medianSecond, 2), std::to_string(p.pairs),
             num(p.test.z), pText(p.test.p), pText(p.pHolm), significanceStars(p.pHolm),
             statisticInWords("Z", p.test.z, p.test.p) + " (Holm: " + pInWords(p.pHolm) + ")"});
    return t;
}

struct Figure {
    std::string caption;
    std::string svg;
};

struct Section {
    std::string heading;
    std::string text;
    std::vector<Table> tables;
    std::vector<Figure> figures;
};

std::string warningsText(const std::vector<std::string>& warnings) {
    std::string w;
    for (const auto& x : warnings) w += (w.empty() ? "" : "; ") + x.substr(0, x.find('\n'));
    return w;
}

/// The Friedman (or Wilcoxon) test of the cells, the LMM and the clmm on every rating.
Table modelTable(const ScaleAnalysis& s) {
    const auto& m = s.models;
    Table t{
        {"test of the stimulus", "on", "statistic", "df", "p", "participant variance", "warnings"},
        {}};
    t.rows.push_back({s.omnibus.conditions.size() >= 3 ? "Friedman (friedman.test)"
                                                       : "Wilcoxon signed-rank (wilcox.test)",
                      "cell means of " + counted(s.omnibus.participants, "participant"),
                      num(s.omnibus.result.statistic),
                      s.omnibus.result.df.empty() ? "" : num(s.omnibus.result.df[0], 3),
                      pText(s.omnibus.result.p), "", s.omnibus.result.error});
    auto model = [&](const std::string& name, const MixedModelResult& r) {
        if (!r.ok()) {
            t.rows.push_back({name, counted(m.ratings, "rating"), "", "", "", "", r.error});
            return;
        }
        t.rows.push_back({name, counted(static_cast<std::size_t>(r.nObs), "rating"),
                          "LRT X² = " + num(r.lrt.statistic), num(r.lrt.df, 3), pText(r.lrt.p),
                          num(r.randomVariance), warningsText(r.warnings)});
    };
    model("LMM (lmerTest::lmer, REML; LRT by ML)", m.lmm);
    if (m.clmmSkipped.empty())
        model("clmm (ordinal::clmm, logit, Laplace)", m.clmm);
    else
        t.rows.push_back({"clmm (ordinal::clmm)", "", "", "", "", "", m.clmmSkipped});
    return t;
}

std::vector<Section> sections(const RatingStudyAnalysis& a, const RatingLabels& labels) {
    std::vector<Section> out;
    for (const auto& s : a.scales) {
        Section sec;
        sec.heading = fmt::format("Scale {} ({} to {})", s.scale.id, s.scale.min, s.scale.max);
        sec.text = fmt::format(
            "{}{}\n\nParticipants: {}. Cell values are each participant's mean rating of the "
            "stimulus. Levene (Brown-Forsythe) across cells: {}. {} across cells ({} "
            "participants with every cell): {}.",
            s.scale.prompt, s.scale.anchors.empty() ? "" : " Anchors: " + s.scale.anchors + ".",
            s.participants, statisticText(s.levene),
            s.omnibus.conditions.size() >= 3 ? "Friedman test" : "Wilcoxon signed-rank test",
            s.omnibus.participants, statisticText(s.omnibus.result));
        sec.tables.push_back(cellTable(s, labels));
        if (s.models.fitted) {
            sec.text += fmt::format(
                "\n\nMixed models of the stimulus effect on every rating ({} ~ stimulus + (1 | "
                "participant)), beside the {}. {}",
                s.scale.id,
                s.omnibus.conditions.size() >= 3 ? "Friedman test" : "Wilcoxon signed-rank test",
                s.models.advice);
            sec.tables.push_back(modelTable(s));
        }
        if (!s.planned.empty()) sec.tables.push_back(pairTable(s.planned, labels));
        for (const auto& fe : s.factorEffects) {
            Table t{{"level of " + fe.factor, "n", "median", "IQR (Q1-Q3)"}, {}};
            for (std::size_t i = 0; i < fe.levels.size(); ++i)
                t.rows.push_back({fe.levels[i], std::to_string(fe.levelStats[i].n),
                                  num(fe.levelStats[i].median, 2),
                                  fmt::format("{}-{}", num(fe.levelStats[i].q1, 2),
                                              num(fe.levelStats[i].q3, 2))});
            sec.text += fmt::format("\n\nMain effect of {} (each participant's median over the "
                                    "other factors; {}): {}.",
                                    fe.factor, counted(fe.omnibus.participants, "participant"),
                                    statisticText(fe.omnibus.result));
            sec.tables.push_back(t);
            sec.tables.push_back(pairTable(fe.pairs, labels));
        }
        for (const auto& g : s.groups) {
            Table t{{g.field, "n", "median", "IQR (Q1-Q3)"}, {}};
            for (const auto& grp : g.groups)
                t.rows.push_back({grp.level, std::to_string(grp.n), num(grp.median, 2),
                                  fmt::format("{}-{}", num(grp.q1, 2), num(grp.q3, 2))});
            sec.text += fmt::format("\n\nBetween participants by {} (each participant's median "
                                    "rating): {}.",
                                    g.field, statisticText(g.kruskal));
            sec.tables.push_back(t);
            if (!g.pairs.empty()) {
                Table mw{{"comparison", "W", "p", "p (Holm)", "", "in words"}, {}};
                for (const auto& p : g.pairs)
                    mw.rows.push_back({p.first + " vs " + p.second, num(p.test.statistic),
                                       pText(p.test.p), pText(p.pHolm), significanceStars(p.pHolm),
                                       testInWords(p.test) + " (Holm: " + pInWords(p.pHolm) + ")"});
                sec.tables.push_back(mw);
            }
        }
        sec.figures.push_back(
            {fmt::format("{}: mean rating per condition with its 95 % confidence interval (t), "
                         "each participant's mean rating of the condition as a grey point",
                         s.scale.id),
             ratingMeansSvg(s, labels)});
        sec.figures.push_back({fmt::format("{}: box plots (median, quartiles, Tukey whiskers; "
                                           "outliers as circles, extremes as dots)",
                                           s.scale.id),
                               ratingBoxPlotSvg(s, labels)});
        out.push_back(std::move(sec));
    }
    if (!a.correlations.empty()) {
        Section sec;
        sec.heading = "Spearman correlations between scales";
        sec.text = "Over (participant, stimulus) cells rated on both scales; R's cor.test(method "
                   "= \"spearman\") p-values, Holm-corrected across all pairs in the last column.";
        Table t{{"scales", "n", "rho", "p", "p (Holm)", "", "in words"}, {}};
        for (const auto& c : a.correlations) {
            const double rho = c.test.estimate.empty() ? std::nan("") : c.test.estimate[0].value;
            t.rows.push_back(
                {c.first + " ~ " + c.second, std::to_string(c.n), num(rho), pText(c.test.p),
                 pText(c.pHolm), significanceStars(c.test.p),
                 statisticInWords("ρ", rho, c.test.p) + " (n = " + std::to_string(c.n) + ")"});
        }
        sec.tables.push_back(t);
        out.push_back(std::move(sec));
    }
    return out;
}

constexpr const char* kMethods =
    "Medians and quartiles: R's quantile(type = 7). Friedman: friedman.test; Wilcoxon "
    "signed-rank: Z from the normal approximation with tie correction and without continuity "
    "correction, zero differences dropped, as SPSS reports it (R: wilcox.test(paired = TRUE, "
    "exact = FALSE, correct = FALSE) gives the same p); Holm: p.adjust(method = \"holm\") within "
    "each family (the planned comparisons of a scale; the pairs of a main effect); "
    "Kruskal-Wallis: kruskal.test; Mann-Whitney: wilcox.test(exact = FALSE, correct = FALSE) with "
    "Holm, only after a significant Kruskal-Wallis test. Significance: * p < 0.05, ** p < 0.01, "
    "*** p < 0.001 (corrected p where given). Means with 95 % confidence intervals: t "
    "intervals over the participants' cell values (mean ± qt(0.975, n - 1) SD / sqrt(n)).";

} // namespace

namespace {

/// The frame shared by the rating figures: a value axis over the scale's range with its title,
/// one slot per cell with the cell's label turned under it, and the x-axis title.
struct PlotFrame {
    double cellW = 64, left = 72, right = 16, top = 34, plotH = 220, bottom = 0;
    double width = 0, height = 0, lo = 0, hi = 1;
    double y(double v) const { return top + plotH * (1 - (v - lo) / (hi - lo)); }
    double x(std::size_t cell) const { return left + cellW * (static_cast<double>(cell) + 0.5); }
};

PlotFrame plotFrame(const ScaleAnalysis& s, const RatingLabels& labels) {
    PlotFrame f;
    std::size_t longest = 0;
    for (const auto& c : s.cells) longest = std::max(longest, labels.stimulus(c.stimulus).size());
    // ~6.5 px per character at 11 px, turned by 40 degrees (sin 40 = 0.64), then the axis title.
    f.bottom = 20 + std::min(200.0, static_cast<double>(longest) * 6.5 * 0.64) + 28;
    // The first cell's label reaches left by its length x cos 40 = 0.77: room for it.
    f.left = std::max(f.left, std::min(200.0, static_cast<double>(longest) * 6.5 * 0.77) -
                                  f.cellW / 2 + 12);
    f.width =
        f.left + f.right + f.cellW * static_cast<double>(std::max<std::size_t>(1, s.cells.size()));
    f.height = f.top + f.plotH + f.bottom;
    f.lo = s.scale.min;
    f.hi = s.scale.max > s.scale.min ? s.scale.max : s.scale.min + 1;
    return f;
}

void openFigure(std::ostringstream& o, const PlotFrame& f, const ScaleAnalysis& s,
                const RatingLabels& labels, const std::string& cssClass,
                const std::string& heading) {
    o << fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"{}\" width=\"{:.0f}\" "
                     "height=\"{:.0f}\" viewBox=\"0 0 {:.0f} {:.0f}\" font-family=\"sans-serif\" "
                     "font-size=\"11\">\n",
                     cssClass, f.width, f.height, f.width, f.height);
    o << fmt::format("<title>{}</title>\n", xmlEscape(s.scale.id + ": " + s.scale.prompt));
    o << fmt::format("<text x=\"{:.0f}\" y=\"16\" font-size=\"13\">{}</text>\n", f.left,
                     xmlEscape(heading));
    const double step = (f.hi - f.lo) > 12 ? std::ceil((f.hi - f.lo) / 10) : 1;
    for (double v = f.lo; v <= f.hi + 1e-9; v += step) {
        o << fmt::format("<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" "
                         "stroke=\"#e0e0e0\"/>\n",
                         f.left, f.width - f.right, f.y(v), f.y(v));
        o << fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{:g}</text>\n",
                         f.left - 6, f.y(v) + 4, v);
    }
    o << fmt::format("<line x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" y2=\"{2:.1f}\" "
                     "stroke=\"black\"/>\n",
                     f.left, f.top, f.top + f.plotH);
    o << fmt::format(
        "<text class=\"axis-title\" transform=\"translate(18,{:.1f}) rotate(-90)\" "
        "text-anchor=\"middle\" font-weight=\"bold\">{}</text>\n",
        f.top + f.plotH / 2,
        xmlEscape(fmt::format("Rating: {} ({:g} to {:g})", s.scale.id, s.scale.min, s.scale.max)));
    o << fmt::format("<text class=\"axis-title\" x=\"{:.1f}\" y=\"{:.1f}\" "
                     "text-anchor=\"middle\" font-weight=\"bold\">Condition</text>\n",
                     f.left + (f.width - f.left - f.right) / 2, f.height - 8);
    for (std::size_t i = 0; i < s.cells.size(); ++i)
        o << fmt::format("<text class=\"cell-label\" transform=\"translate({:.1f},{:.1f}) "
                         "rotate(-40)\" text-anchor=\"end\">{}<title>{}</title></text>\n",
                         f.x(i) + 4, f.top + f.plotH + 14,
                         xmlEscape(labels.stimulus(s.cells[i].stimulus)),
                         xmlEscape(s.cells[i].stimulus));
}

} // namespace

std::string ratingMeansSvg(const ScaleAnalysis& s, const RatingLabels& labels) {
    const PlotFrame f = plotFrame(s, labels);
    std::ostringstream o;
    openFigure(o, f, s, labels, "rating-means", s.scale.id + ": means with 95 % CI");
    const auto inside = [&](double v) { return std::clamp(v, f.lo, f.hi); }; // drawing only
    for (std::size_t i = 0; i < s.cells.size(); ++i) {
        const auto& c = s.cells[i];
        const double cx = f.x(i);
        // Every participant's value: spread sideways in a fixed pattern of 7 columns.
        std::size_t k = 0;
        for (const auto& [who, v] : c.values) {
            const double dx = (static_cast<double>(k++ % 7) - 3.0) * 3.0;
            o << fmt::format("<circle class=\"point\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" "
                             "fill=\"#8c8c8c\" fill-opacity=\"0.6\"><title>{}: {:g}</title>"
                             "</circle>\n",
                             cx - 14 + dx, f.y(v), xmlEscape(who), v);
        }
        const auto m = cellMeanInterval(c);
        if (m.n == 0) continue;
        const std::string tip =
            m.n >= 2 ? fmt::format("{}: mean {:.2f}, 95 % CI {:.2f} to {:.2f}, n {}",
                                   labels.stimulus(c.stimulus), m.mean, m.lower, m.upper, m.n)
                     : fmt::format("{}: mean {:.2f}, n 1 (no interval)",
                                   labels.stimulus(c.stimulus), m.mean);
        if (m.n >= 2) {
            const double y1 = f.y(inside(m.upper)), y2 = f.y(inside(m.lower));
            o << fmt::format("<line class=\"ci\" x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" "
                             "y2=\"{2:.1f}\" stroke=\"#1f4e79\" stroke-width=\"2\"/>\n",
                             cx + 8, y1, y2);
            for (double yy : {y1, y2})
                o << fmt::format("<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" "
                                 "y2=\"{:.1f}\" stroke=\"#1f4e79\" stroke-width=\"2\"/>\n",
                                 cx + 3, cx + 13, yy, yy);
        }
        o << fmt::format("<circle class=\"mean\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4.5\" "
                         "fill=\"#1f4e79\"><title>{}</title></circle>\n",
                         cx + 8, f.y(m.mean), xmlEscape(tip));
    }
    o << "</svg>\n";
    return o.str();
}

std::string ratingBoxPlotSvg(const ScaleAnalysis& s, const RatingLabels& labels) {
    const PlotFrame f = plotFrame(s, labels);
    const auto y = [&](double v) { return f.y(v); };
    // Colour by the first factor's level (the paper: dark / light blue by depth).
    static const char* kPalette[] = {"#1f4e79", "#8fb8de", "#4a90c2",
                                     "#c6dbef", "#2c7fb8", "#a6bddb"};
    std::map<std::string, std::size_t> colourOf;
    std::string firstFactor = s.cells.empty() || s.cells.front().factors.empty()
                                  ? std::string()
                                  : s.cells.front().factors.begin()->first;
    std::ostringstream o;
    openFigure(o, f, s, labels, "rating-boxes", s.scale.id + ": box plots");
    for (std::size_t i = 0; i < s.cells.size(); ++i) {
        const auto& c = s.cells[i];
        const auto& b = c.box;
        const double cx = f.x(i);
        std::string level;
        if (!firstFactor.empty() && c.factors.count(firstFactor)) level = c.factors.at(firstFactor);
        const std::size_t colour = colourOf.try_emplace(level, colourOf.size()).first->second;
        const char* fill = kPalette[colour % 6];
        if (b.n == 0) continue;
        o << fmt::format("<line x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" y2=\"{2:.1f}\" "
                         "stroke=\"black\"/>\n",
                         cx, y(b.whiskerHigh), y(b.q3));
        o << fmt::format("<line x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" y2=\"{2:.1f}\" "
                         "stroke=\"black\"/>\n",
                         cx, y(b.q1), y(b.whiskerLow));
        for (double w : {b.whiskerLow, b.whiskerHigh})
            o << fmt::format("<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" "
                             "stroke=\"black\"/>\n",
                             cx - 8, cx + 8, y(w), y(w));
        o << fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" "
                         "fill=\"{}\" stroke=\"black\"><title>{}: median {:g}, IQR {:g}-{:g}, "
                         "n {}</title></rect>\n",
                         cx - 16, y(b.q3), 32.0, std::max(1.0, y(b.q1) - y(b.q3)), fill,
                         xmlEscape(labels.stimulus(c.stimulus)), b.median, b.q1, b.q3, b.n);
        o << fmt::format("<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" "
                         "stroke=\"#d62728\" stroke-width=\"2\"/>\n",
                         cx - 16, cx + 16, y(b.median), y(b.median));
        for (double v : b.outliers)
            o << fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"none\" "
                             "stroke=\"black\"/>\n",
                             cx, y(v));
        for (double v : b.extremes)
            o << fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"black\"/>\n", cx,
                             y(v));
    }
    o << "</svg>\n";
    return o.str();
}

std::string renderRatingReport(const RatingStudyAnalysis& a, ReportFormat format,
                               const RatingLabels& labels) {
    const auto secs = sections(a, labels);
    const std::string title = a.title.empty() ? "Rating study" : a.title;
    std::string out;
    switch (format) {
    case ReportFormat::Markdown: {
        out += fmt::format("# {}\n\n", title);
        if (labels.simulatedParticipants > 0)
            out += "**" +
                   simulatedNotice(labels.simulatedParticipants, static_cast<int>(a.participants)) +
                   "**\n\n";
        out += fmt::format("{}. {}\n", counted(a.participants, "participant"), kMethods);
        for (const auto& s : secs) {
            out += fmt::format("\n## {}\n\n{}\n\n", s.heading, s.text);
            for (const auto& t : s.tables) out += t.markdown() + "\n";
            for (const auto& fig : s.figures) out += fig.svg + "\n";
        }
        break;
    }
    case ReportFormat::Html: {
        out += fmt::format("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{}</title>"
                           "<style>body{{font-family:sans-serif;max-width:70em;margin:auto}}"
                           "table{{border-collapse:collapse;margin:0.6em 0}}td,th{{border:1px "
                           "solid #ccc;padding:2px 6px}}</style></head><body>\n<h1>{}</h1>\n"
                           "<p>{}. {}</p>\n",
                           xmlEscape(title), xmlEscape(title),
                           counted(a.participants, "participant"), xmlEscape(kMethods));
        out += simulatedBannerHtml(labels.simulatedParticipants, static_cast<int>(a.participants));
        for (const auto& s : secs) {
            out += fmt::format("<h2>{}</h2>\n", xmlEscape(s.heading));
            std::string text = xmlEscape(s.text);
            for (std::size_t at; (at = text.find("\n\n")) != std::string::npos;)
                text.replace(at, 2, "</p><p>");
            out += "<p>" + text + "</p>\n";
            for (const auto& fig : s.figures)
                out += "<figure>\n" + fig.svg + "<figcaption>" + xmlEscape(fig.caption) +
                       "</figcaption>\n</figure>\n";
            for (const auto& t : s.tables) out += t.html();
        }
        out += "</body></html>\n";
        break;
    }
    case ReportFormat::Latex: {
        out += fmt::format("% {}\n", title);
        for (std::size_t i = 0; i < secs.size(); ++i) {
            const auto& s = secs[i];
            out += fmt::format("% {}\n", s.heading);
            if (i < a.scales.size() && !a.scales[i].models.advice.empty())
                out += "% " + a.scales[i].models.advice + "\n";
            for (const auto& t : s.tables) out += t.latex() + "\n";
        }
        break;
    }
    case ReportFormat::Csv: {
        out += std::string(kRatingTidyCsvHeader) + "\n";
        auto row = [&](const std::string& section, const std::string& scale,
                       const std::string& subject, const std::string& comparison,
                       const std::string& statistic, double value) {
            out +=
                fmt::format("{},{},{},{},{},{}\n", csv::escape(section), csv::escape(scale),
                            csv::escape(subject), csv::escape(comparison), csv::escape(statistic),
                            std::isnan(value) ? "" : fmt::format("{:.6g}", value));
        };
        for (const auto& s : a.scales) {
            for (const auto& c : s.cells) {
                row("cell", s.scale.id, c.stimulus, "", "n", static_cast<double>(c.box.n));
                row("cell", s.scale.id, c.stimulus, "", "median", c.box.median);
                row("cell", s.scale.id, c.stimulus, "", "q1", c.box.q1);
                row("cell", s.scale.id, c.stimulus, "", "q3", c.box.q3);
            }
            row("omnibus", s.scale.id, "cells", "", s.omnibus.result.statisticName,
                s.omnibus.result.statistic);
            row("omnibus", s.scale.id, "cells", "", "p", s.omnibus.result.p);
            if (s.models.fitted) {
                const bool clmm = s.models.clmmSkipped.empty() && s.models.clmm.ok();
                auto model = [&](const char* name, const MixedModelResult& r, bool cite) {
                    if (!r.ok()) return;
                    const std::string cmp = cite ? "cite" : "";
                    row("model", s.scale.id, name, cmp, "lrt_statistic", r.lrt.statistic);
                    row("model", s.scale.id, name, cmp, "lrt_df", r.lrt.df);
                    row("model", s.scale.id, name, cmp, "lrt_p", r.lrt.p);
                    row("model", s.scale.id, name, cmp, "participant_variance", r.randomVariance);
                    row("model", s.scale.id, name, cmp, "loglik", r.logLik);
                };
                model("lmm", s.models.lmm, !clmm);
                if (clmm) model("clmm", s.models.clmm, true);
                out += fmt::format("advice,{},{},,,\n", s.scale.id, csv::escape(s.models.advice));
            }
            for (const auto& p : s.planned) {
                const std::string cmp = p.first + " vs " + p.second;
                row("planned", s.scale.id, p.context, cmp, "z", p.test.z);
                row("planned", s.scale.id, p.context, cmp, "p", p.test.p);
                row("planned", s.scale.id, p.context, cmp, "p_holm", p.pHolm);
            }
            for (const auto& fe : s.factorEffects) {
                row("factor", s.scale.id, fe.factor, "", fe.omnibus.result.statisticName,
                    fe.omnibus.result.statistic);
                row("factor", s.scale.id, fe.factor, "", "p", fe.omnibus.result.p);
                for (const auto& p : fe.pairs) {
                    const std::string cmp = p.first + " vs " + p.second;
                    row("factor_pair", s.scale.id, fe.factor, cmp, "z", p.test.z);
                    row("factor_pair", s.scale.id, fe.factor, cmp, "p_holm", p.pHolm);
                }
            }
            for (const auto& g : s.groups) {
                row("groups", s.scale.id, g.field, "", "H", g.kruskal.statistic);
                row("groups", s.scale.id, g.field, "", "p", g.kruskal.p);
            }
        }
        for (const auto& c : a.correlations) {
            row("spearman", c.first, c.second, "", "rho",
                c.test.estimate.empty() ? std::nan("") : c.test.estimate[0].value);
            row("spearman", c.first, c.second, "", "p", c.test.p);
        }
        break;
    }
    }
    return out;
}

} // namespace underfoot::analysis
