// SPDX-License-Identifier: GPL-3.0-or-later
// What `underfoot fit` does to a surface preset's TOML (realism/FitPreset.h).
#include "realism/FitPreset.h"

#include "base/TomlReader.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace underfoot::realism::fitpreset {

namespace {

double clampTo(const Ranges& r, const std::string& path, double v) {
    auto it = r.find(path);
    if (it == r.end()) return v;
    return std::clamp(v, it->second.first, it->second.second);
}

// Applies f(old value) -> new value to `key` of every layer of type `type` (when present).
void eachLayerKey(toml::table& root, const std::string& type, const std::string& key,
                  const Ranges& ranges, const std::function<double(double, int)>& f) {
    auto* layers = root["layer"].as_array();
    if (!layers) return;
    int i = 0, ofType = 0;
    for (auto& node : *layers) {
        auto* t = node.as_table();
        if (t && t->get("type") && t->get("type")->value<std::string>() == type) {
            if (auto v = (*t)[key].value<double>())
                t->insert_or_assign(
                    key, clampTo(ranges, fmt::format("layer[{}].{}", i, key), f(*v, ofType)));
            ++ofType;
        }
        ++i;
    }
}

// Calls f(layer, index) for every grains layer that `which` accepts.
void eachGrainsLayer(toml::table& root, const std::function<bool(const toml::table&)>& which,
                     const std::function<void(toml::table&, int)>& f) {
    auto* layers = root["layer"].as_array();
    if (!layers) return;
    int i = 0;
    for (auto& node : *layers) {
        auto* t = node.as_table();
        if (t && t->get("type") && t->get("type")->value<std::string>() == "grains" && which(*t))
            f(*t, i);
        ++i;
    }
}

// Calls f(layer, index) for every grains layer with ongoing events (not onset-only: some
// events_per_* > 0).
void eachGrainEventLayer(toml::table& root, const std::function<void(toml::table&, int)>& f) {
    eachGrainsLayer(
        root,
        [](const toml::table& t) {
            double rate = 0;
            for (const char* key :
                 {"events_per_kn_rise", "events_per_kn_fall", "events_per_s_per_kn"})
                rate += t[key].value<double>().value_or(0.0);
            return rate > 0;
        },
        f);
}

// Calls f(layer, index) for every grains layer of noise bursts (excitation = "noise").
void eachNoiseLayer(toml::table& root, const std::function<void(toml::table&, int)>& f) {
    eachGrainsLayer(
        root, [](const toml::table& t) { return t["excitation"].value<std::string>() == "noise"; },
        f);
}

// A grains layer that only makes the heel's onset event (onset_energy > 0, no event rates).
bool isThudLayer(const toml::table& t) {
    if (!t.get("type") || t.get("type")->value<std::string>() != "grains") return false;
    double rate = 0;
    for (const char* key : {"events_per_kn_rise", "events_per_kn_fall", "events_per_s_per_kn"})
        rate += t[key].value<double>().value_or(0.0);
    return rate <= 0 && t["onset_energy"].value<double>().value_or(0.0) > 0;
}

void eachMode(toml::table& root, const Ranges& ranges,
              const std::function<void(toml::table& mode, const std::string& path)>& f) {
    auto* layers = root["layer"].as_array();
    if (!layers) return;
    int i = 0;
    for (auto& node : *layers) {
        auto* t = node.as_table();
        if (t && t->get("type") && t->get("type")->value<std::string>() == "impact")
            if (auto* modes = (*t)["modes"].as_array()) {
                int j = 0;
                for (auto& m : *modes)
                    if (auto* mt = m.as_table()) f(*mt, fmt::format("layer[{}].modes[{}]", i, j++));
            }
        ++i;
    }
    (void)ranges;
}

// A knob's rewrite that multiplies these keys of every layer of that type by 2^k.
std::function<void(toml::table&, double, const Ranges&)> octaves(std::string type,
                                                                 std::vector<std::string> keys) {
    return [type = std::move(type), keys = std::move(keys)](toml::table& r, double x,
                                                            const Ranges& rg) {
        for (const auto& key : keys)
            eachLayerKey(r, type, key, rg, [x](double v, int) { return v * std::exp2(x); });
    };
}

struct ModeRow {
    double f = 0, t60 = 0, mass = 1, gain = 1;
};

} // namespace

bool hasLayer(const toml::table& root, const std::string& type, int* count) {
    int n = 0;
    if (const auto* layers = root["layer"].as_array())
        for (const auto& node : *layers)
            if (const auto* t = node.as_table())
                if (t->get("type") && t->get("type")->value<std::string>() == type) ++n;
    if (count) *count = n;
    return n > 0;
}

std::vector<Knob> knobsFor(const toml::table& root) {
    std::vector<Knob> k;
    if (hasLayer(root, "impact")) {
        k.push_back({{"decay", "every mode's t60_s x 2^k", -4.5, 2, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachMode(r, rg, [&](toml::table& m, const std::string& p) {
                             if (auto v = m["t60_s"].value<double>())
                                 m.insert_or_assign("t60_s",
                                                    clampTo(rg, p + ".t60_s", *v * std::exp2(x)));
                         });
                     }});
        k.push_back({{"stiffness", "contact stiffness x 10^k", -1, 1, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "impact", "stiffness", rg,
                                      [x](double v, int) { return v * std::pow(10.0, x); });
                     }});
        k.push_back({{"tilt", "mode gains x (f / 1 kHz)^k", -1.5, 1.5, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachMode(r, rg, [&](toml::table& m, const std::string& p) {
                             auto g = m["gain"].value<double>();
                             auto f = m["freq_hz"].value<double>();
                             if (g && f)
                                 m.insert_or_assign("gain", clampTo(rg, p + ".gain",
                                                                    *g * std::pow(*f / 1000.0, x)));
                         });
                     }});
    }
    int grainLayers = 0;
    if (hasLayer(root, "grains", &grainLayers)) {
        k.push_back(
            {{"grain_band", "grain resonance band (freq_min/max_hz) x 2^k", -1.5, 1.5, 0, 0},
             octaves("grains", {"freq_min_hz", "freq_max_hz"})});
        k.push_back({{"grain_q", "grain resonance Q (q_min/max) x 2^k", -2, 2, 0, 0},
                     octaves("grains", {"q_min", "q_max"})});
        k.push_back({{"grain_rate", "event rates (events_per_*) x 2^k", -2, 1, 0, 0},
                     octaves("grains",
                             {"events_per_kn_rise", "events_per_kn_fall", "events_per_s_per_kn"})});
        // The heel's thud: the level of the onset-only layers (one event when the heel loads).
        bool thud = false;
        if (const auto* layers = root["layer"].as_array())
            for (const auto& node : *layers)
                if (const auto* t = node.as_table()) thud = thud || isThudLayer(*t);
        if (thud)
            k.push_back(
                {{"thud", "heel thud: gain_db of the onset-only layers + k", -18, 18, 0, 0},
                 [](toml::table& r, double x, const Ranges& rg) {
                     auto* layers = r["layer"].as_array();
                     int i = 0;
                     for (auto& node : *layers) {
                         auto* t = node.as_table();
                         if (t && isThudLayer(*t))
                             if (auto v = (*t)["gain_db"].value<double>())
                                 t->insert_or_assign(
                                     "gain_db",
                                     clampTo(rg, fmt::format("layer[{}].gain_db", i), *v + x));
                         ++i;
                     }
                 }});
        // Crunch cascades: burst_events (default 0) + k on every layer of ongoing events (not
        // the onset-only ones), then their delays burst_ms (default 2 ms) x 2^k.
        k.push_back({{"burst", "crunch cascades: burst_events + k (at least 0)", -2, 4, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachGrainEventLayer(r, [&](toml::table& t, int i) {
                             const double v = t["burst_events"].value<double>().value_or(0.0);
                             const double nv = clampTo(rg, fmt::format("layer[{}].burst_events", i),
                                                       std::max(0.0, v + x));
                             if (nv != v) t.insert_or_assign("burst_events", nv);
                         });
                     }});
        k.push_back({{"burst_length", "length of the cascades: burst_ms x 2^k", -2, 3, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachGrainEventLayer(r, [&](toml::table& t, int i) {
                             if (t["burst_events"].value<double>().value_or(0.0) <= 0 || x == 0)
                                 return;
                             const double v = t["burst_ms"].value<double>().value_or(2.0);
                             t.insert_or_assign("burst_ms",
                                                clampTo(rg, fmt::format("layer[{}].burst_ms", i),
                                                        v * std::exp2(x)));
                         });
                     }});
        // Heel burst (GranularLayers.h): only where a layer has one (heel_rate_hz > 0).
        bool heel = false;
        if (const auto* layers = root["layer"].as_array())
            for (const auto& node : *layers)
                if (const auto* t = node.as_table())
                    heel = heel || (*t)["heel_rate_hz"].value<double>().value_or(0.0) > 0;
        if (heel) {
            k.push_back({{"heel_rate", "heel burst's peak rate (heel_rate_hz) x 2^k", -3, 2, 0, 0},
                         octaves("grains", {"heel_rate_hz"})});
            k.push_back({{"heel_time", "heel burst's time to peak (heel_ms) x 2^k", -2, 2, 0, 0},
                         octaves("grains", {"heel_ms"})});
            k.push_back({{"heel_decay", "heel burst's decay (heel_decay_ms) x 2^k", -2, 2, 0, 0},
                         octaves("grains", {"heel_decay_ms"})});
            k.push_back(
                {{"heel_energy", "heel burst's energy scale (heel_energy) x 2^k", -3, 3, 0, 0},
                 octaves("grains", {"heel_energy"})});
        }
        // Noise-burst grains (excitation = "noise", GranularLayers.h): their decay and colour.
        bool noiseLayers = false;
        if (const auto* layers = root["layer"].as_array())
            for (const auto& node : *layers)
                if (const auto* t = node.as_table())
                    noiseLayers = noiseLayers || (*t)["excitation"].value<std::string>() == "noise";
        if (noiseLayers) {
            k.push_back({{"noise_decay", "noise bursts' decay (noise_decay_ms) x 2^k", -2, 2, 0, 0},
                         [](toml::table& r, double x, const Ranges& rg) {
                             eachNoiseLayer(r, [&](toml::table& t, int i) {
                                 if (auto v = t["noise_decay_ms"].value<double>())
                                     t.insert_or_assign(
                                         "noise_decay_ms",
                                         clampTo(rg, fmt::format("layer[{}].noise_decay_ms", i),
                                                 *v * std::exp2(x)));
                             });
                         }});
            k.push_back(
                {{"noise_band",
                  "noise bursts' colour: noise_corner_hz and the tone filters (highpass_hz, "
                  "lowpass_hz) x 2^k",
                  -2, 2, 0, 0},
                 [](toml::table& r, double x, const Ranges& rg) {
                     eachNoiseLayer(r, [&](toml::table& t, int i) {
                         for (const char* key : {"noise_corner_hz", "highpass_hz", "lowpass_hz"})
                             if (auto v = t[key].value<double>(); v && *v > 0)
                                 t.insert_or_assign(key,
                                                    clampTo(rg, fmt::format("layer[{}].{}", i, key),
                                                            *v * std::exp2(x)));
                     });
                 }});
            // The bursts' build-up (0: they start at once, like a tap; up to 0.9 of the decay:
            // grains rubbing and giving way). An offset, since the preset's own ratio may be 0.
            k.push_back(
                {{"noise_attack", "noise bursts' build-up: noise_attack_ratio + k", -0.6, 0.6, 0,
                  0},
                 [](toml::table& r, double x, const Ranges& rg) {
                     eachNoiseLayer(r, [&](toml::table& t, int i) {
                         const double v = t["noise_attack_ratio"].value<double>().value_or(0);
                         t.insert_or_assign(
                             "noise_attack_ratio",
                             clampTo(rg, fmt::format("layer[{}].noise_attack_ratio", i), v + x));
                     });
                 }});
        }
        if (grainLayers > 1)
            k.push_back(
                {{"layer_balance", "first grain layer +k dB, the others -k dB", -12, 12, 0, 0},
                 [](toml::table& r, double x, const Ranges& rg) {
                     eachLayerKey(r, "grains", "gain_db", rg,
                                  [x](double v, int i) { return i == 0 ? v + x : v - x; });
                 }});
    }
    if (hasLayer(root, "bubbles")) {
        k.push_back({{"bubble_size", "bubble radii (radius_min/max_mm) x 2^k", -2, 1, 0, 0},
                     octaves("bubbles", {"radius_min_mm", "radius_max_mm"})});
        k.push_back({{"splash_band", "splash noise centre (splash_hz) x 2^k", -1, 2.5, 0, 0},
                     octaves("bubbles", {"splash_hz"})});
        k.push_back({{"splash_level", "splash_noise_db + k", -12, 12, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "bubbles", "splash_noise_db", rg,
                                      [x](double v, int) { return v + x; });
                     }});
        k.push_back(
            {{"splash_length", "splash length (splash_ms, splash_decay_ms) x 2^k", -2, 2, 0, 0},
             octaves("bubbles", {"splash_ms", "splash_decay_ms"})});
        k.push_back({{"slosh_level", "slosh_db + k", -20, 6, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "bubbles", "slosh_db", rg,
                                      [x](double v, int) { return v + x; });
                     }});
    }
    return k;
}

// TOML text with every long decimal (7 or more digits after the point, as toml++ writes a
// computed double) written with 6 significant digits (readable presets).
std::string toText(const toml::table& t) {
    std::ostringstream s;
    s << t << "\n";
    const std::string text = s.str();
    const std::size_t n = text.size();
    const auto digit = [&](std::size_t i) {
        return i < n && std::isdigit(static_cast<unsigned char>(text[i])) != 0;
    };
    std::string out;
    std::size_t last = 0, i = 0;
    while (i < n) {
        std::size_t j = i + (text[i] == '-' ? 1 : 0);
        const std::size_t intStart = j;
        while (digit(j)) ++j;
        if (j == intStart) { // not a number here
            ++i;
            continue;
        }
        if (j < n && text[j] == '.') {
            const std::size_t fracStart = ++j;
            while (digit(j)) ++j;
            if (j - fracStart >= 7) {
                if (j < n && text[j] == 'e') { // exponent, when it has digits
                    std::size_t e = j + 1;
                    if (e < n && (text[e] == '-' || text[e] == '+')) ++e;
                    const std::size_t expStart = e;
                    while (digit(e)) ++e;
                    if (e > expStart) j = e;
                }
                std::string v = fmt::format("{:.6g}", std::stod(text.substr(i, j - i)));
                if (v.find_first_of(".e") == std::string::npos) v += ".0";
                out += text.substr(last, i - last) + v;
                last = j;
            }
        }
        i = j;
    }
    return out + text.substr(last);
}

int impactModeCount(const toml::table& root) {
    int n = 0;
    if (const auto* layers = root["layer"].as_array())
        for (const auto& node : *layers)
            if (const auto* t = node.as_table())
                if (t->get("type") && t->get("type")->value<std::string>() == "impact")
                    if (const auto* modes = (*t)["modes"].as_array())
                        n = std::max(n, int(modes->size()));
    return n;
}

// Replaces every impact layer's modes by the recorded ones (Fit.h, "Modal seed").
void seedImpactModes(toml::table& root, const std::vector<RecordedMode>& recorded,
                     double clusterOctaves) {
    auto* layers = root["layer"].as_array();
    if (!layers) return;
    for (auto& node : *layers) {
        auto* t = node.as_table();
        if (!t || !t->get("type") || t->get("type")->value<std::string>() != "impact") continue;
        auto* modes = (*t)["modes"].as_array();
        if (!modes || modes->empty()) continue;
        std::vector<ModeRow> orig;
        for (auto& m : *modes)
            if (auto* mt = m.as_table())
                orig.push_back({(*mt)["freq_hz"].value<double>().value_or(0),
                                (*mt)["t60_s"].value<double>().value_or(0),
                                (*mt)["mass_kg"].value<double>().value_or(1.0),
                                (*mt)["gain"].value<double>().value_or(1.0)});
        if (orig.empty()) continue;
        const std::size_t n = orig.size();
        // The strongest recorded modes, at most as many as the layer had, by frequency.
        std::vector<RecordedMode> rec = recorded;
        std::stable_sort(rec.begin(), rec.end(), [](const RecordedMode& a, const RecordedMode& b) {
            return a.gain > b.gain;
        });
        if (rec.size() > n) rec.resize(n);
        std::sort(rec.begin(), rec.end(), [](const RecordedMode& a, const RecordedMode& b) {
            return a.frequencyHz < b.frequencyHz;
        });
        double mobility = 0; // sum of g^2 / m of the original modes
        for (const auto& o : orig) mobility += o.gain * o.gain / o.mass;
        double recSum = 0;
        for (const auto& r : rec) recSum += r.gain;
        const double topHz = rec.empty() ? 0 : rec.back().frequencyHz;
        std::vector<ModeRow> fill;
        for (const auto& o : orig)
            if (rec.size() + fill.size() < n && o.f > topHz * std::exp2(clusterOctaves))
                fill.push_back(o);
        double fillMobility = 0;
        for (const auto& o : fill) fillMobility += o.gain * o.gain / o.mass;
        const double scale =
            recSum > 0 ? std::max(mobility - fillMobility, 0.5 * mobility) / recSum : 0;
        toml::array out;
        auto row = [](double f, double g, double m, double t60) {
            toml::table mt;
            mt.insert("freq_hz", std::round(f * 10) / 10);
            mt.insert("gain", g);
            mt.insert("mass_kg", m);
            mt.insert("t60_s", t60);
            mt.is_inline(true); // one line per mode, as hand-written presets have them
            return mt;
        };
        for (const auto& r : rec) {
            const ModeRow* near = &orig.front();
            for (const auto& o : orig)
                if (std::fabs(std::log2(o.f / r.frequencyHz)) <
                    std::fabs(std::log2(near->f / r.frequencyHz)))
                    near = &o;
            const double mob = r.gain * scale; // g^2 / m of this mode
            double mass = near->mass, g = std::sqrt(mob * mass);
            if (g > 10.0) {
                g = 10.0;
                mass = 100.0 / mob;
            }
            out.push_back(row(r.frequencyHz, g, mass, std::clamp(r.t60S, 0.001, 30.0)));
        }
        for (const auto& o : fill) out.push_back(row(o.f, o.gain, o.mass, o.t60));
        t->insert_or_assign("modes", out);
    }
}

toml::table parsePreset(const std::string& presetFile) {
    return base::rethrowTomlAs<std::invalid_argument>(
        [&] { return base::parseTomlFile(presetFile, "a surface preset (TOML)"); });
}

} // namespace underfoot::realism::fitpreset
