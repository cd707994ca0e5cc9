// SPDX-License-Identifier: GPL-3.0-or-later
// A stimulus as a TOML table: what each trial stores so that replay needs nothing else.
#include "experiment/Protocol.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <sstream>

namespace underfoot::experiment {

namespace {
toml::table parametersToToml(const Parameters& parameters) {
    toml::table t;
    for (const auto& [name, value] : parameters) {
        if (std::holds_alternative<bool>(value))
            t.insert(name, std::get<bool>(value));
        else if (std::holds_alternative<double>(value))
            t.insert(name, std::get<double>(value));
        else
            t.insert(name, std::get<std::string>(value));
    }
    return t;
}

Parameters parametersFromToml(const toml::table* t) {
    Parameters out;
    if (!t) return out;
    for (auto&& [key, node] : *t) {
        if (node.is_boolean())
            out[std::string(key.str())] = node.as_boolean()->get();
        else if (node.is_floating_point())
            out[std::string(key.str())] = node.as_floating_point()->get();
        else if (node.is_integer())
            out[std::string(key.str())] = static_cast<double>(node.as_integer()->get());
        else if (node.is_string())
            out[std::string(key.str())] = node.as_string()->get();
    }
    return out;
}
} // namespace

std::string stimulusToToml(const Stimulus& s) {
    toml::table t;
    t.insert("id", s.id);
    if (!s.label.empty()) t.insert("label", s.label);
    t.insert("surface", s.surface);
    if (s.soundscape) t.insert("soundscape", *s.soundscape);
    t.insert("modalities", toString(s.modalities));
    if (s.reverb) t.insert("reverb", *s.reverb);
    toml::table input;
    input.insert("type", s.input.kind == InputKind::Walker ? "walker" : "sensor");
    if (s.input.kind == InputKind::Sensor)
        input.insert("sensor", toString(s.input.sensor));
    else
        input.insert("walker", parametersToToml(s.input.walker));
    t.insert("input", std::move(input));
    if (!s.wading.empty()) t.insert("wading", parametersToToml(s.wading));
    if (s.practiceOnly) t.insert("practice_only", true);
    if (s.clip) t.insert("clip", *s.clip);
    if (!s.factors.empty()) {
        toml::table f;
        for (const auto& [k, v] : s.factors) f.insert(k, v);
        t.insert("factors", std::move(f));
    }
    std::ostringstream out;
    out << t;
    return out.str();
}

Stimulus stimulusFromToml(const std::string& text) {
    toml::table t;
    try {
        t = toml::parse(text, std::string_view("stored stimulus"));
    } catch (const toml::parse_error& e) {
        throw std::runtime_error(fmt::format("stored stimulus: {}", e.description()));
    }
    Stimulus s;
    s.id = t["id"].value_or(std::string{});
    s.label = t["label"].value_or(std::string{});
    s.surface = t["surface"].value_or(std::string{});
    if (auto v = t["soundscape"].value<std::string>()) s.soundscape = *v;
    const std::string m = t["modalities"].value_or(std::string("audio"));
    s.modalities = m == "haptic" ? Modalities::Haptic
                   : m == "both" ? Modalities::AudioHaptic
                                 : Modalities::Audio;
    if (auto v = t["reverb"].value<std::string>()) s.reverb = *v;
    const std::string kind = t["input"]["type"].value_or(std::string("sensor"));
    s.input.kind = kind == "walker" ? InputKind::Walker : InputKind::Sensor;
    const std::string sensor = t["input"]["sensor"].value_or(std::string("none"));
    s.input.sensor = sensor == "microphones" ? SensorKind::Microphones
                     : sensor == "fsr"       ? SensorKind::Fsr
                     : sensor == "gyro"      ? SensorKind::Gyro
                                             : SensorKind::None;
    s.input.walker = parametersFromToml(t["input"]["walker"].as_table());
    s.wading = parametersFromToml(t["wading"].as_table());
    s.practiceOnly = t["practice_only"].value_or(false);
    if (auto v = t["clip"].value<std::string>()) s.clip = *v;
    if (const toml::table* f = t["factors"].as_table())
        for (auto&& [k, v] : *f) s.factors[std::string(k.str())] = v.value_or(std::string{});
    if (s.id.empty() || s.surface.empty())
        throw std::runtime_error("stored stimulus: missing id or surface");
    return s;
}

} // namespace underfoot::experiment
