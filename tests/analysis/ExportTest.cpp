// SPDX-License-Identifier: GPL-3.0-or-later
// Exports of a report: tidy CSV, LaTeX (booktabs), Markdown, and a well-formed HTML page with
// one SVG heat map per confusion matrix.
#include "analysis/report/Export.h"
#include "analysis/io/CountTables.h"
#include "analysis/io/Csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::analysis;

namespace {

const std::string kDir = std::string(UNDERFOOT_SOURCE_DIR) + "/tests/analysis/data/published/";

AnalysisReport eurohaptics() {
    auto r =
        analyzeConfusions({readCountTable(kDir + "eurohaptics2010_audio_confusion.csv", 20),
                           readCountTable(kDir + "eurohaptics2010_haptic_confusion.csv", 20),
                           readCountTable(kDir + "eurohaptics2010_audiohaptic_confusion.csv", 20)},
                          AnalysisOptions{});
    r.title = "Eurohaptics 2010 & <friends>";
    return r;
}

std::size_t occurrences(const std::string& text, const std::string& needle) {
    std::size_t n = 0;
    for (auto pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + 1))
        ++n;
    return n;
}

/// Minimal XML well-formedness check: balanced and properly nested tags, quoted attributes,
/// and only the five predefined or numeric entities. Returns an empty string when well-formed.
std::string xmlProblem(const std::string& doc) {
    std::vector<std::string> stack;
    std::size_t i = 0;
    if (doc.rfind("<!DOCTYPE html>", 0) == 0) i = doc.find('>') + 1;
    while (i < doc.size()) {
        if (doc[i] == '&') {
            const auto end = doc.find(';', i);
            if (end == std::string::npos) return "unterminated entity";
            const std::string e = doc.substr(i, end - i + 1);
            if (e != "&amp;" && e != "&lt;" && e != "&gt;" && e != "&quot;" &&
                e.rfind("&#", 0) != 0)
                return "bad entity " + e;
            i = end + 1;
            continue;
        }
        if (doc[i] == '>') return "stray '>' at " + std::to_string(i);
        if (doc[i] != '<') {
            ++i;
            continue;
        }
        const auto end = doc.find('>', i);
        if (end == std::string::npos) return "unterminated tag";
        std::string tag = doc.substr(i + 1, end - i - 1);
        i = end + 1;
        if (tag.empty()) return "empty tag";
        if (tag[0] == '/') {
            const std::string name = tag.substr(1);
            if (stack.empty() || stack.back() != name)
                return "closing </" + name + "> does not match <" +
                       (stack.empty() ? std::string("nothing") : stack.back()) + ">";
            stack.pop_back();
            continue;
        }
        const bool selfClosing = tag.back() == '/';
        if (selfClosing) tag.pop_back();
        const std::string name = tag.substr(0, tag.find_first_of(" \n"));
        // attributes: name="value" pairs
        std::size_t a = name.size();
        while (a < tag.size()) {
            while (a < tag.size() && (tag[a] == ' ' || tag[a] == '\n')) ++a;
            if (a >= tag.size()) break;
            const auto eq = tag.find('=', a);
            if (eq == std::string::npos || eq + 1 >= tag.size() || tag[eq + 1] != '"')
                return "unquoted attribute in <" + name + ">";
            const auto close = tag.find('"', eq + 2);
            if (close == std::string::npos) return "unterminated attribute in <" + name + ">";
            a = close + 1;
        }
        if (!selfClosing) stack.push_back(name);
    }
    if (!stack.empty()) return "unclosed <" + stack.back() + ">";
    return {};
}

} // namespace

TEST(Export, TidyCsvHasOneRowPerCellAndReadsBack) {
    const auto r = eurohaptics();
    const std::string text = renderReport(r, ReportFormat::Csv);
    const auto records = csv::parse(text, "report.csv");
    ASSERT_FALSE(records.empty());
    EXPECT_EQ(csv::joinLine(records[0].fields), kTidyCsvHeader);
    std::size_t confusionRows = 0, expected = 0;
    for (const auto& m : r.confusions) expected += 2 * m.rows.size() * m.columns.options.size();
    bool gravelFound = false;
    for (const auto& rec : records) {
        ASSERT_EQ(rec.fields.size(), 8u) << rec.line;
        if (rec.fields[0] == "confusion") ++confusionRows;
        if (rec.fields[0] == "comparison" &&
            rec.fields[1] == "eurohaptics2010_audio vs "
                             "eurohaptics2010_audiohaptic" &&
            rec.fields[2] == "gravel" && rec.fields[4] == "correct" &&
            rec.fields[5] == "statistic") {
            EXPECT_NEAR(std::stod(rec.fields[6]), 8.9010989010989, 1e-12);
            EXPECT_EQ(rec.fields[7],
                      "Pearson's Chi-squared test with Yates' continuity correction");
            gravelFound = true;
        }
    }
    EXPECT_EQ(confusionRows, expected);
    EXPECT_TRUE(gravelFound);
}

TEST(Export, LatexUsesBooktabsAndEscapesSpecialCharacters) {
    const std::string tex = renderReport(eurohaptics(), ReportFormat::Latex);
    EXPECT_GE(occurrences(tex, "\\toprule"), 3u);
    EXPECT_EQ(occurrences(tex, "\\toprule"), occurrences(tex, "\\bottomrule"));
    EXPECT_EQ(occurrences(tex, "\\begin{tabular}"), occurrences(tex, "\\end{tabular}"));
    EXPECT_NE(tex.find("eurohaptics2010\\_audio"), std::string::npos);
    EXPECT_EQ(tex.find("eurohaptics2010_audio"), std::string::npos); // never unescaped
    EXPECT_NE(tex.find("\\%"), std::string::npos);
}

TEST(Export, MarkdownTablesHaveAlignedHeaderRows) {
    const std::string md = renderReport(eurohaptics(), ReportFormat::Markdown);
    EXPECT_EQ(md.rfind("# Eurohaptics 2010 & <friends>", 0), 0u);
    EXPECT_NE(md.find("| Stimulus | BS | GL |"), std::string::npos);
    EXPECT_NE(md.find("| :--- | ---: |"), std::string::npos);
    EXPECT_NE(md.find("X² = 8.9011"), std::string::npos);
}

TEST(Export, HtmlReportIsWellFormedAndContainsEveryMatrixAsSvg) {
    const auto r = eurohaptics();
    const std::string html = renderReport(r, ReportFormat::Html);
    EXPECT_EQ(xmlProblem(html), "");
    EXPECT_EQ(occurrences(html, "<svg "), r.confusions.size());
    std::size_t cells = 0;
    for (const auto& m : r.confusions) cells += m.rows.size() * m.columns.options.size();
    EXPECT_EQ(occurrences(html, "class=\"cell\""), cells);
    EXPECT_NE(html.find("<title>Eurohaptics 2010 &amp; &lt;friends&gt;</title>"),
              std::string::npos);
    EXPECT_NE(html.find("<h2>Tests</h2>"), std::string::npos);
    EXPECT_NE(html.find("X² = 8.9011"), std::string::npos);
    // the checker itself rejects broken markup
    EXPECT_NE(xmlProblem("<p><b>x</p></b>"), "");
    EXPECT_NE(xmlProblem("<p a=1>x</p>"), "");
    EXPECT_NE(xmlProblem("<p>a & b</p>"), "");
}

TEST(Export, HeatMapColourFollowsRowPercentage) {
    ConfusionMatrix m;
    m.group = "g";
    m.rows = {{"gravel", ""}};
    m.columns.options = {{"gravel", "Gravel"}, {"dont_know", "I don't know"}};
    m.counts = {{10, 0}};
    const std::string svg = confusionHeatMapSvg(m);
    EXPECT_NE(svg.find("fill=\"rgb(8,48,107)\""), std::string::npos);    // 100 %
    EXPECT_NE(svg.find("fill=\"rgb(255,255,255)\""), std::string::npos); // 0 %
    EXPECT_EQ(xmlProblem(svg), "");
}

TEST(Export, FormatNamesParse) {
    EXPECT_EQ(parseReportFormat("html"), ReportFormat::Html);
    EXPECT_EQ(parseReportFormat("md"), ReportFormat::Markdown);
    EXPECT_EQ(parseReportFormat("tex"), ReportFormat::Latex);
    EXPECT_FALSE(parseReportFormat("pdf").has_value());
}
