// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/RatingModel.h"

#include "base/Suggest.h"
#include "base/TomlReader.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>

namespace underfoot::experiment {

double RatingModel::expected(const std::string& scaleId, const Stimulus& stimulus,
                             const std::map<std::string, std::string>& fields) const {
    const auto it = scales.find(scaleId);
    if (it == scales.end()) return std::numeric_limits<double>::quiet_NaN();
    const ScaleRatingModel& m = it->second;
    double value = m.base;
    for (const auto& [factor, levels] : m.effects) {
        const auto level = stimulus.factors.find(factor);
        if (level == stimulus.factors.end()) continue;
        if (const auto e = levels.find(level->second); e != levels.end()) value += e->second;
    }
    if (const auto e = m.stimulusEffects.find(stimulus.id); e != m.stimulusEffects.end())
        value += e->second;
    for (const auto& [field, answers] : m.fieldEffects) {
        const auto answer = fields.find(field);
        if (answer == fields.end()) continue;
        if (const auto e = answers.find(answer->second); e != answers.end()) value += e->second;
    }
    return value;
}

namespace {

/// The rating model's tables: the shared collecting reader and two nestings of numbers.
struct ModelReader : base::TomlReader {
    using base::TomlReader::TomlReader;

    std::map<std::string, double> numbers(const toml::node& node, const std::string& what) {
        std::map<std::string, double> out;
        const toml::table* t = node.as_table();
        if (!t) {
            problem(node, fmt::format("{} must be a table of numbers", what));
            return out;
        }
        for (auto&& [key, value] : *t)
            if (auto v = numberNode(value, fmt::format("{}.{}", what, key.str()), -1000, 1000))
                out[std::string(key.str())] = *v;
        return out;
    }
    void nested(const toml::node& node, const std::string& what,
                std::map<std::string, std::map<std::string, double>>& into) {
        const toml::table* t = node.as_table();
        if (!t) {
            problem(node, fmt::format("{} must be a table of tables", what));
            return;
        }
        for (auto&& [key, value] : *t)
            into[std::string(key.str())] = numbers(value, fmt::format("{}.{}", what, key.str()));
    }
};

} // namespace

RatingModel parseRatingModel(const std::string& text, const std::string& sourceName) {
    ModelReader r(sourceName);
    toml::table root;
    try {
        root = base::parseToml(text, sourceName);
    } catch (const base::TomlError& e) {
        throw ProtocolError(e.problems());
    }
    RatingModel model;
    model.source = sourceName;
    for (auto&& [key, node] : root) {
        const std::string k(key.str());
        if (k == "model") {
            const toml::table* t = node.as_table();
            if (!t) {
                r.problem(node, "[model] must be a table");
                continue;
            }
            r.checkKeys(*t, {"replay_probability"}, "[model]");
            if (const auto* mv = t->get("replay_probability"))
                if (auto v = r.numberNode(*mv, "[model].replay_probability", 0, 0.95))
                    model.replayProbability = *v;
        } else if (k == "scales") {
            const toml::table* t = node.as_table();
            if (!t) {
                r.problem(node, "'scales' must be a table of [scales.<id>] tables");
                continue;
            }
            for (auto&& [scaleId, scaleNode] : *t) {
                const std::string ctx = fmt::format("[scales.{}]", scaleId.str());
                const toml::table* st = scaleNode.as_table();
                if (!st) {
                    r.problem(scaleNode, fmt::format("{} must be a table", ctx));
                    continue;
                }
                ScaleRatingModel m;
                bool hasBase = false;
                r.checkKeys(*st,
                            {"base", "participant_sd", "noise_sd", "effects", "stimuli", "fields"},
                            ctx);
                for (auto&& [sk, sv] : *st) {
                    const std::string name(sk.str());
                    const std::string what = ctx + "." + name;
                    if (name == "base") {
                        if (auto v = r.numberNode(sv, what, -1000, 1000)) m.base = *v;
                        hasBase = true;
                    } else if (name == "participant_sd") {
                        if (auto v = r.numberNode(sv, what, 0, 100)) m.participantSd = *v;
                    } else if (name == "noise_sd") {
                        if (auto v = r.numberNode(sv, what, 0, 100)) m.noiseSd = *v;
                    } else if (name == "effects") {
                        r.nested(sv, what, m.effects);
                    } else if (name == "stimuli") {
                        m.stimulusEffects = r.numbers(sv, what);
                    } else if (name == "fields") {
                        r.nested(sv, what, m.fieldEffects);
                    }
                }
                if (!hasBase)
                    r.problem(scaleNode.source(),
                              fmt::format("missing key 'base' in {}; expected the scale's "
                                          "typical rating",
                                          ctx));
                model.scales[std::string(scaleId.str())] = std::move(m);
            }
        } else {
            const std::string close = base::closestName(k, {"model", "scales"});
            r.problem(node.source(), // the [header]
                      fmt::format("unknown table '{}' in a rating model; expected [model] or "
                                  "[scales.<id>]{}",
                                  k, close.empty() ? "" : " (did you mean '" + close + "'?)"));
        }
    }
    if (model.scales.empty() && r.problems().empty())
        r.problem(root.source(), "the rating model declares no [scales.<id>]");
    if (!r.problems().empty()) throw ProtocolError(r.sortedProblems());
    return model;
}

RatingModel loadRatingModel(const std::string& path) {
    std::string text;
    try {
        text = base::readTomlFile(path, "a readable TOML rating model");
    } catch (const base::TomlError& e) {
        throw ProtocolError(e.problems());
    }
    return parseRatingModel(text, path);
}

std::vector<std::string> checkRatingModel(const RatingModel& model, const Protocol& protocol) {
    std::vector<std::string> problems;
    std::map<std::string, std::set<std::string>> levels;
    for (const auto& s : protocol.stimuli)
        for (const auto& [f, l] : s.factors) levels[f].insert(l);
    for (const auto& [scaleId, m] : model.scales) {
        if (!protocol.questions.scale(scaleId)) {
            problems.push_back(fmt::format("{}: scale '{}' is not a scale of protocol {}",
                                           model.source, scaleId, protocol.id));
            continue;
        }
        for (const auto& [factor, effects] : m.effects) {
            if (!levels.count(factor)) {
                problems.push_back(fmt::format("{}: scale '{}' has effects of factor '{}', which "
                                               "no stimulus of protocol {} has",
                                               model.source, scaleId, factor, protocol.id));
                continue;
            }
            for (const auto& [level, v] : effects)
                if (!levels[factor].count(level))
                    problems.push_back(fmt::format("{}: scale '{}': factor '{}' has no level '{}'",
                                                   model.source, scaleId, factor, level));
        }
        for (const auto& [sid, v] : m.stimulusEffects)
            if (!protocol.stimulus(sid))
                problems.push_back(fmt::format("{}: scale '{}': unknown stimulus '{}'",
                                               model.source, scaleId, sid));
        for (const auto& [field, effects] : m.fieldEffects) {
            const ParticipantField* f = protocol.participantField(field);
            if (!f) {
                problems.push_back(fmt::format("{}: scale '{}': unknown participant field '{}'",
                                               model.source, scaleId, field));
                continue;
            }
            for (const auto& [answer, v] : effects)
                if (!f->options.empty() &&
                    std::find(f->options.begin(), f->options.end(), answer) == f->options.end())
                    problems.push_back(fmt::format("{}: scale '{}': field '{}' has no option '{}'",
                                                   model.source, scaleId, field, answer));
        }
    }
    return problems;
}

} // namespace underfoot::experiment
