// SPDX-License-Identifier: GPL-3.0-or-later
#include "base/TomlReader.h"

#include "base/Suggest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <tuple>

namespace underfoot::base {

std::string TomlProblem::toString() const {
    if (line > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
    return fmt::format("{}: {}", file, message);
}

namespace {
std::string joinProblems(const std::vector<TomlProblem>& problems) {
    std::string out;
    for (const auto& p : problems) {
        if (!out.empty()) out += '\n';
        out += p.toString();
    }
    return out;
}
} // namespace

bool isValidId(std::string_view id) {
    if (id.empty() || id.size() > 64) return false;
    return std::all_of(id.begin(), id.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
               (c >= 'A' && c <= 'Z');
    });
}

TomlError::TomlError(std::vector<TomlProblem> problems)
    : std::runtime_error(joinProblems(problems)), problems_(std::move(problems)) {}

std::string sourcePlace(std::string_view file, const toml::source_region& where) {
    if (where.begin.line == 0) return std::string(file);
    return fmt::format("{}:{}:{}", file, where.begin.line, where.begin.column);
}

std::string_view tomlTypeName(const toml::node& node) {
    return toml::impl::node_type_friendly_names[static_cast<int>(node.type())];
}

std::string readTomlFile(const std::string& path, std::string_view what, std::size_t maxBytes) {
    namespace fs = std::filesystem;
    auto fail = [&](std::string why) {
        throw TomlError({{path, 0, 0, fmt::format("{}; expected {}", why, what)}});
    };
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) fail("no such file");
    if (fs::is_directory(status)) fail("is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) fail("cannot open the file");
    std::string text;
    char buffer[65536];
    while (in) {
        in.read(buffer, sizeof buffer);
        const auto got = static_cast<std::size_t>(in.gcount());
        if (text.size() + got > maxBytes)
            fail(fmt::format("larger than {} bytes (the limit of a TOML file)", maxBytes));
        text.append(buffer, got);
    }
    if (in.bad()) fail("read error");
    return text;
}

toml::table parseToml(std::string_view text, std::string_view source) {
    try {
        return toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        const auto& where = e.source().begin;
        throw TomlError(
            {{std::string(source), static_cast<int>(where.line), static_cast<int>(where.column),
              fmt::format("TOML syntax error: {}", e.description())}});
    }
}

toml::table parseTomlFile(const std::string& path, std::string_view what) {
    return parseToml(readTomlFile(path, what), path);
}

// ----------------------------------------------------------------------------------------------

void TomlReader::problem(const toml::source_region& where, std::string message) {
    problems_.push_back({file_, static_cast<int>(where.begin.line),
                         static_cast<int>(where.begin.column), std::move(message)});
    if (mode_ == Mode::Throw) throw TomlError(problems_);
}

void TomlReader::derived(const toml::source_region& where, std::string message) {
    problems_.push_back({file_, static_cast<int>(where.begin.line),
                         static_cast<int>(where.begin.column), std::move(message), true});
    if (mode_ == Mode::Throw) throw TomlError(problems_);
}

std::vector<TomlProblem> TomlReader::sortedProblems() const {
    auto problems = problems_;
    std::stable_sort(
        problems.begin(), problems.end(), [](const TomlProblem& a, const TomlProblem& b) {
            return std::tie(a.derived, a.line, a.column) < std::tie(b.derived, b.line, b.column);
        });
    return problems;
}

void TomlReader::throwIfProblems() const {
    if (!problems_.empty()) throw TomlError(sortedProblems());
}

void TomlReader::checkKeys(const toml::table& table,
                           std::initializer_list<std::string_view> allowed,
                           std::string_view context) {
    std::vector<std::string> names;
    for (auto a : allowed) names.emplace_back(a);
    checkKeys(table, names, context);
}

void TomlReader::checkKeys(const toml::table& table, const std::vector<std::string>& allowed,
                           std::string_view context) {
    for (auto&& [key, node] : table) {
        if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
        problem(key.source().begin.line ? key.source() : node.source(),
                fmt::format("unknown key '{}' in {}; expected one of: {}", key.str(), context,
                            sortedIdsWithSuggestion(key.str(), allowed)));
    }
}

const toml::table* TomlReader::table(const toml::table& parent, std::string_view key,
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

const toml::array* TomlReader::array(const toml::table& parent, std::string_view key,
                                     std::string_view context) {
    const toml::node* node = parent.get(key);
    if (!node) return nullptr;
    if (!node->is_array()) {
        problem(*node, fmt::format("'{}' in {} must be an array, got {}", key, context,
                                   tomlTypeName(*node)));
        return nullptr;
    }
    return node->as_array();
}

std::optional<std::string> TomlReader::string(const toml::table& t, std::string_view key,
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

std::optional<std::string> TomlReader::id(const toml::table& t, std::string_view key,
                                          std::string_view context, bool required) {
    auto value = string(t, key, context, required);
    if (value && !isValidId(*value)) {
        problem(*t.get(key),
                fmt::format("'{}' in {} is '{}'; expected an id of letters, digits, '_' or "
                            "'-' (1 to 64 characters)",
                            key, context, *value));
        return std::nullopt;
    }
    return value;
}

std::optional<std::int64_t> TomlReader::integer(const toml::table& t, std::string_view key,
                                                std::string_view context, bool required,
                                                std::int64_t min, std::int64_t max) {
    const toml::node* node = t.get(key);
    if (!node) {
        if (required)
            problem(t, fmt::format("missing key '{}' in {}; expected an integer", key, context));
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

std::optional<double> TomlReader::numberNode(const toml::node& node, std::string_view what,
                                             double min, double max) {
    double v = 0.0;
    if (node.is_integer())
        v = static_cast<double>(node.as_integer()->get());
    else if (node.is_floating_point())
        v = node.as_floating_point()->get();
    else {
        problem(node, fmt::format("{} must be a number", what));
        return std::nullopt;
    }
    if (!std::isfinite(v) || v < min || v > max) {
        problem(node,
                fmt::format("{} is {}; expected a finite number from {} to {}", what, v, min, max));
        return std::nullopt;
    }
    return v;
}

std::optional<double> TomlReader::number(const toml::table& t, std::string_view key,
                                         std::string_view context, double min, double max,
                                         bool required) {
    const toml::node* node = t.get(key);
    if (!node) {
        if (required)
            problem(t, fmt::format("missing key '{}' in {}; expected a number from {} to {}", key,
                                   context, min, max));
        return std::nullopt;
    }
    return numberNode(*node, fmt::format("'{}' in {}", key, context), min, max);
}

std::optional<bool> TomlReader::boolean(const toml::table& t, std::string_view key,
                                        std::string_view context) {
    const toml::node* node = t.get(key);
    if (!node) return std::nullopt;
    if (!node->is_boolean()) {
        problem(*node, fmt::format("'{}' in {} must be true or false", key, context));
        return std::nullopt;
    }
    return node->as_boolean()->get();
}

std::vector<std::pair<std::string, toml::source_region>>
TomlReader::strings(const toml::table& t, std::string_view key, std::string_view context) {
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
            problem(element, fmt::format("elements of '{}' in {} must be strings", key, context));
            continue;
        }
        out.emplace_back(element.as_string()->get(), element.source());
    }
    return out;
}

std::optional<std::size_t> TomlReader::choiceIndex(const toml::table& t, std::string_view key,
                                                   std::string_view context,
                                                   const std::vector<std::string_view>& names) {
    auto value = string(t, key, context, false);
    if (!value) return std::nullopt;
    for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == *value) return i;
    std::string expected;
    for (auto name : names) expected += (expected.empty() ? "" : ", ") + std::string(name);
    problem(*t.get(key),
            fmt::format("'{}' in {} is '{}'; expected one of: {}", key, context, *value, expected));
    return std::nullopt;
}

} // namespace underfoot::base
