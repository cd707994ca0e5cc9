// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/surfaces/Preset.h"

#include "base/TomlReader.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace underfoot::engine {

namespace {
thread_local std::vector<KeyInfo>* catalog = nullptr;
} // namespace

KeyCatalog::KeyCatalog(std::vector<KeyInfo>& sink) {
    catalog = &sink;
}

KeyCatalog::~KeyCatalog() {
    catalog = nullptr;
}

void PresetReader::record(KeyInfo info) const {
    if (!catalog) return;
    info.file = file_;
    catalog->push_back(std::move(info));
}

void PresetReader::recordKey(std::string_view key, const char* type, std::string_view help) const {
    if (!catalog) return;
    KeyInfo k;
    k.path = keyPath(key);
    k.type = type;
    k.help = std::string(help);
    record(std::move(k));
}

std::string PresetReader::keyPath(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

PresetReader::PresetReader(std::string file, const toml::table& table, std::string path,
                           std::vector<ParamInfo>* sink)
    : file_(std::move(file)), table_(&table), path_(std::move(path)), sink_(sink) {}

const toml::node* PresetReader::find(std::string_view key) {
    used_.emplace_back(key);
    return table_->get(key);
}

void PresetReader::fail(std::string_view key, const std::string& message) const {
    const toml::node* node = key.empty() ? nullptr : table_->get(key);
    const auto& where = node ? node->source() : table_->source();
    const std::string name = path_.empty() ? std::string(key)
                             : key.empty() ? path_
                                           : path_ + "." + std::string(key);
    if (name.empty()) throw PresetError(fmt::format("{}: {}", sourcePlace(file_, where), message));
    throw PresetError(fmt::format("{}: {}: {}", sourcePlace(file_, where), name, message));
}

namespace {
std::string rangeText(double lo, double hi, std::string_view unit) {
    return unit.empty() ? fmt::format("[{:g}, {:g}]", lo, hi)
                        : fmt::format("[{:g}, {:g}] {}", lo, hi, unit);
}
} // namespace

double PresetReader::number(std::string_view key, double defaultValue, double min, double max,
                            std::string_view unit, std::string_view help, bool logScale) {
    const toml::node* node = find(key);
    double value = defaultValue;
    if (node) {
        if (auto v = node->value<double>()) {
            value = *v;
        } else {
            fail(key, "expected a number in " + rangeText(min, max, unit) + ", got " +
                          std::string(base::tomlTypeName(*node)));
        }
        if (!std::isfinite(value))
            fail(key, "expected a finite number in " + rangeText(min, max, unit) + ", got " +
                          fmt::format("{}", value));
        if (value < min || value > max)
            fail(key, fmt::format("expected a number in {}, got {:g}", rangeText(min, max, unit),
                                  value));
    }
    if (sink_)
        sink_->push_back(
            {keyPath(key), std::string(unit), min, max, value, logScale, std::string(help)});
    if (catalog) {
        KeyInfo k;
        k.path = keyPath(key);
        k.type = "number";
        k.unit = std::string(unit);
        k.minValue = min;
        k.maxValue = max;
        k.defaultText = fmt::format("{:g}", defaultValue);
        k.valueText = node ? fmt::format("{:g}", value) : "";
        k.help = std::string(help);
        record(std::move(k));
    }
    return value;
}

double PresetReader::requiredNumber(std::string_view key, double min, double max,
                                    std::string_view unit, std::string_view help, bool logScale) {
    if (!table_->get(key))
        fail("", fmt::format("missing `{}`: expected a number in {} ({})", key,
                             rangeText(min, max, unit), help));
    const double value = number(key, 0.0, min, max, unit, help, logScale);
    if (catalog && !catalog->empty()) {
        catalog->back().required = true;
        catalog->back().defaultText.clear();
    }
    return value;
}

int PresetReader::integer(std::string_view key, int defaultValue, int min, int max,
                          std::string_view help) {
    const toml::node* node = find(key);
    if (catalog) {
        const auto present = node ? node->value_exact<int64_t>() : std::nullopt;
        KeyInfo k;
        k.path = keyPath(key);
        k.type = "integer";
        k.minValue = static_cast<double>(min);
        k.maxValue = static_cast<double>(max);
        k.defaultText = std::to_string(defaultValue);
        k.valueText = present ? std::to_string(*present) : "";
        k.help = std::string(help);
        record(std::move(k));
    }
    if (!node) return defaultValue;
    const auto v = node->value_exact<int64_t>();
    if (!v) fail(key, fmt::format("expected a whole number in [{}, {}] ({})", min, max, help));
    if (*v < min || *v > max)
        fail(key, fmt::format("expected a whole number in [{}, {}], got {}", min, max, *v));
    return static_cast<int>(*v);
}

std::string PresetReader::string(std::string_view key, std::string_view defaultValue,
                                 const std::vector<std::string>& allowed, std::string_view help) {
    const toml::node* node = find(key);
    auto list = [&] {
        std::string s;
        for (const auto& a : allowed) s += (s.empty() ? "" : ", ") + ("\"" + a + "\"");
        return s;
    };
    if (catalog) {
        const auto present = node ? node->value<std::string>() : std::nullopt;
        KeyInfo k;
        k.path = keyPath(key);
        k.type = "string";
        k.defaultText = std::string(defaultValue);
        k.valueText = present.value_or("");
        k.allowed = list();
        k.help = std::string(help);
        record(std::move(k));
    }
    if (!node) return std::string(defaultValue);
    const auto v = node->value<std::string>();
    if (!v) fail(key, allowed.empty() ? "expected a string" : "expected one of " + list());
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), *v) == allowed.end())
        fail(key, fmt::format("expected one of {}, got \"{}\"", list(), *v));
    return *v;
}

std::vector<PresetReader> PresetReader::tables(std::string_view key, std::string_view help) {
    std::vector<PresetReader> out;
    const toml::node* node = find(key);
    recordKey(key, "tables", help);
    if (!node) return out;
    const auto* array = node->as_array();
    if (!array) fail(key, "expected an array of tables ([[...]] or [{...}, ...])");
    std::size_t index = 0;
    for (const auto& element : *array) {
        const auto* t = element.as_table();
        const std::string name =
            fmt::format("{}{}[{}]", path_.empty() ? "" : path_ + ".", key, index + 1);
        if (!t)
            throw PresetError(fmt::format("{}: {}: expected a table",
                                          sourcePlace(file_, element.source()), name));
        out.emplace_back(file_, *t, name, sink_);
        ++index;
    }
    return out;
}

std::optional<PresetReader> PresetReader::table(std::string_view key, std::string_view help) {
    const toml::node* node = find(key);
    recordKey(key, "table", help);
    if (!node) return std::nullopt;
    const auto* t = node->as_table();
    if (!t) fail(key, "expected a table");
    return PresetReader(file_, *t,
                        path_.empty() ? std::string(key) : path_ + "." + std::string(key), sink_);
}

void PresetReader::allow(std::string_view key, std::string_view help) {
    used_.emplace_back(key);
    recordKey(key, "free", help);
}

void PresetReader::finish() const {
    // The shared unknown-key check (base/TomlReader.h): position, known keys, did-you-mean.
    std::vector<std::string> known = used_;
    std::sort(known.begin(), known.end());
    known.erase(std::unique(known.begin(), known.end()), known.end());
    base::rethrowTomlAs<PresetError>([&] {
        base::TomlReader(file_, base::TomlReader::Mode::Throw)
            .checkKeys(*table_, known, path_.empty() ? "the preset" : path_);
    });
}

} // namespace underfoot::engine
