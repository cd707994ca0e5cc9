// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Fit.h"
#include "base/TomlReader.h"
#include "base/Version.h"

#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"

#include <boost/random/sobol.hpp>
#include <fmt/core.h>
#include <nlopt.hpp>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace underfoot::realism {
namespace fs = std::filesystem;

namespace {

using Ranges = std::map<std::string, std::pair<double, double>>;

struct Knob {
    FitKnob info;
    std::function<void(toml::table& root, double k, const Ranges& ranges)> apply;
};

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

bool hasLayer(const toml::table& root, const std::string& type, int* count = nullptr) {
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
    auto mul2 = [](double k2) { return [k2](double v, int) { return v * std::exp2(k2); }; };
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
             [mul2](toml::table& r, double x, const Ranges& rg) {
                 eachLayerKey(r, "grains", "freq_min_hz", rg, mul2(x));
                 eachLayerKey(r, "grains", "freq_max_hz", rg, mul2(x));
             }});
        k.push_back({{"grain_q", "grain resonance Q (q_min/max) x 2^k", -2, 2, 0, 0},
                     [mul2](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "grains", "q_min", rg, mul2(x));
                         eachLayerKey(r, "grains", "q_max", rg, mul2(x));
                     }});
        k.push_back({{"grain_rate", "event rates (events_per_*) x 2^k", -2, 1, 0, 0},
                     [mul2](toml::table& r, double x, const Ranges& rg) {
                         for (const char* key :
                              {"events_per_kn_rise", "events_per_kn_fall", "events_per_s_per_kn"})
                             eachLayerKey(r, "grains", key, rg, mul2(x));
                     }});
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
                         [mul2](toml::table& r, double x, const Ranges& rg) {
                             eachLayerKey(r, "grains", "heel_rate_hz", rg, mul2(x));
                         }});
            k.push_back({{"heel_time", "heel burst's time to peak (heel_ms) x 2^k", -2, 2, 0, 0},
                         [mul2](toml::table& r, double x, const Ranges& rg) {
                             eachLayerKey(r, "grains", "heel_ms", rg, mul2(x));
                         }});
            k.push_back({{"heel_decay", "heel burst's decay (heel_decay_ms) x 2^k", -2, 2, 0, 0},
                         [mul2](toml::table& r, double x, const Ranges& rg) {
                             eachLayerKey(r, "grains", "heel_decay_ms", rg, mul2(x));
                         }});
            k.push_back(
                {{"heel_energy", "heel burst's energy scale (heel_energy) x 2^k", -3, 3, 0, 0},
                 [mul2](toml::table& r, double x, const Ranges& rg) {
                     eachLayerKey(r, "grains", "heel_energy", rg, mul2(x));
                 }});
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
                     [mul2](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "bubbles", "radius_min_mm", rg, mul2(x));
                         eachLayerKey(r, "bubbles", "radius_max_mm", rg, mul2(x));
                     }});
        k.push_back({{"splash_band", "splash noise centre (splash_hz) x 2^k", -1, 2.5, 0, 0},
                     [mul2](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "bubbles", "splash_hz", rg, mul2(x));
                     }});
        k.push_back({{"splash_level", "splash_noise_db + k", -12, 12, 0, 0},
                     [](toml::table& r, double x, const Ranges& rg) {
                         eachLayerKey(r, "bubbles", "splash_noise_db", rg,
                                      [x](double v, int) { return v + x; });
                     }});
        k.push_back(
            {{"splash_length", "splash length (splash_ms, splash_decay_ms) x 2^k", -2, 2, 0, 0},
             [mul2](toml::table& r, double x, const Ranges& rg) {
                 eachLayerKey(r, "bubbles", "splash_ms", rg, mul2(x));
                 eachLayerKey(r, "bubbles", "splash_decay_ms", rg, mul2(x));
             }});
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

double peakOf(const engine::AudioBuffer& a) {
    double p = 0;
    for (float v : a.samples) p = std::max(p, std::fabs(double(v)));
    return p;
}

struct ModeRow {
    double f = 0, t60 = 0, mass = 1, gain = 1;
};

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

} // namespace

std::vector<std::vector<double>> fitStartPoints(int count, const std::vector<double>& lo,
                                                const std::vector<double>& hi) {
    if (count < 1) throw std::invalid_argument(fmt::format("fit: {} starts: expected >= 1", count));
    if (lo.size() != hi.size() || lo.empty())
        throw std::invalid_argument("fit: starting points need one [lo, hi] per knob");
    for (std::size_t i = 0; i < lo.size(); ++i)
        if (!(lo[i] <= 0 && 0 <= hi[i]))
            throw std::invalid_argument(
                fmt::format("fit: knob {}'s box [{}, {}] does not hold 0", i, lo[i], hi[i]));
    std::vector<std::vector<double>> points{std::vector<double>(lo.size(), 0.0)};
    if (count == 1) return points;
    boost::random::sobol sobol(lo.size()); // the first point is the box's centre
    const double range = static_cast<double>(sobol.max()) - static_cast<double>(sobol.min()) + 1;
    for (int p = 1; p < count; ++p) {
        std::vector<double> x(lo.size());
        for (std::size_t i = 0; i < lo.size(); ++i)
            x[i] = lo[i] + (hi[i] - lo[i]) * (static_cast<double>(sobol() - sobol.min()) / range);
        points.push_back(std::move(x));
    }
    return points;
}

double contrastiveObjective(double own, double nearest, double contrast, double margin) {
    if (contrast <= 0 || nearest < 0) return own;
    return own + contrast * std::max(0.0, own - nearest + margin);
}

std::string modalSeededPreset(const std::string& presetFile,
                              const std::vector<RecordedMode>& modes) {
    toml::table root = parsePreset(presetFile);
    if (!hasLayer(root, "impact"))
        throw std::invalid_argument(fmt::format("{}: no impact layer to seed", presetFile));
    if (modes.empty()) throw std::invalid_argument("modal seed: no recorded mode");
    seedImpactModes(root, modes, ModalSeedOptions{}.clusterOctaves);
    return toText(root);
}

FitResult fitSurface(const std::string& presetFile, const std::vector<Recording>& real,
                     const FitOptions& options) {
    const auto t0 = std::chrono::steady_clock::now();
    toml::table root = parsePreset(presetFile);
    if (root.get("base"))
        throw std::invalid_argument(fmt::format(
            "{}: a `base` preset; fit its base preset instead (it inherits the fit)", presetFile));
    Ranges ranges;
    const auto original = engine::Surface::load(presetFile); // keeps parameters() alive
    for (const auto& p : original->parameters()) ranges[p.path] = {p.minValue, p.maxValue};
    auto knobs = knobsFor(root);
    for (const auto& name : options.keep) {
        const auto it = std::find_if(knobs.begin(), knobs.end(),
                                     [&](const Knob& k) { return k.info.name == name; });
        if (it == knobs.end()) {
            std::string names;
            for (const auto& k : knobs) names += (names.empty() ? "" : ", ") + k.info.name;
            throw std::invalid_argument(fmt::format(
                "{}: no knob \"{}\" to keep (this preset's knobs: {})", presetFile, name, names));
        }
        knobs.erase(it);
    }
    if (knobs.empty())
        throw std::invalid_argument(
            options.keep.empty()
                ? fmt::format("{}: no impact, grains or bubbles layer to fit", presetFile)
                : fmt::format("{}: every knob is kept: nothing to fit", presetFile));

    // The render seeds of the objective (FitOptions::seeds): spec.seed alone by default.
    std::vector<std::uint64_t> seeds = options.seeds;
    if (seeds.empty()) seeds.push_back(options.spec.seed);
    if (seeds.size() > 32)
        throw std::invalid_argument(fmt::format(
            "{} render seeds: at most 32 (each evaluation renders once per seed)", seeds.size()));

    // A preset with a room ([reverb]) is fitted against the recordings heard through that room,
    // as `underfoot compare` compares it (describeRecordings, realism/Compare.h).
    const auto room = roomOfSurface(presetFile);
    AnalysisOptions ao;
    ao.maxHz = sharedMaxHz(real, options.spec.rateHz);
    const auto realSteps = describeRecordings(real, ao, room);
    if (realSteps.empty()) throw std::runtime_error("no footstep found in the recordings");

    const auto id = fs::path(presetFile).stem().string();
    // One folder per fit: fits of the same preset may run at once (fitsWithoutEachSource).
    static std::atomic<long> fitCount{0};
    const fs::path tmp = fs::temp_directory_path() / fmt::format("underfoot-fit-{}-{}-{}",
                                                                 static_cast<long>(::getpid()),
                                                                 fitCount.fetch_add(1), id);
    fs::create_directories(tmp);
    const auto tmpFile = (tmp / (id + ".toml")).string();

    auto build = [&](const std::vector<double>& x) {
        toml::table t = root;
        for (std::size_t i = 0; i < knobs.size(); ++i) knobs[i].apply(t, x[i], ranges);
        return t;
    };
    auto write = [&](const toml::table& t) { std::ofstream(tmpFile) << toText(t); };
    auto renderWritten = [&](std::uint64_t seed) { // the preset last written, with this seed
        RenderSpec spec = options.spec;
        spec.seed = seed;
        return renderForComparison(tmpFile, spec);
    };
    // The loudness calibration's render: the first seed's (spec.seed when no seeds are given).
    auto render = [&](const toml::table& t) {
        write(t);
        return renderWritten(seeds.front());
    };
    // Other materials (contrast): each compared on the band its recordings share with the
    // render, as `underfoot compare --all` does.
    struct Target {
        std::string material;
        AnalysisOptions ao;
        std::vector<StepDescriptors> steps;
    };
    std::vector<Target> others;
    if (options.contrast > 0) {
        std::map<std::string, std::vector<Recording>> byMaterial;
        for (const auto& r : options.others)
            if (!r.material.empty() && r.material != options.ownMaterial)
                byMaterial[r.material].push_back(r);
        for (const auto& [material, recs] : byMaterial) {
            Target t{material, {}, {}};
            t.ao.maxHz = sharedMaxHz(recs, options.spec.rateHz);
            t.steps = describeRecordings(recs, t.ao, room);
            if (!t.steps.empty()) others.push_back(std::move(t));
        }
    }
    // Distances of the written preset's render with one seed (the single-seed evaluation).
    auto evaluateSeed = [&](std::uint64_t seed) {
        FitDistances d;
        bool failed = false;
        try {
            const auto audio = renderWritten(seed);
            std::map<double, std::vector<StepDescriptors>> described; // by band limit
            auto stepsAt = [&](const AnalysisOptions& o) -> const std::vector<StepDescriptors>& {
                auto it = described.find(o.maxHz);
                if (it == described.end())
                    it = described.emplace(o.maxHz, describeSteps(audio, o)).first;
                return it->second;
            };
            const auto& own = stepsAt(ao);
            if (own.empty()) throw std::invalid_argument("the render holds no footstep");
            d.own = compareSteps(own, realSteps).distance;
            d.nearest = -1;
            for (const auto& o : others) {
                const double x = compareSteps(stepsAt(o.ao), o.steps).distance;
                if (d.nearest < 0 || x < d.nearest) {
                    d.nearest = x;
                    d.nearestMaterial = o.material;
                }
            }
        } catch (const engine::PresetError&) { // a knob combination the preset's ranges refuse
            failed = true;
        } catch (const std::invalid_argument&) { // a render without a footstep
            failed = true;
        }
        if (failed) {
            d.own = 100.0;
            d.nearest = others.empty() ? -1 : 0.0;
            d.nearestMaterial = others.empty() ? "" : "(none)";
        }
        d.objective = contrastiveObjective(d.own, d.nearest, options.contrast, options.margin);
        if (d.nearest < 0) d.nearest = 0;
        return d;
    };
    auto evaluate = [&](const toml::table& t) {
        write(t);
        if (seeds.size() == 1) return evaluateSeed(seeds.front());
        FitDistances mean;
        double thinnest = -1e300; // own - nearest of the seed with the thinnest margin
        for (const auto seed : seeds) {
            const FitDistances d = evaluateSeed(seed);
            mean.own += d.own;
            mean.nearest += d.nearest;
            mean.objective += d.objective;
            if (d.own - d.nearest > thinnest) {
                thinnest = d.own - d.nearest;
                mean.nearestMaterial = d.nearestMaterial;
            }
        }
        const double n = static_cast<double>(seeds.size());
        mean.own /= n;
        mean.nearest /= n;
        mean.objective /= n;
        return mean;
    };
    auto distanceOf = [&](const toml::table& t) { return evaluate(t).objective; };

    FitResult result;
    result.optimiser = "NLopt LN_BOBYQA";
    std::vector<double> x(knobs.size(), 0.0), lo, hi;
    for (const auto& k : knobs) {
        lo.push_back(k.info.lo);
        hi.push_back(k.info.hi);
    }
    result.before = evaluate(root);
    result.distanceBefore = result.before.own;
    result.contrastive = !others.empty();
    const toml::table originalTable = root; // loudness reference
    // Starting points: the preset itself, or (modal seed) the recordings' modes estimated on
    // the signal and on its first difference; each is refined, the better result is kept.
    struct Start {
        toml::table table;
        std::string name;
        std::vector<RecordedMode> modes;
        std::vector<std::string> skipped;
    };
    std::vector<Start> starts;
    // The preset itself is always a start: a seed whose refinement ends farther than the preset's
    // own modes would otherwise make the fit worse than no fit.
    starts.push_back({root, "the preset's own parameters", {}, {}});
    const bool seedTried = options.modalSeed && hasLayer(root, "impact");
    if (seedTried) {
        for (bool emphasis : {false, true}) {
            auto so = options.seed;
            so.maxModes = impactModeCount(root);
            so.preEmphasis = emphasis;
            Start s{
                root, emphasis ? "recorded modes (first difference)" : "recorded modes", {}, {}};
            s.modes = recordedModes(real, so, &s.skipped);
            seedImpactModes(s.table, s.modes, so.clusterOctaves);
            starts.push_back(std::move(s));
        }
    }
    const auto points = fitStartPoints(options.starts, lo, hi);
    result.startPoints = static_cast<int>(points.size());
    const int runs = static_cast<int>(starts.size() * points.size());
    int evals = 0;
    double best = 0, overall = 1e300;
    std::vector<double> bestX = x, overallX = x;
    std::size_t overallStart = 0, overallPoint = 0;
    std::vector<double> tableD0(starts.size(), 0.0); // objective of each starting preset
    struct Ctx {
        std::function<double(const std::vector<double>&)> f;
    } ctx{[&](const std::vector<double>& xv) {
        const double d = distanceOf(build(xv));
        ++evals;
        if (d < best) {
            best = d;
            bestX = xv;
        }
        if (options.progress &&
            !options.progress(evals, options.maxEvaluations * runs, d, std::min(best, overall)))
            throw nlopt::forced_stop();
        return d;
    }};
    bool stopped = false;
    for (std::size_t run = 0; run < starts.size() * points.size() && !stopped; ++run) {
        const std::size_t si = run / points.size(), pi = run % points.size();
        root = starts[si].table; // `build` applies the knobs to `root`
        double d0 = 1e300;
        if (pi == 0) { // the starting preset itself
            d0 = starts[si].modes.empty() ? result.before.objective : distanceOf(root);
            best = d0;
            tableD0[si] = d0;
        } else {
            best = 1e300; // BOBYQA evaluates its starting point first
        }
        x = points[pi];
        bestX = x;
        nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(knobs.size()));
        opt.set_lower_bounds(lo);
        opt.set_upper_bounds(hi);
        std::vector<double> step;
        for (std::size_t i = 0; i < knobs.size(); ++i) step.push_back(0.25 * (hi[i] - lo[i]));
        opt.set_initial_step(step);
        opt.set_maxeval(options.maxEvaluations);
        opt.set_xtol_abs(1e-3);
        opt.set_min_objective([](const std::vector<double>& xv, std::vector<double>&,
                                 void* data) { return static_cast<Ctx*>(data)->f(xv); },
                              &ctx);
        double fmin = 0;
        try {
            opt.optimize(x, fmin);
        } catch (const nlopt::forced_stop&) {
            stopped = true;
        } catch (const nlopt::roundoff_limited&) {
        }
        result.startObjectives.push_back(best);
        if (best < overall) {
            overall = best;
            overallX = bestX;
            overallStart = si;
            overallPoint = pi;
            result.distanceSeeded = tableD0[si];
        }
    }
    result.bestStartPoint = static_cast<int>(overallPoint);
    root = starts[overallStart].table;
    bestX = overallX;
    result.seedTried = seedTried;
    result.seedStart = starts[overallStart].name;
    if (seedTried && overallStart > 0) {
        result.modalSeeded = true;
        result.seededModes = starts[overallStart].modes;
        result.seedSkipped = starts[overallStart].skipped;
    }
    // Keep the original's loudness: the render's peak equals the original's.
    toml::table fitted = build(bestX);
    const double peakBefore = peakOf(render(originalTable));
    const double peakAfter = peakOf(render(fitted));
    if (peakBefore > 0 && peakAfter > 0) {
        const double g = originalTable["gain_db"].value<double>().value_or(0.0) +
                         20.0 * std::log10(peakBefore / peakAfter);
        fitted.insert_or_assign("gain_db", std::round(g * 10.0) / 10.0);
    }
    result.after = evaluate(fitted);
    result.distanceAfter = result.after.own;
    fs::remove_all(tmp);
    result.evaluations = evals;
    for (std::size_t i = 0; i < knobs.size(); ++i) {
        knobs[i].info.value = bestX[i];
        result.knobs.push_back(knobs[i].info);
    }

    toml::table prov;
    toml::array files, licences, sources;
    for (const auto& r : real) {
        files.push_back(r.file);
        if (std::find_if(licences.begin(), licences.end(), [&](const toml::node& n) {
                return n.value<std::string>() == r.licence;
            }) == licences.end())
            licences.push_back(r.licence);
        if (std::find_if(sources.begin(), sources.end(), [&](const toml::node& n) {
                return n.value<std::string>() == r.package;
            }) == sources.end())
            sources.push_back(r.package);
    }
    prov.insert("tool", fmt::format("underfoot fit {}", underfoot::base::version()));
    prov.insert("optimiser", result.optimiser);
    prov.insert("recordings", files);
    prov.insert("sources", sources);
    prov.insert("licences", licences);
    prov.insert("distance_before", std::round(result.distanceBefore * 1000) / 1000);
    prov.insert("distance_after", std::round(result.distanceAfter * 1000) / 1000);
    prov.insert("walker", options.spec.walker);
    prov.insert("seconds", options.spec.seconds);
    if (seeds.size() == 1) {
        prov.insert("seed", static_cast<std::int64_t>(seeds.front()));
    } else {
        toml::array seedList; // the objective is the mean over these renders (see Fit.h)
        for (const auto seed : seeds) seedList.push_back(static_cast<std::int64_t>(seed));
        prov.insert("seeds", seedList);
    }
    prov.insert("evaluations", evals);
    toml::table kt;
    for (const auto& k : result.knobs) kt.insert(k.name, std::round(k.value * 1000) / 1000);
    prov.insert("knobs", kt);
    if (options.starts > 1) {
        toml::table st;
        st.insert("points", static_cast<std::int64_t>(points.size()));
        st.insert("method", "the preset's own knobs and the first points - 1 points of the Sobol "
                            "sequence (Boost.Random sobol) scaled into the knobs' box, each "
                            "refined by BOBYQA");
        st.insert("evaluations_per_start", options.maxEvaluations);
        st.insert("best", static_cast<std::int64_t>(overallPoint));
        toml::array reached;
        for (double o : result.startObjectives) reached.push_back(std::round(o * 1000) / 1000);
        st.insert("objectives", reached);
        prov.insert("starts", st);
    }
    if (!options.keep.empty()) {
        toml::array kept;
        for (const auto& k : options.keep) kept.push_back(k);
        prov.insert("knobs_kept", kept);
    }
    if (result.contrastive) {
        toml::table ct;
        ct.insert("objective", "d_own + contrast x max(0, d_own - nearest other + margin)");
        ct.insert("contrast", options.contrast);
        ct.insert("margin", options.margin);
        toml::array materials;
        for (const auto& o : others) materials.push_back(o.material);
        ct.insert("other_materials", materials);
        ct.insert("nearest_other_before", result.before.nearestMaterial);
        ct.insert("nearest_other_distance_before", std::round(result.before.nearest * 1000) / 1000);
        ct.insert("nearest_other_after", result.after.nearestMaterial);
        ct.insert("nearest_other_distance_after", std::round(result.after.nearest * 1000) / 1000);
        prov.insert("contrast", ct);
    }
    if (seedTried) {
        toml::table seed;
        seed.insert("method", "matrix pencil on the strongest steps, clustered across files "
                              "and sources (realism/ModalSeed.h)");
        seed.insert("start", result.seedStart);
        seed.insert("modes", static_cast<std::int64_t>(result.seededModes.size()));
        seed.insert("modes_per_step", options.seed.modesPerStep);
        seed.insert("steps_per_file", options.seed.stepsPerFile);
        seed.insert("starts_tried", static_cast<std::int64_t>(starts.size()));
        if (result.modalSeeded)
            seed.insert("distance", std::round(result.distanceSeeded * 1000) / 1000);
        prov.insert("modal_seed", seed);
    }
    fitted.insert_or_assign("provenance", prov);
    result.presetText = toText(fitted);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

} // namespace underfoot::realism
