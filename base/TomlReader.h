// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The one TOML reader (toml++, https://marzer.github.io/tomlplusplus/) every file format of the
/// project goes through: protocols, rating models, surface and wading presets, soundscapes,
/// audio settings, step calibrations, stored stimuli, replays.
///  - reading a file: bounded size, a clear message for a missing or unreadable file;
///  - parsing: a syntax error reads "FILE:LINE:COL: TOML syntax error: <what toml++ says>";
///  - typed accessors (TomlReader): required/optional keys with type, integer vs number,
///    finite and range checks, arrays of strings, subtables, one-of choices;
///  - the unknown-key check, with the did-you-mean of base/Suggest.h.
/// Every problem names the file and line:column; a reader either collects them all (a protocol
/// lists every problem at once, root causes first) or throws at the first.
#include "base/TomlError.h"

#include <toml++/toml.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace underfoot::base {

/// The largest TOML file read (a protocol or preset is a few kB).
inline constexpr std::size_t kMaxTomlFileBytes = 4u << 20;

/// "file:line:column" of a node's source (just the file when it has no position).
std::string sourcePlace(std::string_view file, const toml::source_region& where);

/// The text of a TOML file. Throws TomlError naming the file when it is missing, unreadable,
/// a directory or larger than `maxBytes`; `what` says what the file should be ("a protocol").
std::string readTomlFile(const std::string& path, std::string_view what = "a TOML file",
                         std::size_t maxBytes = kMaxTomlFileBytes);

/// Parses TOML text; `source` names it in messages. Throws TomlError with the position and
/// what toml++ says for a syntax error.
toml::table parseToml(std::string_view text, std::string_view source);

/// readTomlFile() then parseToml().
toml::table parseTomlFile(const std::string& path, std::string_view what = "a TOML file");

/// Runs `f` (a parse or read of TOML) and turns a TomlError into the caller's exception type
/// `E` (constructed from the message), so callers keep the exceptions they document.
template <typename E, typename F>
decltype(auto) rethrowTomlAs(F&& f) {
    try {
        return f();
    } catch (const TomlError& e) {
        throw E(e.what());
    }
}

/// Typed reading of TOML tables with every problem positioned. In Collect mode the accessors
/// record the problem and return nullopt (the caller reads on and reports all at the end); in
/// Throw mode the first problem throws TomlError.
class TomlReader {
  public:
    enum class Mode { Collect, Throw };
    explicit TomlReader(std::string file, Mode mode = Mode::Collect)
        : file_(std::move(file)), mode_(mode) {}

    const std::string& file() const noexcept { return file_; }

    void problem(const toml::source_region& where, std::string message);
    void problem(const toml::node& where, std::string message) {
        problem(where.source(), std::move(message));
    }
    /// A problem that follows from an earlier one (listed after every root cause).
    void derived(const toml::source_region& where, std::string message);
    std::vector<TomlProblem>& problems() noexcept { return problems_; }
    /// The problems, root causes first, then by position.
    std::vector<TomlProblem> sortedProblems() const;
    /// Throws TomlError with sortedProblems() when there is any.
    void throwIfProblems() const;

    /// Reports each key of `table` not in `allowed`: "unknown key 'k' in CONTEXT; expected one
    /// of: a, b (did you mean 'a'?)", at the key's position.
    void checkKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                   std::string_view context);
    void checkKeys(const toml::table& table, const std::vector<std::string>& allowed,
                   std::string_view context);

    /// A subtable (missing: a problem when `required`).
    const toml::table* table(const toml::table& parent, std::string_view key,
                             std::string_view context, bool required);
    /// An array (of anything; missing: nullptr).
    const toml::array* array(const toml::table& parent, std::string_view key,
                             std::string_view context);
    std::optional<std::string> string(const toml::table& t, std::string_view key,
                                      std::string_view context, bool required);
    /// A string of letters, digits, '_' or '-' (1 to 64 characters).
    std::optional<std::string> id(const toml::table& t, std::string_view key,
                                  std::string_view context, bool required);
    /// A whole number (a float such as 2.0 is rejected) in [min, max].
    std::optional<std::int64_t> integer(const toml::table& t, std::string_view key,
                                        std::string_view context, bool required, std::int64_t min,
                                        std::int64_t max);
    /// A finite number (integer or float) in [min, max].
    std::optional<double> number(const toml::table& t, std::string_view key,
                                 std::string_view context, double min, double max,
                                 bool required = false);
    /// A finite number node in [min, max]; `what` names it ("'x' in [model]").
    std::optional<double> numberNode(const toml::node& node, std::string_view what, double min,
                                     double max);
    std::optional<bool> boolean(const toml::table& t, std::string_view key,
                                std::string_view context);
    /// An array of strings with the source of each element.
    std::vector<std::pair<std::string, toml::source_region>>
    strings(const toml::table& t, std::string_view key, std::string_view context);
    /// A string that must be one of `names` (index into `names`).
    std::optional<std::size_t> choiceIndex(const toml::table& t, std::string_view key,
                                           std::string_view context,
                                           const std::vector<std::string_view>& names);
    /// A string naming one of the given values.
    template <typename E>
    std::optional<E> choice(const toml::table& t, std::string_view key, std::string_view context,
                            std::initializer_list<std::pair<std::string_view, E>> names) {
        std::vector<std::string_view> keys;
        for (const auto& n : names) keys.push_back(n.first);
        const auto index = choiceIndex(t, key, context, keys);
        if (!index) return std::nullopt;
        return (names.begin() + *index)->second;
    }

  private:
    std::string file_;
    Mode mode_;
    std::vector<TomlProblem> problems_;
};

/// An id: letters, digits, '_' or '-', 1 to 64 characters (what TomlReader::id accepts).
bool isValidId(std::string_view id);

/// toml++'s name of a node's type ("string", "integer", "floating-point", ...).
std::string_view tomlTypeName(const toml::node& node);

} // namespace underfoot::base
