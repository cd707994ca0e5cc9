// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Reading surface presets (TOML) with every parameter declared once: name, unit, documented
/// range and default. A layer reads its parameters through PresetReader, which
///  - rejects a missing file, bad syntax, a wrong type, a non-finite or out-of-range value and
///    an unknown key, with a message naming the file, line:column and what was expected;
///  - records every parameter it read (ParamInfo), so that the sound palette can show units and
///    ranges and the stability suite can sweep each preset's documented ranges.
#include "base/TomlReader.h"

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

/// One key a reader asked for, as the layer declared it: what the generated preset reference
/// (`underfoot surfaces --keys`, docs/reference/presets.md) lists.
struct KeyInfo {
    std::string file;      ///< the preset file
    std::string path;      ///< e.g. "layer[2].stiffness"
    std::string type;      ///< "number", "integer", "string", "table", "tables" or "free"
    std::string unit;      ///< numbers only
    double minValue = 0.0; ///< numbers and integers: documented range
    double maxValue = 0.0;
    std::string defaultText; ///< the default ("" when required or none)
    std::string valueText;   ///< the value in the file ("" when absent)
    std::string allowed;     ///< strings: the allowed values, comma-separated ("" = any)
    std::string help;        ///< one line: what it does
    bool required = false;
};

/// While alive, every PresetReader of this thread also records each key it is asked for into
/// `sink` (loading only; never on the audio thread). Nested catalogs are not supported.
class KeyCatalog {
  public:
    explicit KeyCatalog(std::vector<KeyInfo>& sink);
    ~KeyCatalog();
    KeyCatalog(const KeyCatalog&) = delete;
    KeyCatalog& operator=(const KeyCatalog&) = delete;
};

/// "file:line:column" for a TOML node (or just the file when it has no source position).
using base::sourcePlace;

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
    /// A string; when `allowed` is not empty it must be one of them. `help`: one line for the
    /// preset reference.
    std::string string(std::string_view key, std::string_view defaultValue,
                       const std::vector<std::string>& allowed = {}, std::string_view help = {});
    /// An array of tables (e.g. modes); empty when absent.
    std::vector<PresetReader> tables(std::string_view key, std::string_view help = {});
    /// A sub-table; nullopt when absent.
    std::optional<PresetReader> table(std::string_view key, std::string_view help = {});
    /// Marks a key as known without reading it (read by someone else, or free text).
    void allow(std::string_view key, std::string_view help = {});
    /// Throws for every key that no call above asked for (typos must not pass silently).
    void finish() const;

    /// Throws a PresetError at this table's position with `message`.
    [[noreturn]] void fail(std::string_view key, const std::string& message) const;
    const std::string& file() const noexcept { return file_; }
    const std::string& path() const noexcept { return path_; }
    std::vector<ParamInfo>* sink() const noexcept { return sink_; }

  private:
    const toml::node* find(std::string_view key);
    void record(KeyInfo info) const;
    void recordKey(std::string_view key, const char* type, std::string_view help = {}) const;
    std::string keyPath(std::string_view key) const;
    std::string file_;
    const toml::table* table_;
    std::string path_;
    std::vector<ParamInfo>* sink_;
    std::vector<std::string> used_;
};

} // namespace underfoot::engine
