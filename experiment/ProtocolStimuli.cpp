// SPDX-License-Identifier: GPL-3.0-or-later
// Stimuli: [input], [[stimuli]], [[factorial]] and [[groups]] of a protocol file.
#include "experiment/ProtocolReader.h"

namespace underfoot::experiment::protocol_detail {

void ProtocolParse::addStimulus(Stimulus s, const toml::source_region& where) {
    if (s.id.empty()) return;
    if (stimulusPlace.count(s.id)) {
        r.problem(where, fmt::format("stimulus id '{}' is used twice (first at line {})", s.id,
                                     stimulusPlace[s.id].begin.line));
        return;
    }
    stimulusPlace[s.id] = where;
    p.stimuli.push_back(std::move(s));
}

Parameters readParameters(Reader& r, const toml::table& t, std::string_view context) {
    Parameters out;
    for (auto&& [key, node] : t) {
        const std::string name(key.str());
        if (node.is_boolean())
            out[name] = node.as_boolean()->get();
        else if (node.is_string())
            out[name] = node.as_string()->get();
        else if (node.is_integer())
            out[name] = static_cast<double>(node.as_integer()->get());
        else if (node.is_floating_point()) {
            const double v = node.as_floating_point()->get();
            if (!std::isfinite(v))
                r.problem(node, fmt::format("'{}' in {} is not a finite number", name, context));
            else
                out[name] = v;
        } else
            r.problem(node, fmt::format("'{}' in {} must be a number, a string or a boolean", name,
                                        context));
    }
    return out;
}

Input readInput(Reader& r, const toml::table& t, std::string_view context, const Input& fallback) {
    r.checkKeys(t, {"type", "sensor", "walker"}, context);
    Input input = fallback;
    if (auto kind = r.choice<InputKind>(
            t, "type", context, {{"walker", InputKind::Walker}, {"sensor", InputKind::Sensor}}))
        input.kind = *kind;
    else if (!t.get("type"))
        r.problem(
            t, fmt::format("missing key 'type' in {}; expected \"walker\" or \"sensor\"", context));
    if (input.kind == InputKind::Sensor) {
        input.walker.clear();
        if (auto sensor = r.choice<SensorKind>(t, "sensor", context,
                                               {{"microphones", SensorKind::Microphones},
                                                {"fsr", SensorKind::Fsr},
                                                {"gyro", SensorKind::Gyro}}))
            input.sensor = *sensor;
        else if (!t.get("sensor"))
            r.problem(t, fmt::format("missing key 'sensor' in {}; expected \"microphones\", "
                                     "\"fsr\" or \"gyro\"",
                                     context));
        if (t.get("walker"))
            r.problem(*t.get("walker"),
                      fmt::format("'walker' parameters in {} need type = \"walker\"", context));
    } else {
        input.sensor = SensorKind::None;
        if (t.get("sensor"))
            r.problem(*t.get("sensor"),
                      fmt::format("'sensor' in {} needs type = \"sensor\"", context));
        input.walker.clear();
        if (auto w = r.table(t, "walker", context, false))
            input.walker = readParameters(r, *w, std::string(context) + ".walker");
    }
    return input;
}

/// Reads the fields shared by [[stimuli]] and [[factorial]].
void readStimulusFields(Reader& r, const toml::table& t, std::string_view context,
                        const Catalogue& catalogue, const Input& defaultInput, Stimulus& s) {
    if (auto surface = r.string(t, "surface", context, true)) {
        if (!catalogue.surface(*surface))
            r.problem(*t.get("surface"),
                      fmt::format("unknown surface '{}' in {}; expected one of: {}", *surface,
                                  context,
                                  sortedIdsWithSuggestion(*surface, ids(catalogue.surfaces))));
        s.surface = *surface;
    }
    if (auto soundscape = r.string(t, "soundscape", context, false)) {
        if (!catalogue.soundscape(*soundscape))
            r.problem(
                *t.get("soundscape"),
                fmt::format("unknown soundscape '{}' in {}; expected one of: {}", *soundscape,
                            context,
                            sortedIdsWithSuggestion(*soundscape, ids(catalogue.soundscapes))));
        s.soundscape = *soundscape;
    }
    if (auto m = r.choice<Modalities>(t, "modalities", context, kModalityNames)) s.modalities = *m;
    if (auto reverb = r.string(t, "reverb", context, false)) {
        if (reverb->empty())
            r.problem(
                *t.get("reverb"),
                fmt::format("'reverb' in {} is empty; expected an impulse-response name", context));
        s.reverb = *reverb;
    }
    if (auto label = r.string(t, "label", context, false)) s.label = *label;
    s.input = defaultInput;
    if (auto in = r.table(t, "input", context, false))
        s.input = readInput(r, *in, std::string(context) + ".input", defaultInput);
    if (auto wading = r.table(t, "wading", context, false)) {
        s.wading = readParameters(r, *wading, std::string(context) + ".wading");
        if (s.surface != "water")
            r.problem(*t.get("wading"),
                      fmt::format("a 'wading' table in {} needs surface = \"water\" (surface is "
                                  "'{}')",
                                  context, s.surface));
    }
}

std::string levelText(const toml::node& node) {
    if (node.is_string()) return node.as_string()->get();
    if (node.is_integer()) return std::to_string(node.as_integer()->get());
    if (node.is_floating_point()) return fmt::format("{}", node.as_floating_point()->get());
    if (node.is_boolean()) return node.as_boolean()->get() ? "true" : "false";
    return {};
}

void readStimuli(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    const Catalogue& catalogue = x.catalogue;
    auto& defaultInput = x.defaultInput;
    auto& stimulusPlace = x.stimulusPlace;
    // [[stimuli]]
    if (const toml::node* node = root.get("stimuli")) {
        const toml::array* array = node->as_array();
        if (!array || !array->is_array_of_tables())
            r.problem(*node, "'stimuli' must be an array of tables ([[stimuli]])");
        else
            for (const toml::node& element : *array) {
                const toml::table& t = *element.as_table();
                const std::string context =
                    fmt::format("[[stimuli]] #{}", stimulusPlace.size() + 1);
                r.checkKeys(t,
                            {"id", "label", "surface", "soundscape", "modalities", "reverb",
                             "input", "wading", "practice_only", "clip", "factors"},
                            context);
                Stimulus s;
                s.id = r.id(t, "id", context, true).value_or("");
                s.practiceOnly = r.boolean(t, "practice_only", context).value_or(false);
                readStimulusFields(r, t, context, catalogue, defaultInput, s);
                if (auto clip = r.string(t, "clip", context, false)) {
                    const toml::node& where = *t.get("clip");
                    if (clip->empty() || clip->front() == '/' ||
                        clip->find("..") != std::string::npos)
                        r.problem(where, fmt::format("'clip' in {} is '{}'; expected a file name "
                                                     "relative to the clip folder (no '..', not "
                                                     "absolute)",
                                                     context, *clip));
                    else {
                        s.clip = *clip;
                        if (!s.id.empty())
                            p.clipPlaces[s.id] = {static_cast<int>(where.source().begin.line),
                                                  static_cast<int>(where.source().begin.column)};
                    }
                    if (t.get("wading"))
                        r.problem(where, fmt::format("{} has both a lab-supplied 'clip' and "
                                                     "'wading' settings; expected one of them",
                                                     context));
                }
                if (auto f = r.table(t, "factors", context, false)) {
                    for (auto&& [key, levelNode] : *f) {
                        const std::string level = levelText(levelNode);
                        if (level.empty() || levelNode.is_array() || levelNode.is_table())
                            r.problem(levelNode, fmt::format("factor '{}' in {}.factors must be a "
                                                             "string, number or boolean level",
                                                             key.str(), context));
                        else
                            s.factors[std::string(key.str())] = level;
                    }
                }
                x.addStimulus(std::move(s), t.source());
            }
    }
}

void readFactorial(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    const Catalogue& catalogue = x.catalogue;
    auto& defaultInput = x.defaultInput;
    // [[factorial]]: stimuli generated by crossing factor levels.
    if (const toml::node* node = root.get("factorial")) {
        const toml::array* array = node->as_array();
        if (!array || !array->is_array_of_tables())
            r.problem(*node, "'factorial' must be an array of tables ([[factorial]])");
        else
            for (const toml::node& element : *array) {
                const toml::table& t = *element.as_table();
                const std::string context = "[[factorial]]";
                r.checkKeys(t,
                            {"id", "label", "surface", "soundscape", "modalities", "reverb",
                             "input", "wading", "factors", "into"},
                            context);
                Stimulus base;
                const std::string pattern = r.string(t, "id", context, true).value_or("");
                readStimulusFields(r, t, context, catalogue, defaultInput, base);
                const std::string into = r.string(t, "into", context, false).value_or("wading");
                if (into != "wading" && into != "walker")
                    r.problem(*t.get("into"), fmt::format("'into' in {} is '{}'; expected "
                                                          "\"wading\" or \"walker\"",
                                                          context, into));
                const toml::table* factors = r.table(t, "factors", context, true);
                if (!factors || pattern.empty()) continue;
                std::vector<std::pair<std::string, std::vector<const toml::node*>>> levels;
                for (auto&& [key, levelNode] : *factors) {
                    const toml::array* la = levelNode.as_array();
                    if (!la || la->empty()) {
                        r.problem(levelNode, fmt::format("factor '{}' in {} must be a non-empty "
                                                         "array of levels",
                                                         key.str(), context));
                        continue;
                    }
                    std::vector<const toml::node*> values;
                    for (const toml::node& v : *la) {
                        if (levelText(v).empty() || v.is_array() || v.is_table())
                            r.problem(v, fmt::format("levels of factor '{}' must be strings, "
                                                     "numbers or booleans",
                                                     key.str()));
                        else
                            values.push_back(&v);
                    }
                    if (!values.empty()) levels.emplace_back(std::string(key.str()), values);
                    if (pattern.find("{" + std::string(key.str()) + "}") == std::string::npos)
                        r.problem(*t.get("id"),
                                  fmt::format("id pattern '{}' in {} does not contain '{{{}}}'; "
                                              "generated ids would collide",
                                              pattern, context, key.str()));
                }
                if (levels.empty()) {
                    r.problem(*factors, fmt::format("{} declares no factors", context));
                    continue;
                }
                // Cross product, first factor (alphabetical) varying slowest.
                std::size_t total = 1;
                for (const auto& level : levels) total *= level.second.size();
                for (std::size_t k = 0; k < total; ++k) {
                    Stimulus s = base;
                    s.id = pattern;
                    Parameters& target = into == "walker" ? s.input.walker : s.wading;
                    std::size_t rest = k;
                    for (std::size_t f = levels.size(); f-- > 0;) {
                        const auto& values = levels[f].second;
                        const toml::node& v = *values[rest % values.size()];
                        rest /= values.size();
                        const std::string& name = levels[f].first;
                        const std::string level = levelText(v);
                        s.factors[name] = level;
                        const std::string placeholder = "{" + name + "}";
                        for (std::size_t at; (at = s.id.find(placeholder)) != std::string::npos;)
                            s.id.replace(at, placeholder.size(), level);
                        if (v.is_string())
                            target[name] = level;
                        else if (v.is_boolean())
                            target[name] = v.as_boolean()->get();
                        else if (v.is_integer())
                            target[name] = static_cast<double>(v.as_integer()->get());
                        else
                            target[name] = v.as_floating_point()->get();
                    }
                    if (k == 0 && into == "wading" && s.surface != "water" && !s.surface.empty())
                        r.problem(t, fmt::format("{} writes wading factors but surface is '{}'; "
                                                 "expected \"water\"",
                                                 context, s.surface));
                    if (!base::isValidId(s.id))
                        r.problem(*t.get("id"), fmt::format("generated stimulus id '{}' is not a "
                                                            "valid id",
                                                            s.id));
                    else
                        x.addStimulus(std::move(s), t.source());
                }
            }
    }
}

void readGroups(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    // [[groups]]
    const toml::node* groupsNode = root.get("groups");
    if (p.design == DesignKind::Within) {
        if (groupsNode) r.problem(*groupsNode, "[[groups]] are only for design type = \"between\"");
        Group all;
        all.id = "all";
        all.label = "all participants";
        for (const auto& s : p.stimuli)
            if (!s.practiceOnly) all.stimuli.push_back(s.id);
        if (all.stimuli.empty() && !p.stimuli.empty())
            r.problem(root, "every stimulus is practice_only; expected at least one main stimulus");
        p.groups.push_back(std::move(all));
    } else if (!groupsNode) {
        r.problem(root, "design type = \"between\" needs [[groups]]");
    } else if (!groupsNode->is_array_of_tables()) {
        r.problem(*groupsNode, "'groups' must be an array of tables ([[groups]])");
    } else {
        std::set<std::string> groupIds;
        for (const toml::node& element : *groupsNode->as_array()) {
            const toml::table& t = *element.as_table();
            const std::string context = fmt::format("[[groups]] #{}", p.groups.size() + 1);
            r.checkKeys(t, {"id", "label", "stimuli", "target", "modalities"}, context);
            Group g;
            g.id = r.id(t, "id", context, true).value_or("");
            g.label = r.string(t, "label", context, false).value_or(g.id);
            g.target =
                static_cast<int>(r.integer(t, "target", context, false, 0, 100000).value_or(0));
            if (auto m = r.choice<Modalities>(t, "modalities", context, kModalityNames))
                g.modalities = *m;
            if (!g.id.empty() && !groupIds.insert(g.id).second)
                r.problem(t, fmt::format("group id '{}' is used twice", g.id));
            if (!t.get("stimuli")) {
                for (const auto& s : p.stimuli)
                    if (!s.practiceOnly) g.stimuli.push_back(s.id);
            } else {
                for (const auto& [sid, where] : r.strings(t, "stimuli", context)) {
                    if (!p.stimulus(sid))
                        r.problem(where, fmt::format("group '{}' names unknown stimulus '{}'; "
                                                     "expected one of the [[stimuli]] ids",
                                                     g.id, sid));
                    else if (p.stimulus(sid)->practiceOnly)
                        r.problem(where, fmt::format("group '{}' names stimulus '{}', which is "
                                                     "practice_only",
                                                     g.id, sid));
                    else if (std::find(g.stimuli.begin(), g.stimuli.end(), sid) != g.stimuli.end())
                        r.problem(where, fmt::format("group '{}' lists stimulus '{}' twice "
                                                     "(use ordering.repetitions instead)",
                                                     g.id, sid));
                    else
                        g.stimuli.push_back(sid);
                }
                if (g.stimuli.empty())
                    r.problem(
                        *t.get("stimuli"),
                        fmt::format("group '{}' is empty; expected at least one stimulus", g.id));
            }
            p.groups.push_back(std::move(g));
        }
        if (p.groups.empty()) r.problem(*groupsNode, "[[groups]] declares no group");
    }
}

void checkDriverKeys(ProtocolParse& x) {
    // The keys of the engine's virtual walker (engine/control/VirtualWalker.h) and of the wading
    // model (engine/wading/Wading.h), named here so that a typo is reported at its line with a
    // suggestion; their values and ranges are checked by rendering every distinct stimulus
    // (`underfoot protocol check`, `study create`).
    static const std::vector<std::string> kWalkerKeys = {"cadence", "mass", "shoe", "variability"};
    static const std::vector<std::string> kWadingKeys = {
        "algorithm", "cadence", "depth", "filter", "sample_rate_hz", "seed", "stride", "stride_m"};
    std::set<std::string> reported; // a walker of [input] is reported once, at [input]
    for (const auto& s : x.p.stimuli) {
        const auto place = x.stimulusPlace.find(s.id);
        const toml::source_region own =
            place != x.stimulusPlace.end() ? place->second : x.root.source();
        const std::string name = fmt::format("stimulus '{}'", s.id);
        for (const auto& [key, value] : s.wading) {
            // [[factorial]] stimuli share their table: one report per table and key.
            if (std::find(kWadingKeys.begin(), kWadingKeys.end(), key) != kWadingKeys.end() ||
                !reported.insert(fmt::format("wading/{}/{}", own.begin.line, key)).second)
                continue;
            x.r.problem(own, fmt::format("{}: unknown wading key '{}'; expected one of: {}", name,
                                         key, sortedIdsWithSuggestion(key, kWadingKeys)));
        }
        if (s.input.kind != InputKind::Walker || s.surface == "water" || !s.wading.empty())
            continue; // water stimuli walk the virtual gait of their wading settings
        const bool inherited = s.input.walker == x.defaultInput.walker && x.root.get("input");
        const toml::source_region where = inherited ? x.root.get("input")->source() : own;
        const std::string whose = inherited ? std::string("[input]") : name;
        for (const auto& [key, value] : s.input.walker) {
            if (!reported.insert(whose + "/" + key).second) continue;
            if (std::find(kWalkerKeys.begin(), kWalkerKeys.end(), key) == kWalkerKeys.end())
                x.r.problem(where,
                            fmt::format("{}: unknown walker key '{}'; expected one of: {}", whose,
                                        key, sortedIdsWithSuggestion(key, kWalkerKeys)));
            else if (!std::holds_alternative<double>(value))
                x.r.problem(where, fmt::format("{}: walker key '{}' must be a number", whose, key));
        }
    }
}
} // namespace underfoot::experiment::protocol_detail
