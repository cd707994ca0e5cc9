// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/report/Export.h"

#include "analysis/report/Markup.h"
#include "analysis/report/Words.h"

#include "analysis/io/Csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace underfoot::analysis {

std::optional<ReportFormat> parseReportFormat(std::string_view name) {
    if (name == "csv") return ReportFormat::Csv;
    if (name == "latex" || name == "tex") return ReportFormat::Latex;
    if (name == "markdown" || name == "md") return ReportFormat::Markdown;
    if (name == "html") return ReportFormat::Html;
    return std::nullopt;
}

namespace {

using markup::latexEscape;
using markup::markdownCell;
using markup::simulatedBannerHtml;
using markup::simulatedNotice;
using markup::xmlEscape;

// ------------------------------------------------------------------ shared helpers

std::string full(double v) {
    return std::isnan(v) ? std::string() : fmt::format("{}", v);
}

std::string fixed(double v, int digits) {
    if (std::isnan(v)) return "NA";
    if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
    return fmt::format("{:.{}f}", v, digits);
}

std::string pValue(double p) {
    if (std::isnan(p)) return "NA";
    if (p < 0.001) return "< 0.001";
    return fmt::format("{:.4f}", p);
}

std::string count(double v) {
    return fmt::format("{}", static_cast<long long>(std::llround(v)));
}

/// A surface's label: the protocol's (its answer list) when it lists the surface, else the
/// catalogue's.
std::string surfaceLabel(const std::string& id, const AnswerList* answers) {
    if (answers)
        if (auto i = answers->indexOf(id); i && !answers->options[*i].label.empty())
            return answers->options[*i].label;
    return labelFor(id);
}

std::string stimulusLabel(const StimulusKey& k, const AnswerList* answers = nullptr) {
    return k.soundscapeId.empty()
               ? surfaceLabel(k.surfaceId, answers)
               : surfaceLabel(k.surfaceId, answers) + " / " + labelFor(k.soundscapeId);
}

std::string columnCode(const std::string& id) {
    if (id == kDontKnowId) return "DK";
    if (auto s = findSurface(id)) return s->code;
    return id;
}

std::string dfText(const TestResult& t) {
    std::string out;
    for (std::size_t i = 0; i < t.df.size(); ++i)
        out += (i ? ", " : "") + fixed(t.df[i], t.df[i] == std::round(t.df[i]) ? 0 : 2);
    return out.empty() ? "NA" : out;
}

/// A plain table shared by the LaTeX, Markdown and HTML renderers.
struct TextTable {
    std::string caption;
    std::vector<std::string> header;
    std::vector<bool> numeric; ///< right-aligned columns
    std::vector<std::vector<std::string>> rows;
};

TextTable confusionTable(const ConfusionMatrix& m) {
    TextTable t;
    t.caption = fmt::format("Confusion matrix, {} (counts; rows = presented stimulus)", m.group);
    t.header.push_back("Stimulus");
    t.numeric.push_back(false);
    for (const auto& o : m.columns.options) {
        t.header.push_back(columnCode(o.id));
        t.numeric.push_back(true);
    }
    t.header.push_back("n");
    t.numeric.push_back(true);
    for (std::size_t i = 0; i < m.rows.size(); ++i) {
        std::vector<std::string> row{stimulusLabel(m.rows[i])};
        for (double v : m.counts[i]) row.push_back(count(v));
        row.push_back(count(m.rowTotal(i)));
        t.rows.push_back(std::move(row));
    }
    return t;
}

TextTable categoryTable(const CategoryMatrix& m) {
    TextTable t;
    t.caption = fmt::format("Category recognition, {} (row %)", m.group);
    t.header.push_back("Presented");
    t.numeric.push_back(false);
    for (const auto& c : m.columns) {
        t.header.push_back(c == "dont_know" ? "don't know" : c);
        t.numeric.push_back(true);
    }
    for (std::size_t i = 0; i < m.rows.size(); ++i) {
        std::vector<std::string> row{categoryName(m.rows[i])};
        for (std::size_t j = 0; j < m.columns.size(); ++j)
            row.push_back(fixed(m.rowPercent(i, j), 1) + " (" + count(m.counts[i][j]) + ")");
        t.rows.push_back(std::move(row));
    }
    return t;
}

TextTable summaryTable(const AnalysisReport& r) {
    TextTable t;
    const bool anySoundscape =
        std::any_of(r.summary.begin(), r.summary.end(),
                    [](const SummaryRow& s) { return s.soundscapeCorrect.n > 0; });
    // The caption says what the columns below hold, no more.
    t.caption = "Per-stimulus summary: % with 95% Wilson interval";
    if (r.hasRatings)
        t.caption += "; realism on correct answers only, quality on all answers except \"I "
                     "don't know\" (mean ± SD)";
    if (anySoundscape) t.caption += "; % soundscape: the soundscape named correctly";
    t.header = {"Group", "Stimulus", "n", "% correct", "% wrong", "% don't know"};
    t.numeric = {false, false, true, true, true, true};
    if (r.hasRatings) {
        t.header.insert(t.header.end(), {"Realism", "Quality"});
        t.numeric.insert(t.numeric.end(), {true, true});
    }
    if (anySoundscape) {
        t.header.push_back("% soundscape");
        t.numeric.push_back(true);
    }
    auto pct = [](const Proportion& p) {
        if (p.n == 0) return std::string("NA");
        return fixed(p.percent, 2) + " [" + fixed(p.wilson.lower, 1) + ", " +
               fixed(p.wilson.upper, 1) + "]";
    };
    auto mean = [](const MeanSummary& m) {
        if (m.n == 0) return std::string("NA");
        return fixed(m.mean, 2) + " ± " + fixed(m.sd, 2) + " (n=" + count(m.n) + ")";
    };
    for (const auto& s : r.summary) {
        std::vector<std::string> row{s.group,      stimulusLabel(s.stimulus),
                                     count(s.n),   pct(s.correct),
                                     pct(s.wrong), pct(s.dontKnow)};
        if (r.hasRatings) {
            row.push_back(mean(s.realism));
            row.push_back(mean(s.quality));
        }
        if (anySoundscape) row.push_back(pct(s.soundscapeCorrect));
        t.rows.push_back(std::move(row));
    }
    return t;
}

/// `words`: with the "In words" column (χ² ... ; not in LaTeX, whose tables keep to ASCII).
TextTable comparisonTable(const AnalysisReport& r, bool words = true) {
    TextTable t;
    t.caption = "Between-group comparisons: chi-square with Yates' correction on correct vs "
                "not correct (Fisher's exact p as a check), Welch t-tests on ratings; Holm "
                "adjustment across surfaces";
    t.header = {"Measure", "Surface", "Groups",   "A",        "B",      "Statistic",
                "df",      "p",       "p (Holm)", "Fisher p", "Effect", "In words"};
    t.numeric = {false, false, false, true, true, true, true, true, true, true, true, false};
    for (const auto& c : r.comparisons) {
        const bool counts = c.measure == Measure::Correct || c.measure == Measure::DontKnow;
        auto value = [&](double v, double n) {
            return (counts ? fixed(v, 1) + "%" : fixed(v, 2)) + " (n=" + count(n) + ")";
        };
        std::vector<std::string> row{
            measureName(c.measure), c.surfaceId.empty() ? "all" : labelFor(c.surfaceId),
            c.groupA + " vs " + c.groupB, value(c.valueA, c.nA), value(c.valueB, c.nB)};
        if (c.test.ok()) {
            row.push_back((c.test.statisticName == "t" ? "t = " : "X² = ") +
                          fixed(c.test.statistic, 4));
            row.push_back(dfText(c.test));
            row.push_back(pValue(c.test.p));
            row.push_back(pValue(c.pHolm));
        } else {
            row.push_back(c.test.error);
            row.push_back("");
            row.push_back("NA");
            row.push_back("NA");
        }
        row.push_back(counts ? pValue(c.fisherP) : "");
        row.push_back(std::isnan(c.effect) ? "NA" : c.effectName + " = " + fixed(c.effect, 3));
        if (words) row.push_back(testInWords(c.test));
        t.rows.push_back(std::move(row));
    }
    return t;
}

TextTable mixedModelTable(const AnalysisReport& r) {
    TextTable t;
    t.caption = "Mixed models beside the comparisons (participant as random intercept): "
                "logistic (glmer) on correct answers; linear (lmer, REML, Satterthwaite df) and "
                "cumulative link (clmm, logit) on ratings; estimate = group B against group A "
                "(log-odds ratio / mean difference / log-odds ratio of a higher rating); LRT = "
                "likelihood-ratio test of the group; \"all\" has surface as a fixed factor; "
                "classic p = chi-square / t-test; Mann-Whitney p = wilcox.test of the ratings";
    t.header = {"Measure",
                "Surface",
                "Groups",
                "Model",
                "Estimate (SE)",
                "z / t",
                "df",
                "p (Wald)",
                "LRT X²",
                "p (LRT)",
                "Participant var.",
                "Classic p",
                "Mann-Whitney p",
                "Warnings"};
    t.numeric = {false, false, false, false, true, true, true,
                 true,  true,  true,  true,  true, true, false};
    for (const auto& m : r.mixedModels) {
        std::vector<std::string> row{measureName(m.measure),
                                     m.surfaceId.empty() ? "all" : labelFor(m.surfaceId),
                                     m.groupA + " vs " + m.groupB, m.model};
        if (!m.error.empty()) {
            row.push_back(m.error);
            for (int k = 0; k < 7; ++k) row.push_back("");
            row.push_back(std::isnan(m.classicP) ? "" : pValue(m.classicP));
            row.push_back(std::isnan(m.nonparametricP) ? "" : pValue(m.nonparametricP));
            row.push_back("");
        } else {
            row.push_back(fixed(m.estimate, 3) + " (" + fixed(m.se, 3) + ")");
            row.push_back(fixed(m.statistic, 3));
            row.push_back(std::isnan(m.df) ? "" : fixed(m.df, 1));
            row.push_back(pValue(m.p));
            row.push_back(fixed(m.lrtStatistic, 3));
            row.push_back(pValue(m.lrtP));
            row.push_back(fixed(m.randomVariance, 3));
            row.push_back(std::isnan(m.classicP) ? "" : pValue(m.classicP));
            row.push_back(std::isnan(m.nonparametricP) ? "" : pValue(m.nonparametricP));
            std::string w;
            for (const auto& x : m.warnings) {
                std::string one = x.substr(0, x.find('\n'));
                w += (w.empty() ? "" : "; ") + one;
            }
            row.push_back(w);
        }
        t.rows.push_back(std::move(row));
    }
    return t;
}

std::vector<TextTable> allTables(const AnalysisReport& r, bool words = true) {
    std::vector<TextTable> tables;
    for (const auto& m : r.confusions) tables.push_back(confusionTable(m));
    for (const auto& m : r.categories) tables.push_back(categoryTable(m));
    tables.push_back(summaryTable(r));
    if (!r.comparisons.empty()) tables.push_back(comparisonTable(r, words));
    if (!r.mixedModels.empty()) tables.push_back(mixedModelTable(r));
    return tables;
}

// ------------------------------------------------------------------ tidy CSV

void tidy(std::string& out, const std::string& table, const std::string& group,
          const std::string& stimulus, const std::string& soundscape, const std::string& column,
          const std::string& statistic, double value, const std::string& note = {}) {
    out +=
        csv::joinLine({table, group, stimulus, soundscape, column, statistic, full(value), note});
    out += '\n';
}

std::string renderCsv(const AnalysisReport& r) {
    std::string out(kTidyCsvHeader);
    out += '\n';
    for (const auto& m : r.confusions)
        for (std::size_t i = 0; i < m.rows.size(); ++i)
            for (std::size_t j = 0; j < m.columns.options.size(); ++j) {
                const auto& row = m.rows[i];
                const auto& id = m.columns.options[j].id;
                tidy(out, "confusion", m.group, row.surfaceId, row.soundscapeId, id, "count",
                     m.counts[i][j]);
                tidy(out, "confusion", m.group, row.surfaceId, row.soundscapeId, id, "row_percent",
                     m.rowPercent(i, j));
            }
    for (const auto& m : r.categories)
        for (std::size_t i = 0; i < m.rows.size(); ++i)
            for (std::size_t j = 0; j < m.columns.size(); ++j) {
                tidy(out, "category", m.group, categoryName(m.rows[i]), "", m.columns[j], "count",
                     m.counts[i][j]);
                tidy(out, "category", m.group, categoryName(m.rows[i]), "", m.columns[j],
                     "row_percent", m.rowPercent(i, j));
            }
    for (const auto& s : r.summary) {
        const auto& k = s.stimulus;
        tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, "trials", "n", s.n);
        const std::pair<const char*, const Proportion*> props[] = {
            {"correct", &s.correct},
            {"wrong", &s.wrong},
            {"dont_know", &s.dontKnow},
            {"soundscape_correct", &s.soundscapeCorrect}};
        for (const auto& [name, p] : props) {
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "count", p->count);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "n", p->n);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "percent", p->percent);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "wilson_lower",
                 p->wilson.lower);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "wilson_upper",
                 p->wilson.upper);
        }
        if (!r.hasRatings) continue;
        const std::pair<const char*, const MeanSummary*> means[] = {{"realism", &s.realism},
                                                                    {"quality", &s.quality}};
        for (const auto& [name, m] : means) {
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "n", m->n);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "mean", m->mean);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "sd", m->sd);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "se", m->se);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "ci_lower",
                 m->ci.lower);
            tidy(out, "summary", s.group, k.surfaceId, k.soundscapeId, name, "ci_upper",
                 m->ci.upper);
        }
    }
    for (const auto& c : r.comparisons) {
        const std::string groups = c.groupA + " vs " + c.groupB;
        const std::string measure = measureName(c.measure);
        const std::string note = c.test.ok() ? c.test.method : c.test.error;
        auto row = [&](const char* stat, double v) {
            tidy(out, "comparison", groups, c.surfaceId, "", measure, stat, v, note);
        };
        row("n_a", c.nA);
        row("n_b", c.nB);
        row("value_a", c.valueA);
        row("value_b", c.valueB);
        row("statistic", c.test.statistic);
        row("df", c.test.df.empty() ? std::numeric_limits<double>::quiet_NaN() : c.test.df[0]);
        row("p", c.test.p);
        row("p_holm", c.pHolm);
        if (!std::isnan(c.fisherP)) row("fisher_p", c.fisherP);
        row(c.effectName == "phi" ? "phi" : "cohens_d", c.effect);
    }
    for (const auto& m : r.mixedModels) {
        const std::string groups = m.groupA + " vs " + m.groupB;
        std::string note = m.model;
        if (!m.error.empty()) note += ": " + m.error;
        for (const auto& w : m.warnings) note += "; " + w.substr(0, w.find('\n'));
        auto row = [&](const char* stat, double v) {
            tidy(out, "mixed_model", groups, m.surfaceId.empty() ? "all" : m.surfaceId, "",
                 measureName(m.measure), stat, v, note);
        };
        row("observations", m.observations);
        row("participants", m.participants);
        row("estimate", m.estimate);
        row("se", m.se);
        row("statistic", m.statistic);
        if (!std::isnan(m.df)) row("df", m.df);
        row("p", m.p);
        row("lrt_statistic", m.lrtStatistic);
        row("lrt_p", m.lrtP);
        row("random_variance", m.randomVariance);
        row("classic_p", m.classicP);
        if (!std::isnan(m.nonparametricP)) row("mann_whitney_p", m.nonparametricP);
    }
    if (!r.mixedModelAdvice.empty())
        tidy(out, "mixed_model_advice", "", "", "", "", "", std::nan(""), r.mixedModelAdvice);
    return out;
}

// ------------------------------------------------------------------ LaTeX

std::string renderLatex(const AnalysisReport& r) {
    std::string out = "% Generated by `underfoot analyze`. Needs \\usepackage{booktabs}.\n";
    if (!r.title.empty()) out += "% " + r.title + "\n";
    if (r.simulatedParticipants > 0)
        out += "% " + simulatedNotice(r.simulatedParticipants, r.participants) + "\n";
    for (const auto& note : r.notes) out += "% " + note + "\n";
    for (const auto& t : allTables(r, false)) {
        out += "\\begin{table}[htbp]\n\\centering\n\\small\n";
        out += "\\caption{" + latexEscape(t.caption) + "}\n";
        out += "\\begin{tabular}{";
        for (bool n : t.numeric) out += n ? 'r' : 'l';
        out += "}\n\\toprule\n";
        for (std::size_t j = 0; j < t.header.size(); ++j)
            out += (j ? " & " : "") + latexEscape(t.header[j]);
        out += " \\\\\n\\midrule\n";
        for (const auto& row : t.rows) {
            for (std::size_t j = 0; j < row.size(); ++j)
                out += (j ? " & " : "") + latexEscape(row[j]);
            out += " \\\\\n";
        }
        out += "\\bottomrule\n\\end{tabular}\n\\end{table}\n\n";
    }
    if (!r.mixedModelAdvice.empty())
        out += "\\paragraph{Which test to cite.} " + latexEscape(r.mixedModelAdvice) + "\n";
    return out;
}

// ------------------------------------------------------------------ Markdown

std::string renderMarkdown(const AnalysisReport& r) {
    std::string out = "# " + (r.title.empty() ? std::string("Analysis") : r.title) + "\n\n";
    if (r.simulatedParticipants > 0)
        out += "**" + simulatedNotice(r.simulatedParticipants, r.participants) + "**\n\n";
    for (const auto& note : r.notes) out += "- " + markdownCell(note) + "\n";
    if (!r.notes.empty()) out += "\n";
    for (const auto& t : allTables(r)) {
        out += "**" + markdownCell(t.caption) + "**\n\n|";
        for (const auto& h : t.header) out += " " + markdownCell(h) + " |";
        out += "\n|";
        for (bool n : t.numeric) out += n ? " ---: |" : " :--- |";
        out += "\n";
        for (const auto& row : t.rows) {
            out += "|";
            for (const auto& cell : row) out += " " + markdownCell(cell) + " |";
            out += "\n";
        }
        out += "\n";
    }
    if (!r.mixedModelAdvice.empty()) out += "**" + markdownCell(r.mixedModelAdvice) + "**\n";
    return out;
}

// ------------------------------------------------------------------ HTML

/// Colour of a row percentage: white (0 %) to deep blue (100 %).
std::string heatColour(double percent) {
    const double t = std::isnan(percent) ? 0.0 : std::clamp(percent / 100.0, 0.0, 1.0);
    auto mix = [&](double from, double to) {
        return static_cast<int>(std::lround(from + (to - from) * std::sqrt(t)));
    };
    return fmt::format("rgb({},{},{})", mix(255, 8), mix(255, 48), mix(255, 107));
}

std::string htmlTable(const TextTable& t) {
    std::string out = "<table>\n<caption>" + xmlEscape(t.caption) + "</caption>\n<thead><tr>";
    for (std::size_t j = 0; j < t.header.size(); ++j)
        out += std::string(t.numeric[j] ? "<th class=\"num\">" : "<th>") + xmlEscape(t.header[j]) +
               "</th>";
    out += "</tr></thead>\n<tbody>\n";
    for (const auto& row : t.rows) {
        out += "<tr>";
        for (std::size_t j = 0; j < row.size(); ++j)
            out +=
                std::string(j < t.numeric.size() && t.numeric[j] ? "<td class=\"num\">" : "<td>") +
                xmlEscape(row[j]) + "</td>";
        out += "</tr>\n";
    }
    return out + "</tbody>\n</table>\n";
}

/// "correct answers, Gravel: group A 85.0 % (n = 40), group B 50.0 % (n = 40); χ²(1) = 8.90,
/// p = 0.003 (Holm: p = 0.006), Fisher's exact p = 0.002."
std::string comparisonSentence(const ComparisonRow& c) {
    const bool counts = c.measure == Measure::Correct || c.measure == Measure::DontKnow;
    const char* what = c.measure == Measure::Correct    ? "correct answers"
                       : c.measure == Measure::DontKnow ? "\"I don't know\" answers"
                       : c.measure == Measure::Realism  ? "mean realism"
                                                        : "mean quality";
    const auto value = [&](double v, double n) {
        return (counts ? fixed(v, 1) + " %" : fixed(v, 2)) + " (n = " + count(n) + ")";
    };
    std::string out =
        fmt::format("{}, {}: {} {}, {} {}; {}", what,
                    c.surfaceId.empty() ? "all surfaces" : labelFor(c.surfaceId), c.groupA,
                    value(c.valueA, c.nA), c.groupB, value(c.valueB, c.nB), testInWords(c.test));
    if (c.test.ok() && !std::isnan(c.pHolm)) out += " (Holm: " + pInWords(c.pHolm) + ")";
    if (counts && !std::isnan(c.fisherP)) out += ", Fisher's exact " + pInWords(c.fisherP);
    if (!std::isnan(c.effect)) out += fmt::format(", {} = {}", c.effectName, fixed(c.effect, 2));
    return out + ".";
}

/// Ratings per stimulus of one group: each answer as a dot, the mean as a bar with its 95 %
/// confidence interval (t), stimuli by their protocol labels.
std::string ratingMeansSvg(const AnalysisReport& r, const std::string& group, bool realism) {
    const AnswerList* answers = nullptr;
    for (const auto& m : r.confusions)
        if (m.group == group) answers = &m.columns;
    std::vector<const SummaryRow*> rows;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    std::size_t longest = 0;
    for (const auto& s : r.summary) {
        if (s.group != group) continue;
        const MeanSummary& m = realism ? s.realism : s.quality;
        if (m.values.empty()) continue;
        rows.push_back(&s);
        for (double v : m.values) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (!std::isnan(m.ci.lower)) {
            lo = std::min(lo, m.ci.lower);
            hi = std::max(hi, m.ci.upper);
        }
        longest = std::max(longest, stimulusLabel(s.stimulus, answers).size());
    }
    if (rows.empty()) return {};
    lo = std::floor(lo);
    hi = std::ceil(hi);
    if (hi <= lo) hi = lo + 1;
    constexpr int rowH = 28, plotW = 420, top = 34, bottom = 46;
    const int left = std::max(110, static_cast<int>(longest) * 7 + 16);
    const int width = left + plotW + 30,
              height = top + rowH * static_cast<int>(rows.size()) + bottom;
    const auto sx = [&](double v) { return left + plotW * (v - lo) / (hi - lo); };
    const char* measure = realism ? "realism" : "quality";
    std::string out = fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" "
                                  "height=\"{}\" viewBox=\"0 0 {} {}\" role=\"img\" "
                                  "font-family=\"sans-serif\" font-size=\"12\">\n",
                                  width, height, width, height);
    out += "<title>" + xmlEscape(fmt::format("Mean {} per stimulus, {}", measure, group)) +
           "</title>\n";
    const int axisY = top + rowH * static_cast<int>(rows.size());
    const double span = hi - lo;
    const double step = span <= 10 ? 1 : std::ceil(span / 10);
    for (double v = lo; v <= hi + 1e-9; v += step) {
        out += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" "
                           "stroke=\"#e3e3e3\"/>\n<text x=\"{0:.1f}\" y=\"{3}\" "
                           "text-anchor=\"middle\">{4}</text>\n",
                           sx(v), top - 6, axisY, axisY + 16, fixed(v, 0));
    }
    out += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#444\"/>\n", left,
                       axisY, left + plotW, axisY);
    out += fmt::format("<text class=\"axis-title\" x=\"{}\" y=\"{}\" text-anchor=\"middle\" "
                       "font-weight=\"bold\">{} rating: mean with 95 % CI (bar), each answer "
                       "(dot)</text>\n",
                       left + plotW / 2, axisY + 36, realism ? "Realism" : "Quality");
    out += fmt::format("<text class=\"axis-title\" x=\"{}\" y=\"16\" text-anchor=\"middle\" "
                       "font-weight=\"bold\">Stimulus</text>\n",
                       left / 2);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const SummaryRow& s = *rows[i];
        const MeanSummary& m = realism ? s.realism : s.quality;
        const std::string label = stimulusLabel(s.stimulus, answers);
        const int y = top + rowH * static_cast<int>(i) + rowH / 2;
        out += fmt::format("<text class=\"row-label\" x=\"{}\" y=\"{}\" text-anchor=\"end\">{}"
                           "</text>\n",
                           left - 8, y + 4, xmlEscape(label));
        // Answers as dots, spread over the row by a fixed pattern (no randomness in a report).
        for (std::size_t k = 0; k < m.values.size(); ++k) {
            const double dy = (static_cast<double>(k % 7) - 3.0) * 2.2;
            out += fmt::format("<circle class=\"point\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" "
                               "fill=\"#1f77b4\" fill-opacity=\"0.35\"/>\n",
                               sx(m.values[k]), y + dy);
        }
        if (!std::isnan(m.ci.lower))
            out += fmt::format("<line class=\"ci\" x1=\"{:.1f}\" y1=\"{}\" x2=\"{:.1f}\" "
                               "y2=\"{}\" stroke=\"#111\" stroke-width=\"2\"/>\n",
                               sx(m.ci.lower), y, sx(m.ci.upper), y);
        out += fmt::format(
            "<rect class=\"mean\" x=\"{:.1f}\" y=\"{}\" width=\"3\" height=\"16\" "
            "fill=\"#d62728\"><title>{}: mean {} {}{}, n {}</title></rect>\n",
            sx(m.mean) - 1.5, y - 8, xmlEscape(label), measure, fixed(m.mean, 2),
            std::isnan(m.ci.lower)
                ? std::string()
                : fmt::format(", 95 % CI {} to {}", fixed(m.ci.lower, 2), fixed(m.ci.upper, 2)),
            count(m.n));
    }
    return out + "</svg>\n";
}

std::string renderHtml(const AnalysisReport& r) {
    const std::string title = r.title.empty() ? std::string("Underfoot analysis") : r.title;
    std::string out =
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\" />\n"
        "<title>" +
        xmlEscape(title) +
        "</title>\n<style>\n"
        "body{font-family:system-ui,sans-serif;margin:2em;color:#222;max-width:80em}\n"
        "table{border-collapse:collapse;margin:1em 0 2em 0;font-size:0.9em}\n"
        "caption{text-align:left;font-weight:600;padding-bottom:0.4em}\n"
        "th,td{padding:0.25em 0.6em;border-bottom:1px solid #ddd}\n"
        "thead th{border-bottom:2px solid #444}\n"
        ".num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\n"
        "figure{margin:1em 0 2em 0}\nfigcaption{font-weight:600}\n"
        "</style>\n</head>\n<body>\n<h1>" +
        xmlEscape(title) + "</h1>\n";
    out += simulatedBannerHtml(r.simulatedParticipants, r.participants);
    if (!r.source.empty()) out += "<p>Source: " + xmlEscape(r.source) + "</p>\n";
    if (!r.notes.empty()) {
        out += "<ul class=\"notes\">\n";
        for (const auto& note : r.notes) out += "<li>" + xmlEscape(note) + "</li>\n";
        out += "</ul>\n";
    }
    out += "<h2>Confusion matrices</h2>\n";
    for (const auto& m : r.confusions) {
        out += "<figure class=\"confusion\" id=\"confusion-" + xmlEscape(m.group) + "\">\n";
        out += "<figcaption>Confusion matrix, " + xmlEscape(m.group) +
               ": counts and row % in each cell (colour = row %; outlined = the correct "
               "answer)</figcaption>\n";
        out += confusionHeatMapSvg(m);
        out += "</figure>\n";
    }
    out += "<h2>Categories</h2>\n";
    for (const auto& m : r.categories) out += htmlTable(categoryTable(m));
    out += "<h2>Summary</h2>\n" + htmlTable(summaryTable(r));
    if (r.hasRatings) {
        out += "<h2>Ratings</h2>\n";
        std::vector<std::string> groups;
        for (const auto& s : r.summary)
            if (std::find(groups.begin(), groups.end(), s.group) == groups.end())
                groups.push_back(s.group);
        for (const bool realism : {true, false})
            for (const auto& g : groups) {
                const std::string svg = ratingMeansSvg(r, g, realism);
                if (svg.empty()) continue;
                out += "<figure class=\"ratings\" id=\"" +
                       xmlEscape(std::string(realism ? "realism-" : "quality-") + g) +
                       "\">\n<figcaption>" +
                       xmlEscape(fmt::format(
                           "{}, {}: mean per stimulus with its 95 % confidence interval (t) and "
                           "every answer{}",
                           realism ? "Realism" : "Quality", g,
                           realism ? " (correct answers only)"
                                   : " (all answers except \"I don't know\")")) +
                       "</figcaption>\n" + svg + "</figure>\n";
            }
    }
    if (!r.comparisons.empty()) {
        out += "<h2>Tests</h2>\n<ul class=\"tests\">\n";
        for (const auto& c : r.comparisons)
            out += "<li>" + xmlEscape(comparisonSentence(c)) + "</li>\n";
        out += "</ul>\n" + htmlTable(comparisonTable(r));
    }
    if (!r.mixedModels.empty()) {
        out += "<h2>Mixed models</h2>\n";
        if (!r.mixedModelAdvice.empty())
            out +=
                "<p class=\"advice\"><strong>" + xmlEscape(r.mixedModelAdvice) + "</strong></p>\n";
        out += htmlTable(mixedModelTable(r));
    }
    out += "</body>\n</html>\n";
    return out;
}

} // namespace

std::string confusionHeatMapSvg(const ConfusionMatrix& m) {
    constexpr int cellW = 56, cellH = 40, right = 50, axisTitle = 22;
    const AnswerList* answers = &m.columns;
    std::size_t longestRow = 0, longestColumn = 0;
    for (const auto& row : m.rows)
        longestRow = std::max(longestRow, stimulusLabel(row, answers).size());
    for (const auto& o : m.columns.options) longestColumn = std::max(longestColumn, o.label.size());
    // About 7 px per character at 12 px sans-serif; column labels are turned by 40 degrees.
    const int left = axisTitle + std::max(110, static_cast<int>(longestRow) * 7 + 12);
    const int top = axisTitle + 12 + std::min(220, static_cast<int>(longestColumn) * 5 + 16);
    const int columns = static_cast<int>(m.columns.options.size());
    const int rows = static_cast<int>(m.rows.size());
    // The last column's label reaches right by its length x cos 40 (~5 px a character).
    const int width = left + cellW * columns +
                      std::max(right + 60, static_cast<int>(longestColumn) * 5 + 10),
              height = top + cellH * rows + 10;
    std::string out = fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" "
                                  "height=\"{}\" viewBox=\"0 0 {} {}\" role=\"img\" "
                                  "font-family=\"sans-serif\" font-size=\"12\">\n",
                                  width, height, width, height);
    out += "<title>" + xmlEscape("Confusion matrix " + m.group) + "</title>\n";
    // Axis titles.
    out += fmt::format("<text class=\"axis-title\" x=\"{}\" y=\"16\" text-anchor=\"middle\" "
                       "font-weight=\"bold\">Answer given</text>\n",
                       left + cellW * columns / 2);
    out += fmt::format("<text class=\"axis-title\" transform=\"translate(16,{}) rotate(-90)\" "
                       "text-anchor=\"middle\" font-weight=\"bold\">Presented stimulus</text>\n",
                       top + cellH * rows / 2);
    for (int j = 0; j < columns; ++j) {
        const auto& o = m.columns.options[static_cast<std::size_t>(j)];
        const int x = left + cellW * j + cellW / 2;
        out += fmt::format("<text class=\"column-label\" transform=\"translate({},{}) "
                           "rotate(-40)\" text-anchor=\"start\">{}<title>{}</title></text>\n",
                           x - 4, top - 6, xmlEscape(o.label), xmlEscape(o.id));
    }
    out += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" "
                       "font-weight=\"bold\">n</text>\n",
                       left + cellW * columns + right / 2, top - 8);
    for (int i = 0; i < rows; ++i) {
        const auto row = static_cast<std::size_t>(i);
        const int y = top + cellH * i;
        const std::string rowLabel = stimulusLabel(m.rows[row], answers);
        out += fmt::format("<text class=\"row-label\" x=\"{}\" y=\"{}\" "
                           "text-anchor=\"end\">{}</text>\n",
                           left - 8, y + cellH / 2 + 4, xmlEscape(rowLabel));
        for (int j = 0; j < columns; ++j) {
            const auto col = static_cast<std::size_t>(j);
            const double pct = m.rowPercent(row, col);
            const int x = left + cellW * j;
            const bool correct = answerIsCorrect(m.columns.options[col].id, m.rows[row].surfaceId);
            out += fmt::format("<rect class=\"cell\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" "
                               "fill=\"{}\" stroke=\"{}\" stroke-width=\"{}\"><title>{} -&gt; "
                               "{}: {} ({}%)</title></rect>\n",
                               x, y, cellW, cellH, heatColour(pct), correct ? "#d62728" : "#cccccc",
                               correct ? 2 : 1, xmlEscape(rowLabel),
                               xmlEscape(m.columns.options[col].label), count(m.counts[row][col]),
                               fixed(pct, 1));
            if (m.counts[row][col] > 0) {
                const char* ink = pct > 45 ? "#ffffff" : "#111111";
                out += fmt::format("<text class=\"count\" x=\"{}\" y=\"{}\" "
                                   "text-anchor=\"middle\" font-weight=\"bold\" "
                                   "fill=\"{}\">{}</text>\n",
                                   x + cellW / 2, y + 17, ink, count(m.counts[row][col]));
                out += fmt::format("<text class=\"row-percent\" x=\"{}\" y=\"{}\" "
                                   "text-anchor=\"middle\" font-size=\"10\" "
                                   "fill=\"{}\">{}%</text>\n",
                                   x + cellW / 2, y + 32, ink, fixed(pct, 1));
            }
        }
        out += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
                           left + cellW * columns + right / 2, y + cellH / 2 + 4,
                           count(m.rowTotal(row)));
    }
    return out + "</svg>\n";
}

std::string renderReport(const AnalysisReport& report, ReportFormat format) {
    switch (format) {
    case ReportFormat::Csv:
        return renderCsv(report);
    case ReportFormat::Latex:
        return renderLatex(report);
    case ReportFormat::Markdown:
        return renderMarkdown(report);
    case ReportFormat::Html:
        return renderHtml(report);
    }
    return renderCsv(report);
}

} // namespace underfoot::analysis
