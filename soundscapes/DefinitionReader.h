// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Internal to soundscapes/: the reader that the soundscape definitions and the coherence table
/// share. Every error it throws is a DefinitionError that names FILE:LINE:COLUMN and what was
/// expected; key and number checks are those of the project's TOML reader (base/TomlReader.h,
/// on toml++, https://marzer.github.io/tomlplusplus/).
#include "base/TomlReader.h"
#include "soundscapes/Definition.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace underfoot::soundscapes {

// Reads one TOML file with located, explicit error messages.
class DefinitionReader {
  public:
    explicit DefinitionReader(std::string source) : source_(std::move(source)) {}

    std::string where(const toml::node& node) const {
        const auto& b = node.source().begin;
        return fmt::format("{}:{}:{}", source_, b.line, b.column);
    }
    [[noreturn]] void fail(const toml::node& node, const std::string& what) const {
        throw DefinitionError(fmt::format("{}: {}", where(node), what));
    }
    [[noreturn]] void failAt(const std::string& where, const std::string& what) const {
        throw DefinitionError(fmt::format("{}: {}", where, what));
    }

    // The unknown-key check and the number checks of the shared reader (base/TomlReader.h),
    // stopping at the first problem.
    void checkKeys(const toml::table& t, const std::set<std::string>& allowed,
                   const std::string& context) const {
        base::rethrowTomlAs<DefinitionError>([&] {
            base::TomlReader(source_, base::TomlReader::Mode::Throw)
                .checkKeys(t, std::vector<std::string>(allowed.begin(), allowed.end()), context);
        });
    }

    std::string string(const toml::table& t, std::string_view key, const std::string& context,
                       const toml::node& owner, bool required) const {
        const toml::node* n = t.get(key);
        if (!n) {
            if (required) fail(owner, fmt::format("{} needs a string '{}'", context, key));
            return {};
        }
        if (!n->is_string()) fail(*n, fmt::format("'{}' must be a string", key));
        return std::string(*n->as_string());
    }

    double number(const toml::node& n, std::string_view key, double lo, double hi) const {
        return base::rethrowTomlAs<DefinitionError>([&] {
            return *base::TomlReader(source_, base::TomlReader::Mode::Throw)
                        .numberNode(n, fmt::format("'{}'", key), lo, hi);
        });
    }
    double number(const toml::table& t, std::string_view key, double lo, double hi,
                  double fallback) const {
        const toml::node* n = t.get(key);
        return n ? number(*n, key, lo, hi) : fallback;
    }
    std::pair<double, double> range(const toml::node& n, std::string_view key, double lo,
                                    double hi) const {
        const toml::array* a = n.as_array();
        if (!a || a->size() != 2)
            fail(n, fmt::format("'{}' must be a two-number array [min, max]", key));
        const double x = number(*a->get(0), key, lo, hi), y = number(*a->get(1), key, lo, hi);
        if (x > y) fail(n, fmt::format("'{}' must be [min, max] with min <= max", key));
        return {x, y};
    }

    // Calls each(table, node) for every entry of the array of tables [[key]] of root, if
    // present; anything else under that key is an error at its place.
    template <class Each>
    void forEachTable(const toml::table& root, std::string_view key, Each each) const {
        const toml::node* n = root.get(key);
        if (!n) return;
        const toml::array* arr = n->as_array();
        if (!arr) fail(*n, fmt::format("'{}' must be an array of tables: [[{}]]", key, key));
        for (const auto& item : *arr) {
            const toml::table* t = item.as_table();
            if (!t) fail(item, fmt::format("[[{}]] entries must be tables", key));
            each(*t, item);
        }
    }

  private:
    std::string source_;
};

} // namespace underfoot::soundscapes
