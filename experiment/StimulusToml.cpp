// SPDX-License-Identifier: GPL-3.0-or-later
// A stimulus as a TOML table: what each trial stores so that replay needs nothing else.
#include "experiment/Protocol.h"
#include "experiment/ProtocolReader.h"

#include "base/TomlReader.h"

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
    // Written by stimulusToToml(); read back with the protocol's checks, stopping at the first
    // problem (a stored row is not edited by hand).
    static constexpr std::string_view kSource = "stored stimulus";
    const toml::table t = base::parseToml(text, kSource);
    protocol_detail::Reader r{std::string(kSource), base::TomlReader::Mode::Throw};
    r.checkKeys(t,
                {"id", "label", "surface", "soundscape", "modalities", "reverb", "input", "wading",
                 "practice_only", "clip", "factors"},
                kSource);
    Stimulus s;
    s.id = r.string(t, "id", kSource, true).value_or("");
    s.label = r.string(t, "label", kSource, false).value_or("");
    s.surface = r.string(t, "surface", kSource, true).value_or("");
    s.soundscape = r.string(t, "soundscape", kSource, false);
    s.modalities = r.choice(t, "modalities", kSource, protocol_detail::kModalityNames)
                       .value_or(Modalities::Audio);
    s.reverb = r.string(t, "reverb", kSource, false);
    if (const toml::table* input = r.table(t, "input", kSource, false)) {
        r.checkKeys(*input, {"type", "sensor", "walker"}, "[input]");
        s.input.kind =
            r.choice<InputKind>(*input, "type", "[input]",
                                {{"sensor", InputKind::Sensor}, {"walker", InputKind::Walker}})
                .value_or(InputKind::Sensor);
        s.input.sensor = r.choice<SensorKind>(*input, "sensor", "[input]",
                                              {{"none", SensorKind::None},
                                               {"microphones", SensorKind::Microphones},
                                               {"fsr", SensorKind::Fsr},
                                               {"gyro", SensorKind::Gyro}})
                             .value_or(SensorKind::None);
        if (const toml::table* w = r.table(*input, "walker", "[input]", false))
            s.input.walker = protocol_detail::readParameters(r, *w, "[input.walker]");
    }
    if (const toml::table* w = r.table(t, "wading", kSource, false))
        s.wading = protocol_detail::readParameters(r, *w, "[wading]");
    s.practiceOnly = r.boolean(t, "practice_only", kSource).value_or(false);
    s.clip = r.string(t, "clip", kSource, false);
    if (const toml::table* f = r.table(t, "factors", kSource, false))
        for (auto&& [k, v] : *f)
            s.factors[std::string(k.str())] = r.string(*f, k.str(), "[factors]", true).value_or("");
    if (s.id.empty() || s.surface.empty())
        throw base::TomlError({{std::string(kSource), 0, 0, "empty id or surface"}});
    return s;
}

} // namespace underfoot::experiment
