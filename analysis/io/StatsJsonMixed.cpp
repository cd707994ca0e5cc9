// SPDX-License-Identifier: GPL-3.0-or-later
#include "analysis/io/StatsJsonMixed.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace underfoot::analysis {

using nlohmann::json;

namespace {

struct MixedRequestError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

json num(double v) {
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
    return v;
}

std::vector<double> numbers(const json& body, const char* key) {
    if (!body.contains(key) || body.at(key).is_null())
        throw MixedRequestError(fmt::format("missing field '{}' (an array of numbers)", key));
    const json& v = body.at(key);
    if (!v.is_array())
        throw MixedRequestError(fmt::format("'{}' must be an array of numbers", key));
    std::vector<double> out;
    out.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i].is_null())
            out.push_back(std::nan(""));
        else if (v[i].is_number())
            out.push_back(v[i].get<double>());
        else
            throw MixedRequestError(
                fmt::format("'{}[{}]' must be a number or null (missing)", key, i));
    }
    return out;
}

/// A factor given as strings or numbers; numbers also yield a numeric level order.
std::vector<std::string> labels(const json& body, const char* key, bool required,
                                std::vector<std::string>* numericOrder) {
    if (!body.contains(key) || body.at(key).is_null()) {
        if (required)
            throw MixedRequestError(
                fmt::format("missing field '{}' (an array of strings or numbers)", key));
        return {};
    }
    const json& v = body.at(key);
    if (!v.is_array())
        throw MixedRequestError(fmt::format("'{}' must be an array of strings or numbers", key));
    std::vector<std::string> out;
    std::vector<double> values;
    bool allNumbers = true;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i].is_null()) {
            out.emplace_back();
        } else if (v[i].is_string()) {
            out.push_back(v[i].get<std::string>());
            if (out.back().empty())
                throw MixedRequestError(fmt::format(
                    "'{}[{}]' is an empty string (use null for a missing value)", key, i));
            allNumbers = false;
        } else if (v[i].is_number()) {
            const double x = v[i].get<double>();
            if (!std::isfinite(x))
                throw MixedRequestError(fmt::format("'{}[{}]' must be finite", key, i));
            out.push_back(fmt::format("{}", x));
            values.push_back(x);
        } else {
            throw MixedRequestError(
                fmt::format("'{}[{}]' must be a string, a number or null (missing)", key, i));
        }
    }
    if (numericOrder && allNumbers && !values.empty()) {
        std::sort(values.begin(), values.end());
        values.erase(std::unique(values.begin(), values.end()), values.end());
        for (double x : values) numericOrder->push_back(fmt::format("{}", x));
    }
    return out;
}

std::vector<std::string> levelList(const json& body, const char* key) {
    if (!body.contains(key) || body.at(key).is_null()) return {};
    const json& v = body.at(key);
    if (!v.is_array())
        throw MixedRequestError(fmt::format("'{}' must be an array of strings", key));
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i].is_string())
            out.push_back(v[i].get<std::string>());
        else if (v[i].is_number())
            out.push_back(fmt::format("{}", v[i].get<double>()));
        else
            throw MixedRequestError(fmt::format("'{}[{}]' must be a string", key, i));
    }
    return out;
}

json coefficients(std::string_view test, const std::vector<FixedEffect>& terms, bool withP) {
    json out = json::array();
    for (const auto& f : terms) {
        json c{{"name", f.name},
               {"estimate", num(f.estimate)},
               {"se", num(f.se)},
               {"statistic", num(f.statistic)}};
        if (withP) c["p"] = num(f.p);
        if (test == "lmm") c["df"] = num(f.df);
        out.push_back(c);
    }
    return out;
}

json resultObject(std::string_view test, const MixedModelResult& r,
                  const OrdinalMixedResult* ordinal = nullptr) {
    const json fixed = coefficients(test, r.fixed, true);
    json out{
        {"test", std::string(test)},
        {"method", r.method},
        {"formula", r.formula},
        {"fixed", fixed},
        {"statistic_name", r.statisticName},
        {"random_variance", num(r.randomVariance)},
        {"loglik", num(r.logLik)},
        {"aic", num(r.aic)},
        {"deviance", num(r.deviance)},
        {"nobs", r.nObs},
        {"ngroups", r.nGroups},
        {"lrt",
         json{{"statistic", num(r.lrt.statistic)}, {"df", num(r.lrt.df)}, {"p", num(r.lrt.p)}}},
        {"warnings", r.warnings}};
    if (test == "lmm")
        out["residual_variance"] = num(r.residualVariance);
    else
        out["nAGQ"] = r.nAGQ;
    if (const auto* o = ordinal) {
        out["thresholds"] = coefficients(test, o->thresholds, false);
        out["link"] = o->link;
        out["levels"] = o->categories;
    }
    return out;
}

/// The scale's categories of a clmm request ("levels": numbers in increasing order).
std::vector<double> categoryList(const json& body) {
    if (!body.contains("levels") || body.at("levels").is_null()) return {};
    const json& v = body.at("levels");
    if (!v.is_array())
        throw MixedRequestError("'levels' must be an array of numbers (the scale's categories)");
    std::vector<double> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!v[i].is_number())
            throw MixedRequestError(fmt::format("'levels[{}]' must be a number", i));
        out.push_back(v[i].get<double>());
    }
    return out;
}

json run(std::string_view test, const json& body) {
    if (!body.is_object()) throw MixedRequestError("the request must be a JSON object");
    std::set<std::string> allowed{"y",       "condition",        "participant",
                                  "surface", "condition_levels", "surface_levels"};
    if (test != "lmm") allowed.insert("nAGQ");
    if (test == "clmm") allowed.insert({"link", "levels"});
    for (const auto& [key, value] : body.items())
        if (!allowed.count(key))
            throw MixedRequestError(fmt::format("unknown field '{}' (expected one of: {})", key,
                                                fmt::join(allowed, ", ")));
    MixedModelData data;
    data.y = numbers(body, "y");
    std::vector<std::string> conditionOrder, surfaceOrder;
    data.condition = labels(body, "condition", true, &conditionOrder);
    data.participant = labels(body, "participant", true, nullptr);
    data.surface = labels(body, "surface", false, &surfaceOrder);
    data.conditionLevels = levelList(body, "condition_levels");
    if (data.conditionLevels.empty()) data.conditionLevels = conditionOrder;
    data.surfaceLevels = levelList(body, "surface_levels");
    if (data.surfaceLevels.empty()) data.surfaceLevels = surfaceOrder;
    int nAGQ = 1;
    if (body.contains("nAGQ") && !body.at("nAGQ").is_null()) {
        const json& v = body.at("nAGQ");
        if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 25)
            throw MixedRequestError("'nAGQ' must be an integer from 1 (Laplace) to 25");
        nAGQ = static_cast<int>(v.get<long long>());
    }
    if (test == "clmm") {
        OrdinalOptions o;
        o.nAGQ = nAGQ;
        o.categories = categoryList(body);
        if (body.contains("link") && !body.at("link").is_null()) {
            const json& v = body.at("link");
            if (!v.is_string() || !parseOrdinalLink(v.get<std::string>(), o.link))
                throw MixedRequestError("'link' must be \"logit\", \"probit\" or \"cloglog\"");
        }
        const OrdinalMixedResult r = fitOrdinalMixedModel(data, o);
        if (!r.ok()) throw MixedRequestError(r.error);
        return resultObject(test, r, &r);
    }
    const MixedModelResult r =
        test == "glmm" ? fitLogisticMixedModel(data, nAGQ) : fitLinearMixedModel(data);
    if (!r.ok()) throw MixedRequestError(r.error);
    return resultObject(test, r);
}

std::string dump(const json& j) {
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

} // namespace

bool isMixedModelTest(std::string_view test) {
    return test == "glmm" || test == "lmm" || test == "clmm";
}

std::string mixedModelResultJson(std::string_view test, const MixedModelResult& result) {
    return dump(resultObject(test, result));
}

std::string ordinalModelResultJson(const OrdinalMixedResult& result) {
    return dump(resultObject("clmm", result, &result));
}

StatsResponse runMixedModelRequest(std::string_view test, std::string_view requestJson) {
    try {
        if (!isMixedModelTest(test))
            throw MixedRequestError(
                fmt::format("unknown mixed model '{}' (glmm, lmm or clmm)", test));
        const json body = json::parse(requestJson.begin(), requestJson.end());
        return {true, dump(run(test, body))};
    } catch (const json::parse_error& e) {
        return {false, dump(json{{"error",
                                  fmt::format("invalid JSON at byte {}: {}", e.byte, e.what())}})};
    } catch (const std::exception& e) {
        return {false, dump(json{{"error", e.what()}})};
    }
}

} // namespace underfoot::analysis
