// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reading surface presets (TOML) with every parameter declared once: name, unit, documented
/// range and default. A layer reads its parameters through PresetReader, which
///  - rejects a missing file, bad syntax, a wrong type, a non-finite or out-of-range value and
///    an unknown key, with a message naming the file, line:column and what was expected;
///  - records every parameter it read (ParamInfo), so that the sound palette can show units and
///    ranges and the stability suite can sweep each preset's documented ranges.
#include <toml++/toml.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::engine {

/// A problem in a preset file; what() reads "file:line:column: what was expected".
struct PresetError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// One numeric parameter as declared by the layer that reads it.
struct ParamInfo {
    std::string path; ///< e.g. "layer[2].stiffness"
    std::string unit; ///< e.g. "N/m^alpha"
    double minValue;  ///< documented range
    double maxValue;
    double value;     ///< value in the file (or default)
    bool logScale;    ///< sweep on a log scale (stiffness, rates, ...)
    std::string help; ///< one line: what it does
};

/// "file:line:column" for a TOML node (or just the file when it has no source position).
std::string sourcePlace(const std::string& file, const toml::source_region& where);

class PresetReader {
  public:
    /// `path` names the table in messages ("layer[2]"), `file` the preset file.
    PresetReader(std::string file, const toml::table& table, std::string path,
                 std::vector<ParamInfo>* sink);

    /// A number in [min, max] (integers accepted); `defaultValue` when absent.
    double number(std::string_view key, double defaultValue, double min, double max,
                  std::string_view unit, std::string_view help, bool logScale = false);
    /// A required number in [min, max].
    double requiredNumber(std::string_view key, double min, double max, std::string_view unit,
                          std::string_view help, bool logScale = false);
    /// An integer in [min, max].
    int integer(std::string_view key, int defaultValue, int min, int max, std::string_view help);
    /// A string; when `allowed` is not empty it must be one of them.
    std::string string(std::string_view key, std::string_view defaultValue,
                       const std::vector<std::string>& allowed = {});
    /// An array of tables (e.g. modes); empty when absent.
    std::vector<PresetReader> tables(std::string_view key);
    /// A sub-table; nullopt when absent.
    std::optional<PresetReader> table(std::string_view key);
    /// Marks a key as known without reading it (read by someone else).
    void allow(std::string_view key);
    /// Throws for every key that no call above asked for (typos must not pass silently).
    void finish() const;

    /// Throws a PresetError at this table's position with `message`.
    [[noreturn]] void fail(std::string_view key, const std::string& message) const;
    const std::string& file() const noexcept { return file_; }
    const std::string& path() const noexcept { return path_; }
    std::vector<ParamInfo>* sink() const noexcept { return sink_; }

  private:
    const toml::node* find(std::string_view key);
    std::string file_;
    const toml::table* table_;
    std::string path_;
    std::vector<ParamInfo>* sink_;
    std::vector<std::string> used_;
};

} // namespace underfoot::engine
