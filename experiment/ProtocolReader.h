// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The protocol reader's parts, shared by the files that read one table each (Protocol.cpp,
/// ProtocolStimuli.cpp, ProtocolQuestions.cpp, ProtocolOrdering.cpp, ProtocolSettings.cpp): the
/// TOML reader that collects every problem with its position, and the state of one parse.
#include "experiment/Protocol.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::experiment::protocol_detail {

inline bool validId(std::string_view id) {
    if (id.empty() || id.size() > 64) return false;
    return std::all_of(id.begin(), id.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
               (c >= 'A' && c <= 'Z');
    });
}

inline std::string joinIds(const std::vector<CatalogueEntry>& entries) {
    std::string out;
    for (const auto& e : entries) out += (out.empty() ? "" : ", ") + e.id;
    return out;
}

inline std::vector<std::string> ids(const std::vector<CatalogueEntry>& entries) {
    std::vector<std::string> out;
    for (const auto& e : entries) out.push_back(e.id);
    return out;
}

inline std::string joinList(const std::vector<std::string>& values) {
    std::string out;
    for (const auto& v : values) out += (out.empty() ? "" : ", ") + v;
    return out;
}

class Reader {
  public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    void problem(const toml::source_region& where, std::string message) {
        problems_.push_back({file_, static_cast<int>(where.begin.line),
                             static_cast<int>(where.begin.column), std::move(message)});
    }
    void problem(const toml::node& where, std::string message) {
        problem(where.source(), std::move(message));
    }
    /// A problem that follows from an earlier one (listed after every root cause).
    void derived(const toml::source_region& where, std::string message) {
        problem(where, std::move(message));
        problems_.back().derived = true;
    }
    std::vector<ProtocolProblem>& problems() { return problems_; }

    /// Reports keys of `table` not in `allowed` (catches typos instead of ignoring them).
    void checkKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                   std::string_view context) {
        for (auto&& [key, node] : table) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
            std::string expected;
            for (auto a : allowed) expected += (expected.empty() ? "" : ", ") + std::string(a);
            std::vector<std::string> names;
            for (auto a : allowed) names.emplace_back(a);
            problem(key.source().begin.line ? key.source() : node.source(),
                    fmt::format("unknown key '{}' in {}; expected one of: {}", key.str(), context,
                                sortedIdsWithSuggestion(key.str(), names)));
        }
    }

    const toml::table* table(const toml::table& parent, std::string_view key,
                             std::string_view context, bool required) {
        const toml::node* node = parent.get(key);
        if (!node) {
            if (required) problem(parent, fmt::format("missing table [{}] in {}", key, context));
            return nullptr;
        }
        if (!node->is_table()) {
            problem(*node, fmt::format("'{}' in {} must be a table", key, context));
            return nullptr;
        }
        return node->as_table();
    }

    std::optional<std::string> string(const toml::table& t, std::string_view key,
                                      std::string_view context, bool required) {
        const toml::node* node = t.get(key);
        if (!node) {
            if (required)
                problem(t, fmt::format("missing key '{}' in {}; expected a string", key, context));
            return std::nullopt;
        }
        if (!node->is_string()) {
            problem(*node, fmt::format("'{}' in {} must be a string", key, context));
            return std::nullopt;
        }
        return node->as_string()->get();
    }

    std::optional<std::string> id(const toml::table& t, std::string_view key,
                                  std::string_view context, bool required) {
        auto value = string(t, key, context, required);
        if (value && !validId(*value)) {
            problem(*t.get(key),
                    fmt::format("'{}' in {} is '{}'; expected an id of letters, digits, '_' or "
                                "'-' (1 to 64 characters)",
                                key, context, *value));
            return std::nullopt;
        }
        return value;
    }

    std::optional<std::int64_t> integer(const toml::table& t, std::string_view key,
                                        std::string_view context, bool required, std::int64_t min,
                                        std::int64_t max) {
        const toml::node* node = t.get(key);
        if (!node) {
            if (required)
                problem(t,
                        fmt::format("missing key '{}' in {}; expected an integer", key, context));
            return std::nullopt;
        }
        if (!node->is_integer()) {
            problem(*node, fmt::format("'{}' in {} must be an integer", key, context));
            return std::nullopt;
        }
        const std::int64_t v = node->as_integer()->get();
        if (v < min || v > max) {
            problem(*node,
                    fmt::format("'{}' in {} is {}; expected {} to {}", key, context, v, min, max));
            return std::nullopt;
        }
        return v;
    }

    std::optional<double> number(const toml::table& t, std::string_view key,
                                 std::string_view context, double min, double max) {
        const toml::node* node = t.get(key);
        if (!node) return std::nullopt;
        double v = 0.0;
        if (node->is_integer())
            v = static_cast<double>(node->as_integer()->get());
        else if (node->is_floating_point())
            v = node->as_floating_point()->get();
        else {
            problem(*node, fmt::format("'{}' in {} must be a number", key, context));
            return std::nullopt;
        }
        if (!std::isfinite(v) || v < min || v > max) {
            problem(*node, fmt::format("'{}' in {} is {}; expected a finite number from {} to {}",
                                       key, context, v, min, max));
            return std::nullopt;
        }
        return v;
    }

    std::optional<bool> boolean(const toml::table& t, std::string_view key,
                                std::string_view context) {
        const toml::node* node = t.get(key);
        if (!node) return std::nullopt;
        if (!node->is_boolean()) {
            problem(*node, fmt::format("'{}' in {} must be true or false", key, context));
            return std::nullopt;
        }
        return node->as_boolean()->get();
    }

    /// An array of strings with the source of each element.
    std::vector<std::pair<std::string, toml::source_region>>
    strings(const toml::table& t, std::string_view key, std::string_view context) {
        std::vector<std::pair<std::string, toml::source_region>> out;
        const toml::node* node = t.get(key);
        if (!node) return out;
        const toml::array* array = node->as_array();
        if (!array) {
            problem(*node, fmt::format("'{}' in {} must be an array of strings", key, context));
            return out;
        }
        for (const toml::node& element : *array) {
            if (!element.is_string()) {
                problem(element,
                        fmt::format("elements of '{}' in {} must be strings", key, context));
                continue;
            }
            out.emplace_back(element.as_string()->get(), element.source());
        }
        return out;
    }

    /// A `choice` string: one of the given names.
    template <typename E>
    std::optional<E> choice(const toml::table& t, std::string_view key, std::string_view context,
                            std::initializer_list<std::pair<std::string_view, E>> names) {
        auto value = string(t, key, context, false);
        if (!value) return std::nullopt;
        for (const auto& [name, e] : names)
            if (name == *value) return e;
        std::string expected;
        for (const auto& [name, e] : names)
            expected += (expected.empty() ? "" : ", ") + std::string(name);
        problem(*t.get(key), fmt::format("'{}' in {} is '{}'; expected one of: {}", key, context,
                                         *value, expected));
        return std::nullopt;
    }

    /// Free parameters: numbers (finite), strings, booleans.
    Parameters parameters(const toml::table& t, std::string_view context) {
        Parameters out;
        for (auto&& [key, node] : t) {
            const std::string name(key.str());
            if (node.is_boolean())
                out[name] = node.as_boolean()->get();
            else if (node.is_string())
                out[name] = node.as_string()->get();
            else if (node.is_integer())
                out[name] = static_cast<double>(node.as_integer()->get());
            else if (node.is_floating_point()) {
                const double v = node.as_floating_point()->get();
                if (!std::isfinite(v))
                    problem(node, fmt::format("'{}' in {} is not a finite number", name, context));
                else
                    out[name] = v;
            } else
                problem(node, fmt::format("'{}' in {} must be a number, a string or a boolean",
                                          name, context));
        }
        return out;
    }

  private:
    std::string file_;
    std::vector<ProtocolProblem> problems_;
};

inline const std::initializer_list<std::pair<std::string_view, Modalities>> kModalityNames = {
    {"audio", Modalities::Audio},
    {"haptic", Modalities::Haptic},
    {"both", Modalities::AudioHaptic},
    {"audio_haptic", Modalities::AudioHaptic}};

/// One parse: the reader, the document, the protocol being filled and what the tables share.
struct ProtocolParse {
    Reader& r;
    const toml::table& root;
    Protocol& p;
    const Catalogue& catalogue;
    /// [input]: the default input of every stimulus.
    Input defaultInput;
    /// Where each stimulus id was declared.
    std::map<std::string, toml::source_region> stimulusPlace;
    /// [ordering] (null when absent).
    const toml::table* orderingTable = nullptr;
    /// Adds a stimulus unless its id is empty or already used (reported).
    void addStimulus(Stimulus s, const toml::source_region& where);
};

Input readInput(Reader& r, const toml::table& t, std::string_view context, const Input& fallback);
std::string levelText(const toml::node& node);

// One function per table, in the order parseProtocol calls them.
void readHeader(ProtocolParse& x);    // [protocol], [design], [timing], [input]
void readStimuli(ProtocolParse& x);   // [[stimuli]]
void readFactorial(ProtocolParse& x); // [[factorial]]
void readGroups(ProtocolParse& x);    // [[groups]]
void readOrdering(ProtocolParse& x);  // [ordering]
void readQuestions(ProtocolParse& x); // [questions]
void readSettings(
    ProtocolParse& x); // [laps], [clips], [[participant_fields]], [rules], [simulation]
void checkDriverKeys(ProtocolParse& x); // the walker and wading keys of every stimulus
/// The plans' feasibility: no-immediate-repeat, breaks (after [questions]: per-scale blocks).
void checkOrdering(Reader& r, const toml::table* orderingTable, const toml::table& root,
                   const Protocol& p);

} // namespace underfoot::experiment::protocol_detail
