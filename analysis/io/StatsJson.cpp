// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/StatsJson.h"

#include "analysis/io/StatsJsonMixed.h"
#include "analysis/stats/Tests.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace underfoot::analysis {

using nlohmann::json;

const std::vector<std::string>& statsTestNames() {
    static const std::vector<std::string> names{"binom",
                                                "chisq",
                                                "chisq_gof",
                                                "clmm",
                                                "fisher",
                                                "friedman",
                                                "glmm",
                                                "kendall",
                                                "kruskal",
                                                "levene",
                                                "lmm",
                                                "p_adjust",
                                                "pairwise_wilcoxon",
                                                "pearson",
                                                "prop",
                                                "shapiro",
                                                "spearman",
                                                "t",
                                                "wilcoxon",
                                                "wilson"};
    return names;
}

namespace {

/// A user error in the request; becomes {"error": ...}.
struct RequestError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

class Request {
  public:
    Request(const json& body, std::set<std::string> allowed) : body_(body) {
        if (!body_.is_object()) throw RequestError("the request must be a JSON object");
        for (const auto& [key, value] : body_.items())
            if (!allowed.count(key)) {
                std::string list;
                for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
                throw RequestError(
                    fmt::format("unknown field '{}' (expected one of: {})", key, list));
            }
    }
    bool has(const std::string& key) const {
        return body_.contains(key) && !body_.at(key).is_null();
    }
    std::vector<double> numbers(const std::string& key) const {
        if (!has(key))
            throw RequestError(fmt::format("missing field '{}' (an array of numbers)", key));
        return toNumbers(body_.at(key), key);
    }
    std::vector<std::vector<double>> matrix(const std::string& key) const {
        if (!has(key))
            throw RequestError(
                fmt::format("missing field '{}' (an array of arrays of numbers)", key));
        const json& v = body_.at(key);
        if (!v.is_array())
            throw RequestError(fmt::format("'{}' must be an array of arrays of numbers", key));
        std::vector<std::vector<double>> out;
        for (std::size_t i = 0; i < v.size(); ++i)
            out.push_back(toNumbers(v[i], fmt::format("{}[{}]", key, i)));
        return out;
    }
    double number(const std::string& key, double fallback) const {
        if (!has(key)) return fallback;
        const json& v = body_.at(key);
        if (!v.is_number()) throw RequestError(fmt::format("'{}' must be a number", key));
        return v.get<double>();
    }
    double requiredNumber(const std::string& key) const {
        if (!has(key)) throw RequestError(fmt::format("missing field '{}' (a number)", key));
        return number(key, 0);
    }
    bool flag(const std::string& key, bool fallback) const {
        if (!has(key)) return fallback;
        const json& v = body_.at(key);
        if (!v.is_boolean()) throw RequestError(fmt::format("'{}' must be true or false", key));
        return v.get<bool>();
    }
    std::string text(const std::string& key, const std::string& fallback) const {
        if (!has(key)) return fallback;
        const json& v = body_.at(key);
        if (!v.is_string()) throw RequestError(fmt::format("'{}' must be a string", key));
        return v.get<std::string>();
    }
    Alternative alternative() const {
        const std::string a = text("alternative", "two.sided");
        if (a == "two.sided" || a == "two_sided") return Alternative::TwoSided;
        if (a == "less") return Alternative::Less;
        if (a == "greater") return Alternative::Greater;
        throw RequestError("'alternative' must be \"two.sided\", \"less\" or \"greater\"");
    }
    Exactness exactness() const {
        if (!has("exact")) return Exactness::Auto;
        return flag("exact", false) ? Exactness::Exact : Exactness::Approximate;
    }

  private:
    static std::vector<double> toNumbers(const json& v, const std::string& key) {
        if (!v.is_array()) throw RequestError(fmt::format("'{}' must be an array of numbers", key));
        std::vector<double> out;
        out.reserve(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (v[i].is_null()) {
                out.push_back(std::nan("")); // missing value, dropped as R drops NA
            } else if (v[i].is_number()) {
                out.push_back(v[i].get<double>());
            } else {
                throw RequestError(
                    fmt::format("'{}[{}]' must be a number or null (missing)", key, i));
            }
        }
        return out;
    }
    const json& body_;
};

json number(double v) {
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
    return v;
}

json resultJson(const std::string& test, const TestResult& r) {
    if (!r.ok()) throw RequestError(r.error);
    json out;
    out["test"] = test;
    out["method"] = r.method;
    if (!r.statisticName.empty()) {
        out["statistic"] = number(r.statistic);
        out["statistic_name"] = r.statisticName;
    }
    if (r.df.size() == 1) out["df"] = number(r.df[0]);
    if (r.df.size() > 1) {
        json df = json::array();
        for (double d : r.df) df.push_back(number(d));
        out["df"] = df;
    }
    out["p"] = number(r.p);
    if (r.confInt) {
        out["conf_int"] = json::array({number(r.confInt->lower), number(r.confInt->upper)});
        out["conf_level"] = number(r.confInt->level);
    }
    if (r.estimate.size() == 1) {
        out["estimate"] = number(r.estimate[0].value);
        out["estimate_names"] = json::array({r.estimate[0].name});
    } else if (r.estimate.size() > 1) {
        json values = json::array(), names = json::array();
        for (const auto& e : r.estimate) {
            values.push_back(number(e.value));
            names.push_back(e.name);
        }
        out["estimate"] = values;
        out["estimate_names"] = names;
    }
    out["alternative"] = alternativeName(r.alternative);
    out["warnings"] = r.warnings;
    return out;
}

Continuity continuity(const Request& q) {
    return q.flag("correct", true) ? Continuity::Corrected : Continuity::Uncorrected;
}

PAdjustMethod adjustMethod(const std::string& m) {
    if (m == "holm") return PAdjustMethod::Holm;
    if (m == "bonferroni") return PAdjustMethod::Bonferroni;
    if (m == "hochberg") return PAdjustMethod::Hochberg;
    if (m == "BH" || m == "fdr") return PAdjustMethod::BenjaminiHochberg;
    if (m == "none") return PAdjustMethod::None;
    throw RequestError(
        "'method' must be \"holm\", \"bonferroni\", \"hochberg\", \"BH\" or \"none\"");
}

json run(const std::string& test, const json& body) {
    if (test == "chisq") {
        const Request q(body, {"table", "correct"});
        return resultJson(test, chisqTest(q.matrix("table"), continuity(q)));
    }
    if (test == "chisq_gof") {
        const Request q(body, {"x", "p"});
        const auto p = q.has("p") ? q.numbers("p") : std::vector<double>{};
        return resultJson(test, chisqGoodnessOfFit(q.numbers("x"), p));
    }
    if (test == "fisher") {
        const Request q(body, {"table", "conf_level", "alternative"});
        const auto table = q.matrix("table");
        // r x c tables: exact p by enumeration, two-sided only, as R.
        if (table.size() != 2 || std::any_of(table.begin(), table.end(),
                                             [](const auto& row) { return row.size() != 2; })) {
            if (q.alternative() != Alternative::TwoSided)
                throw RequestError("'alternative' other than \"two.sided\" is only for 2 x 2 "
                                   "tables (as R's fisher.test)");
            return resultJson(test, fisherTestRxC(table));
        }
        return resultJson(
            test, fisherTest(q.matrix("table"), q.number("conf_level", 0.95), q.alternative()));
    }
    if (test == "t") {
        const Request q(body, {"x", "y", "paired", "var_equal", "mu", "conf_level", "alternative"});
        TTestOptions o;
        o.alternative = q.alternative();
        o.mu = q.number("mu", 0);
        o.pairing = q.flag("paired", false) ? Pairing::Paired : Pairing::Independent;
        o.variance = q.flag("var_equal", false) ? Variance::Equal : Variance::Welch;
        o.confLevel = q.number("conf_level", 0.95);
        if (!q.has("y")) {
            if (o.pairing == Pairing::Paired) throw RequestError("'y' is missing for paired test");
            return resultJson(test, tTest(q.numbers("x"), o));
        }
        return resultJson(test, tTest(q.numbers("x"), q.numbers("y"), o));
    }
    if (test == "wilcoxon") {
        const Request q(body, {"x", "y", "paired", "correct", "exact", "mu", "alternative",
                               "conf_int", "conf_level"});
        WilcoxonOptions o;
        o.alternative = q.alternative();
        o.mu = q.number("mu", 0);
        o.pairing = q.flag("paired", false) ? Pairing::Paired : Pairing::Independent;
        o.continuity = continuity(q);
        o.exactness = q.exactness();
        if (!q.has("y") && o.pairing == Pairing::Paired)
            throw RequestError("'y' is missing for paired test");
        if (q.flag("conf_int", false)) { // Hodges-Lehmann estimate and interval
            const double level = q.number("conf_level", 0.95);
            if (!q.has("y")) return resultJson(test, wilcoxonTestCi(q.numbers("x"), o, level));
            return resultJson(test, wilcoxonTestCi(q.numbers("x"), q.numbers("y"), o, level));
        }
        if (q.has("conf_level")) throw RequestError("'conf_level' needs \"conf_int\": true");
        if (!q.has("y")) return resultJson(test, wilcoxonTest(q.numbers("x"), o));
        return resultJson(test, wilcoxonTest(q.numbers("x"), q.numbers("y"), o));
    }
    if (test == "pairwise_wilcoxon") {
        const Request q(body, {"groups", "paired", "correct", "exact", "method"});
        WilcoxonOptions o;
        o.pairing = q.flag("paired", false) ? Pairing::Paired : Pairing::Independent;
        o.continuity = continuity(q);
        o.exactness = q.exactness();
        const std::string m = q.text("method", "holm");
        const auto method = adjustMethod(m);
        json pairs = json::array();
        for (const auto& r : pairwiseWilcoxon(q.matrix("groups"), method, o)) {
            if (!r.test.ok())
                throw RequestError(
                    fmt::format("groups {} and {}: {}", r.first, r.second, r.test.error));
            pairs.push_back(json{{"first", r.first},
                                 {"second", r.second},
                                 {"method", r.test.method},
                                 {"statistic", number(r.test.statistic)},
                                 {"statistic_name", r.test.statisticName},
                                 {"p", number(r.test.p)},
                                 {"p_adjusted", number(r.pAdjusted)},
                                 {"warnings", r.test.warnings}});
        }
        return json{{"test", test}, {"adjust_method", m}, {"pairs", pairs}};
    }
    if (test == "kruskal") {
        const Request q(body, {"groups"});
        return resultJson(test, kruskalTest(q.matrix("groups")));
    }
    if (test == "friedman") {
        const Request q(body, {"y"});
        return resultJson(test, friedmanTest(q.matrix("y")));
    }
    if (test == "spearman") {
        const Request q(body, {"x", "y", "alternative", "exact"});
        const auto r = spearmanTest(q.numbers("x"), q.numbers("y"), q.alternative(), q.exactness());
        json out = resultJson(test, r);
        out["rho"] = number(r.estimate.empty() ? std::nan("") : r.estimate[0].value);
        return out;
    }
    if (test == "pearson") {
        const Request q(body, {"x", "y", "alternative", "conf_level"});
        return resultJson(test, pearsonTest(q.numbers("x"), q.numbers("y"), q.alternative(),
                                            q.number("conf_level", 0.95)));
    }
    if (test == "kendall") {
        const Request q(body, {"x", "y", "alternative", "exact", "continuity"});
        const auto r = kendallTest(q.numbers("x"), q.numbers("y"), q.alternative(), q.exactness(),
                                   q.flag("continuity", false) ? Continuity::Corrected
                                                               : Continuity::Uncorrected);
        json out = resultJson(test, r);
        out["tau"] = number(r.estimate.empty() ? std::nan("") : r.estimate[0].value);
        return out;
    }
    if (test == "p_adjust") {
        const Request q(body, {"p", "method"});
        const std::string m = q.text("method", "holm");
        const auto method = adjustMethod(m);
        const auto p = q.numbers("p");
        for (double v : p)
            if (!std::isnan(v) && !(v >= 0 && v <= 1))
                throw RequestError("'p' values must be between 0 and 1 (or null)");
        json adjusted = json::array();
        for (double v : pAdjust(p, method)) adjusted.push_back(number(v));
        return json{{"test", test}, {"method", m}, {"adjusted", adjusted}};
    }
    if (test == "shapiro") {
        const Request q(body, {"x"});
        return resultJson(test, shapiroTest(q.numbers("x")));
    }
    if (test == "levene") {
        const Request q(body, {"groups", "center"});
        const std::string c = q.text("center", "median");
        if (c != "median" && c != "mean")
            throw RequestError("'center' must be \"median\" or \"mean\"");
        return resultJson(test, leveneTest(q.matrix("groups"), c == "mean" ? LeveneCenter::Mean
                                                                           : LeveneCenter::Median));
    }
    if (test == "binom") {
        const Request q(body, {"x", "n", "p", "conf_level", "alternative"});
        return resultJson(test, binomTest(q.requiredNumber("x"), q.requiredNumber("n"),
                                          q.number("p", 0.5), q.alternative(),
                                          q.number("conf_level", 0.95)));
    }
    if (test == "prop") {
        const Request q(body, {"x", "n", "p", "correct", "conf_level", "alternative"});
        const auto p = q.has("p") ? q.numbers("p") : std::vector<double>{};
        return resultJson(test, propTest(q.numbers("x"), q.numbers("n"), p, q.alternative(),
                                         q.number("conf_level", 0.95), continuity(q)));
    }
    if (test == "wilson") {
        const Request q(body, {"x", "n", "conf_level", "correct"});
        const double x = q.requiredNumber("x"), n = q.requiredNumber("n");
        if (!(n > 0) || !(x >= 0) || x > n) throw RequestError("need 0 <= x <= n and n > 0");
        const auto ci = wilsonInterval(x, n, q.number("conf_level", 0.95),
                                       q.flag("correct", false) ? Continuity::Corrected
                                                                : Continuity::Uncorrected);
        return json{{"test", test},
                    {"method", "Wilson score interval"},
                    {"estimate", x / n},
                    {"conf_int", json::array({number(ci.lower), number(ci.upper)})},
                    {"conf_level", number(ci.level)}};
    }
    std::string list;
    for (const auto& n : statsTestNames()) list += (list.empty() ? "" : ", ") + n;
    throw RequestError(fmt::format("unknown test '{}' (expected one of: {})", test, list));
}

} // namespace

std::pair<std::size_t, std::size_t> jsonErrorPosition(std::string_view text, std::size_t byte) {
    // nlohmann counts the byte it failed on from 1; 0 means before any input.
    const std::size_t end = std::min(byte == 0 ? 0 : byte - 1, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return {line, column};
}

StatsResponse runStatsRequest(std::string_view test, std::string_view requestJson) {
    if (isMixedModelTest(test)) return runMixedModelRequest(test, requestJson); // mixed models
    try {
        const json body = json::parse(requestJson.begin(), requestJson.end());
        return {true,
                run(std::string(test), body).dump(-1, ' ', false, json::error_handler_t::replace)};
    } catch (const json::parse_error& e) {
        const auto [line, column] = jsonErrorPosition(requestJson, e.byte);
        return {false, json{{"error", fmt::format("invalid JSON at line {}, column {} (byte {}): "
                                                  "{}",
                                                  line, column, e.byte, e.what())}}
                           .dump(-1, ' ', false, json::error_handler_t::replace)};
    } catch (const RequestError& e) {
        return {false,
                json{{"error", e.what()}}.dump(-1, ' ', false, json::error_handler_t::replace)};
    } catch (const json::exception& e) {
        return {false,
                json{{"error", e.what()}}.dump(-1, ' ', false, json::error_handler_t::replace)};
    }
}

} // namespace underfoot::analysis
