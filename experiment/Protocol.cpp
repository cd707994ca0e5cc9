// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Protocol.h"

#include "base/DataDir.h"
#include "experiment/Random.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>

namespace underfoot::experiment {

// ----------------------------------------------------------------------------------------------
// Small helpers

bool Questions::asksSoundscape(const std::string& groupId) const {
    if (soundscapeOptions.empty()) return false;
    if (soundscapeGroups.empty()) return true;
    return std::find(soundscapeGroups.begin(), soundscapeGroups.end(), groupId) !=
           soundscapeGroups.end();
}

namespace {
const AnswerOption* optionByLetter(const std::vector<AnswerOption>& options, char letter) {
    for (const auto& o : options)
        if (o.letter == letter) return &o;
    return nullptr;
}
const AnswerOption* optionById(const std::vector<AnswerOption>& options, const std::string& id) {
    for (const auto& o : options)
        if (o.id == id) return &o;
    return nullptr;
}
} // namespace

const AnswerOption* Questions::surfaceOptionByLetter(char letter) const {
    return optionByLetter(surfaceOptions, letter);
}
const AnswerOption* Questions::surfaceOption(const std::string& optionId) const {
    return optionById(surfaceOptions, optionId);
}
const AnswerOption* Questions::soundscapeOptionByLetter(char letter) const {
    return optionByLetter(soundscapeOptions, letter);
}
const AnswerOption* Questions::soundscapeOption(const std::string& optionId) const {
    return optionById(soundscapeOptions, optionId);
}
const Scale* Questions::scale(const std::string& scaleId) const {
    for (const auto& s : scales)
        if (s.id == scaleId) return &s;
    return nullptr;
}

bool Scale::asksFor(const std::string& stimulusId) const {
    return stimuli.empty() ||
           std::find(stimuli.begin(), stimuli.end(), stimulusId) != stimuli.end();
}

const ParticipantField* Protocol::participantField(const std::string& fieldId) const {
    for (const auto& f : participantFields)
        if (f.id == fieldId) return &f;
    return nullptr;
}

std::vector<const Scale*> askedScales(const Protocol& protocol, const Stimulus& stimulus,
                                      int block) {
    std::vector<const Scale*> out;
    const auto& scales = protocol.questions.scales;
    if (protocol.ordering.blocks == BlockKind::Scale && block >= 1 &&
        block <= static_cast<int>(scales.size())) {
        const Scale& s = scales[static_cast<std::size_t>(block - 1)];
        if (s.asksFor(stimulus.id)) out.push_back(&s);
        return out;
    }
    for (const auto& s : scales)
        if (s.asksFor(stimulus.id)) out.push_back(&s);
    return out;
}

std::string clipPath(const Stimulus& stimulus, const std::string& clipDir) {
    const std::string name = stimulus.clip ? *stimulus.clip : stimulus.id + ".wav";
    if (clipDir.empty()) return name;
    return clipDir.back() == '/' ? clipDir + name : clipDir + "/" + name;
}

std::uint64_t clipSeed(const Protocol& protocol, const Stimulus& stimulus) {
    // FNV-1a of the id: stable across platforms and independent of the order of stimuli.
    std::uint64_t h = 14695981039346656037ULL;
    for (const char c : stimulus.id) {
        h ^= static_cast<unsigned char>(c);
        h *= 1099511628211ULL;
    }
    return deriveSeed(protocol.clips.seed, {h, 0xC11F});
}

std::vector<ProtocolProblem> checkClipFiles(const Protocol& protocol, const std::string& clipDir) {
    std::vector<ProtocolProblem> problems;
    for (const auto& s : protocol.stimuli) {
        if (!s.clip) continue;
        const std::string path = clipPath(s, clipDir);
        std::ifstream in(path, std::ios::binary);
        if (in && in.peek() != std::ifstream::traits_type::eof()) continue;
        const auto place = protocol.clipPlaces.find(s.id);
        const int line = place == protocol.clipPlaces.end() ? 0 : place->second.first;
        const int column = place == protocol.clipPlaces.end() ? 0 : place->second.second;
        problems.push_back(
            {protocol.sourceName, line, column,
             fmt::format("stimulus '{}' plays the lab-supplied clip '{}', but {} {}; expected "
                         "the lab's recording there (an audio file readable by libsndfile)",
                         s.id, *s.clip, path,
                         in ? "is empty" : "does not exist or cannot be read")});
    }
    return problems;
}

const Stimulus* Protocol::stimulus(const std::string& stimulusId) const {
    for (const auto& s : stimuli)
        if (s.id == stimulusId) return &s;
    return nullptr;
}
const Group* Protocol::group(const std::string& groupId) const {
    for (const auto& g : groups)
        if (g.id == groupId) return &g;
    return nullptr;
}

std::string ProtocolProblem::toString() const {
    if (line > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
    return fmt::format("{}: {}", file, message);
}

namespace {
std::string joinProblems(const std::vector<ProtocolProblem>& problems) {
    std::string out;
    for (const auto& p : problems) {
        if (!out.empty()) out += '\n';
        out += p.toString();
    }
    return out;
}
} // namespace

ProtocolError::ProtocolError(std::vector<ProtocolProblem> problems)
    : std::runtime_error(joinProblems(problems)), problems_(std::move(problems)) {}

std::string sha256Hex(const std::string& text) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    if (EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha256(), nullptr) != 1)
        throw std::runtime_error("SHA-256 computation failed (OpenSSL EVP_Digest)");
    std::string hex;
    hex.reserve(length * 2);
    for (unsigned int i = 0; i < length; ++i) hex += fmt::format("{:02x}", digest[i]);
    return hex;
}

const char* toString(Modalities modalities) {
    switch (modalities) {
    case Modalities::Audio:
        return "audio";
    case Modalities::Haptic:
        return "haptic";
    case Modalities::AudioHaptic:
        return "both";
    }
    return "audio";
}

const char* toString(SensorKind sensor) {
    switch (sensor) {
    case SensorKind::None:
        return "none";
    case SensorKind::Microphones:
        return "microphones";
    case SensorKind::Fsr:
        return "fsr";
    case SensorKind::Gyro:
        return "gyro";
    }
    return "none";
}

const char* toString(DesignKind design) {
    return design == DesignKind::Within ? "within" : "between";
}

std::string shippedProtocolDir() {
    return base::dataDirectory(base::DataKind::Protocols);
}

// ----------------------------------------------------------------------------------------------
// The reader: collects every problem with its position.

namespace {

bool validId(std::string_view id) {
    if (id.empty() || id.size() > 64) return false;
    return std::all_of(id.begin(), id.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
               (c >= 'A' && c <= 'Z');
    });
}

std::string joinIds(const std::vector<CatalogueEntry>& entries) {
    std::string out;
    for (const auto& e : entries) out += (out.empty() ? "" : ", ") + e.id;
    return out;
}

std::vector<std::string> ids(const std::vector<CatalogueEntry>& entries) {
    std::vector<std::string> out;
    for (const auto& e : entries) out.push_back(e.id);
    return out;
}

std::string joinList(const std::vector<std::string>& values) {
    std::string out;
    for (const auto& v : values) out += (out.empty() ? "" : ", ") + v;
    return out;
}

class Reader {
  public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    void problem(const toml::source_region& where, std::string message) {
        problems_.push_back({file_, static_cast<int>(where.begin.line),
                             static_cast<int>(where.begin.column), std::move(message)});
    }
    void problem(const toml::node& where, std::string message) {
        problem(where.source(), std::move(message));
    }
    std::vector<ProtocolProblem>& problems() { return problems_; }

    /// Reports keys of `table` not in `allowed` (catches typos instead of ignoring them).
    void checkKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                   std::string_view context) {
        for (auto&& [key, node] : table) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
            std::string expected;
            for (auto a : allowed) expected += (expected.empty() ? "" : ", ") + std::string(a);
            problem(key.source().begin.line ? key.source() : node.source(),
                    fmt::format("unknown key '{}' in {}; expected one of: {}", key.str(), context,
                                expected));
        }
    }

    const toml::table* table(const toml::table& parent, std::string_view key,
                             std::string_view context, bool required) {
        const toml::node* node = parent.get(key);
        if (!node) {
            if (required) problem(parent, fmt::format("missing table [{}] in {}", key, context));
            return nullptr;
        }
        if (!node->is_table()) {
            problem(*node, fmt::format("'{}' in {} must be a table", key, context));
            return nullptr;
        }
        return node->as_table();
    }

    std::optional<std::string> string(const toml::table& t, std::string_view key,
                                      std::string_view context, bool required) {
        const toml::node* node = t.get(key);
        if (!node) {
            if (required)
                problem(t, fmt::format("missing key '{}' in {}; expected a string", key, context));
            return std::nullopt;
        }
        if (!node->is_string()) {
            problem(*node, fmt::format("'{}' in {} must be a string", key, context));
            return std::nullopt;
        }
        return node->as_string()->get();
    }

    std::optional<std::string> id(const toml::table& t, std::string_view key,
                                  std::string_view context, bool required) {
        auto value = string(t, key, context, required);
        if (value && !validId(*value)) {
            problem(*t.get(key),
                    fmt::format("'{}' in {} is '{}'; expected an id of letters, digits, '_' or "
                                "'-' (1 to 64 characters)",
                                key, context, *value));
            return std::nullopt;
        }
        return value;
    }

    std::optional<std::int64_t> integer(const toml::table& t, std::string_view key,
                                        std::string_view context, bool required, std::int64_t min,
                                        std::int64_t max) {
        const toml::node* node = t.get(key);
        if (!node) {
            if (required)
                problem(t,
                        fmt::format("missing key '{}' in {}; expected an integer", key, context));
            return std::nullopt;
        }
        if (!node->is_integer()) {
            problem(*node, fmt::format("'{}' in {} must be an integer", key, context));
            return std::nullopt;
        }
        const std::int64_t v = node->as_integer()->get();
        if (v < min || v > max) {
            problem(*node,
                    fmt::format("'{}' in {} is {}; expected {} to {}", key, context, v, min, max));
            return std::nullopt;
        }
        return v;
    }

    std::optional<double> number(const toml::table& t, std::string_view key,
                                 std::string_view context, double min, double max) {
        const toml::node* node = t.get(key);
        if (!node) return std::nullopt;
        double v = 0.0;
        if (node->is_integer())
            v = static_cast<double>(node->as_integer()->get());
        else if (node->is_floating_point())
            v = node->as_floating_point()->get();
        else {
            problem(*node, fmt::format("'{}' in {} must be a number", key, context));
            return std::nullopt;
        }
        if (!std::isfinite(v) || v < min || v > max) {
            problem(*node, fmt::format("'{}' in {} is {}; expected a finite number from {} to {}",
                                       key, context, v, min, max));
            return std::nullopt;
        }
        return v;
    }

    std::optional<bool> boolean(const toml::table& t, std::string_view key,
                                std::string_view context) {
        const toml::node* node = t.get(key);
        if (!node) return std::nullopt;
        if (!node->is_boolean()) {
            problem(*node, fmt::format("'{}' in {} must be true or false", key, context));
            return std::nullopt;
        }
        return node->as_boolean()->get();
    }

    /// An array of strings with the source of each element.
    std::vector<std::pair<std::string, toml::source_region>>
    strings(const toml::table& t, std::string_view key, std::string_view context) {
        std::vector<std::pair<std::string, toml::source_region>> out;
        const toml::node* node = t.get(key);
        if (!node) return out;
        const toml::array* array = node->as_array();
        if (!array) {
            problem(*node, fmt::format("'{}' in {} must be an array of strings", key, context));
            return out;
        }
        for (const toml::node& element : *array) {
            if (!element.is_string()) {
                problem(element,
                        fmt::format("elements of '{}' in {} must be strings", key, context));
                continue;
            }
            out.emplace_back(element.as_string()->get(), element.source());
        }
        return out;
    }

    /// A `choice` string: one of the given names.
    template <typename E>
    std::optional<E> choice(const toml::table& t, std::string_view key, std::string_view context,
                            std::initializer_list<std::pair<std::string_view, E>> names) {
        auto value = string(t, key, context, false);
        if (!value) return std::nullopt;
        for (const auto& [name, e] : names)
            if (name == *value) return e;
        std::string expected;
        for (const auto& [name, e] : names)
            expected += (expected.empty() ? "" : ", ") + std::string(name);
        problem(*t.get(key), fmt::format("'{}' in {} is '{}'; expected one of: {}", key, context,
                                         *value, expected));
        return std::nullopt;
    }

    /// Free parameters: numbers (finite), strings, booleans.
    Parameters parameters(const toml::table& t, std::string_view context) {
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
                    problem(node, fmt::format("'{}' in {} is not a finite number", name, context));
                else
                    out[name] = v;
            } else
                problem(node, fmt::format("'{}' in {} must be a number, a string or a boolean",
                                          name, context));
        }
        return out;
    }

  private:
    std::string file_;
    std::vector<ProtocolProblem> problems_;
};

const std::initializer_list<std::pair<std::string_view, Modalities>> kModalityNames = {
    {"audio", Modalities::Audio},
    {"haptic", Modalities::Haptic},
    {"both", Modalities::AudioHaptic},
    {"audio_haptic", Modalities::AudioHaptic}};

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
            input.walker = r.parameters(*w, std::string(context) + ".walker");
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
        s.wading = r.parameters(*wading, std::string(context) + ".wading");
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

std::vector<AnswerOption> readOptions(Reader& r, const toml::table& t, std::string_view context,
                                      bool surfaces, const Catalogue& catalogue) {
    std::vector<AnswerOption> options;
    const auto ids = r.strings(t, "options", context);
    if (ids.empty() && t.get("options") && t.get("options")->is_array())
        r.problem(*t.get("options"), fmt::format("'options' in {} is empty", context));
    if (!t.get("options"))
        r.problem(t, fmt::format("missing key 'options' in {}; expected an array of {} ids",
                                 context, surfaces ? "surface" : "soundscape"));
    std::set<std::string> seen;
    for (const auto& [optionId, where] : ids) {
        const CatalogueEntry* entry =
            surfaces ? catalogue.surface(optionId) : catalogue.soundscape(optionId);
        if (!entry && !(optionId == kDontKnow)) {
            r.problem(where,
                      fmt::format("unknown {} '{}' in {}.options; expected one of: {}{}",
                                  surfaces ? "surface" : "soundscape", optionId, context,
                                  joinIds(surfaces ? catalogue.surfaces : catalogue.soundscapes),
                                  ", dont_know"));
            continue;
        }
        if (!seen.insert(optionId).second) {
            r.problem(where, fmt::format("'{}' appears twice in {}.options", optionId, context));
            continue;
        }
        options.push_back({optionId, '?', entry ? entry->label : "I don't know"});
    }
    const bool dontKnow = r.boolean(t, "dont_know", context).value_or(true);
    if (dontKnow && !seen.count(std::string(kDontKnow)))
        options.push_back({std::string(kDontKnow), '?', "I don't know"});
    if (options.size() > 26)
        r.problem(t, fmt::format("{} has {} options; at most 26 fit the keyboard letters a-z",
                                 context, options.size()));
    for (std::size_t i = 0; i < options.size() && i < 26; ++i)
        options[i].letter = static_cast<char>('a' + i);
    // Optional relabelling: labels = { deep_snow = "snow" }.
    if (auto labels = r.table(t, "labels", context, false)) {
        for (auto&& [key, node] : *labels) {
            const std::string_view keyName = key.str(); // clang 14 cannot capture a binding
            auto it = std::find_if(options.begin(), options.end(),
                                   [&](const AnswerOption& o) { return o.id == keyName; });
            if (it == options.end())
                r.problem(node, fmt::format("label for '{}' in {}.labels, which is not an option",
                                            key.str(), context));
            else if (!node.is_string())
                r.problem(node, fmt::format("labels in {}.labels must be strings", context));
            else
                it->label = node.as_string()->get();
        }
    }
    return options;
}

/// Williams design: rows of a Latin square in which every condition follows every other equally
/// often (k rows for even k; k rows and their mirror images for odd k).
std::vector<std::vector<std::size_t>> williamsRows(std::size_t k) {
    std::vector<std::size_t> first;
    for (std::size_t i = 0, lo = 1, hi = k - 1; i < k; ++i) {
        if (i == 0)
            first.push_back(0);
        else if (i % 2 == 1)
            first.push_back(lo++);
        else
            first.push_back(hi--);
    }
    std::vector<std::vector<std::size_t>> rows;
    for (std::size_t r = 0; r < k; ++r) {
        std::vector<std::size_t> row;
        for (std::size_t c : first) row.push_back((c + r) % k);
        rows.push_back(row);
    }
    if (k % 2 == 1)
        for (std::size_t r = 0; r < k; ++r) rows.emplace_back(rows[r].rbegin(), rows[r].rend());
    return rows;
}

/// Replaces the implicit group "all" by one group per Williams row, each in a fixed order.
void applyLatinSquare(Protocol& p) {
    if (p.groups.size() != 1 || p.groups.front().stimuli.size() < 2) return;
    const std::vector<std::string> conditions = p.groups.front().stimuli;
    std::vector<Group> groups;
    const auto rows = williamsRows(conditions.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
        Group g;
        g.id = fmt::format("order{}", r + 1);
        for (std::size_t c : rows[r]) g.stimuli.push_back(conditions[c]);
        g.label = "order " + joinList(g.stimuli);
        groups.push_back(std::move(g));
    }
    p.groups = std::move(groups);
    p.ordering.order = OrderKind::Fixed;
}

/// Number of trials per group for the break check, and the feasibility of no-immediate-repeat.
void checkOrdering(Reader& r, const toml::table* orderingTable, const toml::table& root,
                   const Protocol& p) {
    const toml::source_region where = orderingTable ? orderingTable->source() : root.source();
    const auto& o = p.ordering;
    int largestTrials = 0;
    for (const auto& g : p.groups) {
        const int distinct = static_cast<int>(g.stimuli.size());
        const int blocks = o.blocks == BlockKind::Scale
                               ? std::max(1, static_cast<int>(p.questions.scales.size()))
                               : 1;
        const int trials = distinct * o.repetitions * blocks;
        largestTrials = std::max(largestTrials, trials);
        if (distinct == 0 || !o.noImmediateRepeat) continue;
        const std::string whose = p.design == DesignKind::Between ? fmt::format("group '{}'", g.id)
                                                                  : std::string("the protocol");
        if (o.order == OrderKind::Fixed) {
            // The declared order repeated: a repeat happens inside (duplicate neighbours) or
            // at the seam between repetitions.
            for (std::size_t i = 1; i < g.stimuli.size(); ++i)
                if (g.stimuli[i] == g.stimuli[i - 1])
                    r.problem(where, fmt::format("impossible ordering constraint: {} presents "
                                                 "'{}' twice in a row in its fixed order",
                                                 whose, g.stimuli[i]));
            if (o.repetitions > 1 && g.stimuli.front() == g.stimuli.back())
                r.problem(where,
                          fmt::format("impossible ordering constraint: with order = \"fixed\" "
                                      "and {} repetitions, {} repeats '{}' at the seam between "
                                      "repetitions",
                                      o.repetitions, whose, g.stimuli.front()));
        } else if (distinct < 2 && trials > 1) {
            r.problem(where,
                      fmt::format("impossible ordering constraint: no_immediate_repeat with {} "
                                  "repetitions of a single stimulus in {}; at least two "
                                  "different stimuli are needed",
                                  o.repetitions, whose));
        }
    }
    if (o.breakEvery > 0 && o.breakEvery >= largestTrials)
        r.problem(where, fmt::format("break_every = {} leaves no break: the longest plan has {} "
                                     "trials; expected a number below {}",
                                     o.breakEvery, largestTrials, largestTrials));
}

} // namespace

// ----------------------------------------------------------------------------------------------

Protocol parseProtocol(const std::string& text, const std::string& sourceName,
                       const Catalogue& catalogue) {
    Reader r(sourceName);
    toml::table root;
    try {
        root = toml::parse(std::string_view(text), std::string_view(sourceName));
    } catch (const toml::parse_error& e) {
        r.problem(e.source(), fmt::format("TOML syntax error: {}", e.description()));
        throw ProtocolError(r.problems());
    }

    Protocol p;
    p.sourceText = text;
    p.hash = sha256Hex(text);
    p.sourceName = sourceName;

    r.checkKeys(root,
                {"protocol", "design", "timing", "input", "stimuli", "factorial", "groups",
                 "ordering", "questions", "rules", "laps", "clips", "participant_fields",
                 "simulation"},
                "the protocol file");

    // [protocol]
    if (auto t = r.table(root, "protocol", "the protocol file", true)) {
        r.checkKeys(*t, {"id", "version", "title", "reference", "description"}, "[protocol]");
        p.id = r.id(*t, "id", "[protocol]", true).value_or("");
        p.version =
            static_cast<int>(r.integer(*t, "version", "[protocol]", true, 1, 1000000).value_or(1));
        p.title = r.string(*t, "title", "[protocol]", true).value_or("");
        p.reference = r.string(*t, "reference", "[protocol]", false).value_or("");
        p.description = r.string(*t, "description", "[protocol]", false).value_or("");
    }

    // [design]
    if (auto t = r.table(root, "design", "the protocol file", true)) {
        r.checkKeys(*t, {"type"}, "[design]");
        if (auto d = r.choice<DesignKind>(
                *t, "type", "[design]",
                {{"within", DesignKind::Within}, {"between", DesignKind::Between}}))
            p.design = *d;
        else if (!t->get("type"))
            r.problem(*t, "missing key 'type' in [design]; expected \"within\" or \"between\"");
    }

    // [timing]
    if (auto t = r.table(root, "timing", "the protocol file", false)) {
        r.checkKeys(*t, {"briefing_s", "trial_s", "break_s"}, "[timing]");
        p.timing.briefingS = r.number(*t, "briefing_s", "[timing]", 0, 86400).value_or(120.0);
        p.timing.trialS = r.number(*t, "trial_s", "[timing]", 0, 86400).value_or(45.0);
        p.timing.breakS = r.number(*t, "break_s", "[timing]", 0, 86400).value_or(60.0);
    }

    // [input]: the default input of every stimulus.
    Input defaultInput;
    if (auto t = r.table(root, "input", "the protocol file", false))
        defaultInput = readInput(r, *t, "[input]", Input{});

    // [[stimuli]]
    std::map<std::string, toml::source_region> stimulusPlace;
    auto addStimulus = [&](Stimulus s, const toml::source_region& where) {
        if (s.id.empty()) return;
        if (stimulusPlace.count(s.id)) {
            r.problem(where, fmt::format("stimulus id '{}' is used twice (first at line {})", s.id,
                                         stimulusPlace[s.id].begin.line));
            return;
        }
        stimulusPlace[s.id] = where;
        p.stimuli.push_back(std::move(s));
    };
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
                addStimulus(std::move(s), t.source());
            }
    }

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
                    if (!validId(s.id))
                        r.problem(*t.get("id"), fmt::format("generated stimulus id '{}' is not a "
                                                            "valid id",
                                                            s.id));
                    else
                        addStimulus(std::move(s), t.source());
                }
            }
    }
    if (p.stimuli.empty() && !root.get("stimuli") && !root.get("factorial"))
        r.problem(root, "the protocol declares no stimuli; expected [[stimuli]] or [[factorial]]");

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

    // [ordering]
    const toml::table* orderingTable = r.table(root, "ordering", "the protocol file", false);
    if (orderingTable) {
        const toml::table& t = *orderingTable;
        const char* ctx = "[ordering]";
        r.checkKeys(t,
                    {"repetitions", "order", "blocks", "no_immediate_repeat", "practice",
                     "break_every", "counterbalance"},
                    ctx);
        p.ordering.repetitions =
            static_cast<int>(r.integer(t, "repetitions", ctx, false, 1, 1000).value_or(1));
        if (auto o = r.choice<OrderKind>(
                t, "order", ctx, {{"random", OrderKind::Random}, {"fixed", OrderKind::Fixed}}))
            p.ordering.order = *o;
        if (auto b = r.choice<BlockKind>(t, "blocks", ctx,
                                         {{"none", BlockKind::None},
                                          {"repetition", BlockKind::Repetition},
                                          {"scale", BlockKind::Scale}}))
            p.ordering.blocks = *b;
        if (auto c = r.choice<Counterbalance>(
                t, "counterbalance", ctx,
                {{"none", Counterbalance::None}, {"latin_square", Counterbalance::LatinSquare}})) {
            p.ordering.counterbalance = *c;
            if (*c == Counterbalance::LatinSquare) {
                if (p.design != DesignKind::Within)
                    r.problem(*t.get("counterbalance"),
                              "counterbalance = \"latin_square\" balances the order of "
                              "conditions within subjects; expected design type = \"within\"");
                else if (t.get("order") && p.ordering.order == OrderKind::Random)
                    r.problem(*t.get("order"),
                              "order = \"random\" contradicts counterbalance = "
                              "\"latin_square\" (each Latin-square row is a fixed order); "
                              "remove 'order'");
                else if (t.get("blocks") && p.ordering.blocks == BlockKind::Scale)
                    r.problem(*t.get("blocks"),
                              "blocks = \"scale\" cannot be combined with counterbalance = "
                              "\"latin_square\"");
                else
                    applyLatinSquare(p);
            }
        }
        p.ordering.noImmediateRepeat = r.boolean(t, "no_immediate_repeat", ctx).value_or(false);
        for (const auto& [sid, where] : r.strings(t, "practice", ctx)) {
            if (!p.stimulus(sid))
                r.problem(where, fmt::format("practice names unknown stimulus '{}'; expected one "
                                             "of the [[stimuli]] ids",
                                             sid));
            else
                p.ordering.practice.push_back(sid);
        }
        p.ordering.breakEvery =
            static_cast<int>(r.integer(t, "break_every", ctx, false, 0, 100000).value_or(0));
    }
    // [questions]
    if (auto t = r.table(root, "questions", "the protocol file", true)) {
        r.checkKeys(*t, {"surface", "scales", "soundscape", "comment"}, "[questions]");
        p.questions.comment = r.boolean(*t, "comment", "[questions]").value_or(false);
        if (auto s = r.table(*t, "surface", "[questions]", false)) {
            r.checkKeys(*s, {"prompt", "options", "dont_know", "labels"}, "[questions.surface]");
            p.questions.surfacePrompt = r.string(*s, "prompt", "[questions.surface]", false)
                                            .value_or("Which surface are you walking on?");
            p.questions.surfaceOptions = readOptions(r, *s, "[questions.surface]", true, catalogue);
            // Every stimulus must be answerable correctly.
            for (const auto& st : p.stimuli) {
                if (st.surface.empty() || !catalogue.surface(st.surface)) continue;
                bool answerable = false;
                for (const auto& o : p.questions.surfaceOptions)
                    answerable = answerable || answerIsCorrect(o.id, st.surface);
                if (!answerable)
                    r.problem(*s, fmt::format("no answer option names the surface of stimulus "
                                              "'{}' ('{}'); expected '{}' in "
                                              "[questions.surface].options",
                                              st.id, st.surface, baseSurface(st.surface)));
            }
        }
        if (const toml::node* scalesNode = t->get("scales")) {
            if (!scalesNode->is_array_of_tables())
                r.problem(*scalesNode,
                          "'scales' must be an array of tables ([[questions.scales]])");
            else
                for (const toml::node& element : *scalesNode->as_array()) {
                    const toml::table& st = *element.as_table();
                    const std::string ctx =
                        fmt::format("[[questions.scales]] #{}", p.questions.scales.size() + 1);
                    r.checkKeys(st,
                                {"id", "prompt", "min", "max", "min_label", "max_label", "anchors",
                                 "stimuli"},
                                ctx);
                    Scale sc;
                    sc.id = r.id(st, "id", ctx, true).value_or("");
                    sc.prompt = r.string(st, "prompt", ctx, true).value_or("");
                    sc.min =
                        static_cast<int>(r.integer(st, "min", ctx, true, -1000, 1000).value_or(1));
                    sc.max =
                        static_cast<int>(r.integer(st, "max", ctx, true, -1000, 1000).value_or(7));
                    sc.minLabel = r.string(st, "min_label", ctx, false).value_or("");
                    sc.maxLabel = r.string(st, "max_label", ctx, false).value_or("");
                    if (sc.min >= sc.max)
                        r.problem(st, fmt::format("scale '{}' has min {} >= max {}; expected "
                                                  "min < max",
                                                  sc.id, sc.min, sc.max));
                    if (auto anchors = r.table(st, "anchors", ctx, false)) {
                        for (auto&& [key, node] : *anchors) {
                            const std::string k(key.str());
                            int value = 0;
                            std::size_t used = 0;
                            bool isNumber = !k.empty();
                            try {
                                value = std::stoi(k, &used);
                            } catch (const std::exception&) {
                                isNumber = false;
                            }
                            const auto& where =
                                key.source().begin.line ? key.source() : node.source();
                            if (!isNumber || used != k.size())
                                r.problem(where, fmt::format("anchor '{}' of scale '{}' is not a "
                                                             "whole number; expected a scale "
                                                             "point such as {} = \"...\"",
                                                             k, sc.id, sc.min));
                            else if (value < sc.min || value > sc.max)
                                r.problem(where, fmt::format("anchor {} of scale '{}' is outside "
                                                             "its range; expected {} to {}",
                                                             value, sc.id, sc.min, sc.max));
                            else if (!node.is_string() || node.as_string()->get().empty())
                                r.problem(node, fmt::format("anchor {} of scale '{}' must be a "
                                                            "non-empty string",
                                                            value, sc.id));
                            else
                                sc.anchors[value] = node.as_string()->get();
                        }
                        if (sc.minLabel.empty() && sc.anchors.count(sc.min))
                            sc.minLabel = sc.anchors[sc.min];
                        if (sc.maxLabel.empty() && sc.anchors.count(sc.max))
                            sc.maxLabel = sc.anchors[sc.max];
                    }
                    if (!sc.minLabel.empty()) sc.anchors.try_emplace(sc.min, sc.minLabel);
                    if (!sc.maxLabel.empty()) sc.anchors.try_emplace(sc.max, sc.maxLabel);
                    for (const auto& [sid, where] : r.strings(st, "stimuli", ctx)) {
                        const Stimulus* target = p.stimulus(sid);
                        if (!target)
                            r.problem(where, fmt::format("scale '{}' names unknown stimulus "
                                                         "'{}'; expected one of the stimulus ids",
                                                         sc.id, sid));
                        else if (std::find(sc.stimuli.begin(), sc.stimuli.end(), sid) !=
                                 sc.stimuli.end())
                            r.problem(where, fmt::format("scale '{}' lists stimulus '{}' twice",
                                                         sc.id, sid));
                        else
                            sc.stimuli.push_back(sid);
                    }
                    if (st.get("stimuli") && sc.stimuli.empty() && st.get("stimuli")->is_array())
                        r.problem(*st.get("stimuli"),
                                  fmt::format("scale '{}' has an empty 'stimuli' list; expected "
                                              "stimulus ids, or no list for every stimulus",
                                              sc.id));
                    if (!sc.id.empty() && p.questions.scale(sc.id))
                        r.problem(st, fmt::format("scale id '{}' is used twice", sc.id));
                    else
                        p.questions.scales.push_back(sc);
                }
        }
        if (auto s = r.table(*t, "soundscape", "[questions]", false)) {
            r.checkKeys(*s, {"prompt", "options", "dont_know", "labels", "groups"},
                        "[questions.soundscape]");
            p.questions.soundscapePrompt = r.string(*s, "prompt", "[questions.soundscape]", false)
                                               .value_or("Which environment are you in?");
            p.questions.soundscapeOptions =
                readOptions(r, *s, "[questions.soundscape]", false, catalogue);
            for (const auto& [gid, where] : r.strings(*s, "groups", "[questions.soundscape]")) {
                if (!p.group(gid))
                    r.problem(where, fmt::format("[questions.soundscape] names unknown group "
                                                 "'{}'; expected one of: {}",
                                                 gid, [&] {
                                                     std::vector<std::string> ids;
                                                     for (const auto& g : p.groups)
                                                         ids.push_back(g.id);
                                                     return joinList(ids);
                                                 }()));
                else
                    p.questions.soundscapeGroups.push_back(gid);
            }
        }
        if (!p.questions.asksSurface() && p.questions.scales.empty() &&
            p.questions.soundscapeOptions.empty())
            r.problem(*t, "[questions] asks nothing; expected a surface question, scales or a "
                          "soundscape question");
    }

    if (p.ordering.blocks == BlockKind::Scale && p.questions.scales.empty())
        r.problem(orderingTable ? orderingTable->source() : root.source(),
                  "blocks = \"scale\" needs [[questions.scales]]; expected at least one scale");
    if (p.ordering.blocks == BlockKind::Scale && p.questions.asksSurface())
        r.problem(orderingTable ? orderingTable->source() : root.source(),
                  "blocks = \"scale\" asks one scale per block; the surface question would be "
                  "asked in every block — remove [questions.surface] or the scale blocks");
    checkOrdering(r, orderingTable, root, p);

    // [laps]
    if (auto t = r.table(root, "laps", "the protocol file", false)) {
        r.checkKeys(*t, {"baseline", "feedback"}, "[laps]");
        p.laps.baseline =
            static_cast<int>(r.integer(*t, "baseline", "[laps]", false, 0, 100).value_or(0));
        p.laps.feedback =
            static_cast<int>(r.integer(*t, "feedback", "[laps]", true, 1, 100).value_or(1));
    }

    // [clips]
    if (auto t = r.table(root, "clips", "the protocol file", false)) {
        r.checkKeys(*t, {"seconds", "seed", "replay"}, "[clips]");
        p.clips.enabled = true;
        p.clips.seconds = r.number(*t, "seconds", "[clips]", 0.5, 600).value_or(10.0);
        p.clips.seed = static_cast<std::uint64_t>(
            r.integer(*t, "seed", "[clips]", false, 0, std::numeric_limits<std::int64_t>::max())
                .value_or(1));
        p.clips.replay = r.boolean(*t, "replay", "[clips]").value_or(true);
        if (p.laps.total() > 0)
            r.problem(*t, "[clips] (a listening test) and [laps] (an interactive test) exclude "
                          "each other; expected one of them");
    }
    // A lab-supplied clip makes the protocol a listening test even without a [clips] table.
    for (const auto& s : p.stimuli)
        if (s.clip) p.clips.enabled = true;
    if (p.clips.enabled && p.laps.total() > 0 && !root.get("clips"))
        r.problem(*root.get("laps"), "[laps] (an interactive test) cannot be combined with "
                                     "lab-supplied clips (a listening test)");

    // [[participant_fields]]
    if (const toml::node* node = root.get("participant_fields")) {
        if (!node->is_array_of_tables())
            r.problem(*node, "'participant_fields' must be an array of tables "
                             "([[participant_fields]])");
        else
            for (const toml::node& element : *node->as_array()) {
                const toml::table& t = *element.as_table();
                const std::string ctx =
                    fmt::format("[[participant_fields]] #{}", p.participantFields.size() + 1);
                r.checkKeys(t, {"id", "label", "options", "required"}, ctx);
                ParticipantField f;
                f.id = r.id(t, "id", ctx, true).value_or("");
                f.label = r.string(t, "label", ctx, false).value_or(f.id);
                f.required = r.boolean(t, "required", ctx).value_or(true);
                std::set<std::string> seen;
                for (const auto& [option, where] : r.strings(t, "options", ctx)) {
                    if (option.empty() || !seen.insert(option).second)
                        r.problem(where, fmt::format("option '{}' of {} is empty or listed twice",
                                                     option, ctx));
                    else
                        f.options.push_back(option);
                }
                if (t.get("options") && f.options.empty() && t.get("options")->is_array())
                    r.problem(*t.get("options"),
                              fmt::format("'options' of {} is empty; expected the allowed "
                                          "answers, or no 'options' for free text",
                                          ctx));
                static const std::set<std::string> kBuiltIn = {"code",  "age",     "gender",
                                                               "shoes", "hearing", "group"};
                if (kBuiltIn.count(f.id))
                    r.problem(t, fmt::format("participant field '{}' is built in; expected "
                                             "another id",
                                             f.id));
                else if (!f.id.empty() && p.participantField(f.id))
                    r.problem(t, fmt::format("participant field '{}' is declared twice", f.id));
                else if (!f.id.empty())
                    p.participantFields.push_back(std::move(f));
            }
    }

    // [rules]
    if (auto t = r.table(root, "rules", "the protocol file", false)) {
        r.checkKeys(*t, {"lock"}, "[rules]");
        if (auto l = r.choice<LockRule>(
                *t, "lock", "[rules]",
                {{"next_trial", LockRule::NextTrialStart}, {"answer", LockRule::OnAnswer}}))
            p.lock = *l;
    }

    // [simulation]: the published data synthetic participants answer from (issue #17).
    if (auto t = r.table(root, "simulation", "the protocol file", false)) {
        r.checkKeys(*t, {"confusion", "rating_model"}, "[simulation]");
        auto relativePath = [&](const toml::node& node, const std::string& value) {
            if (value.empty() || value.front() == '/' || value.find("..") != std::string::npos)
                r.problem(node, fmt::format("'{}' in [simulation]: expected a path relative to "
                                            "the protocol's folder, without '..'",
                                            value));
        };
        if (const toml::node* c = t->get("confusion")) {
            if (c->is_string()) {
                p.simulation.confusion[""] = c->as_string()->get();
                relativePath(*c, c->as_string()->get());
            } else if (c->is_table()) {
                for (auto&& [key, node] : *c->as_table()) {
                    const std::string group(key.str());
                    if (!p.group(group))
                        r.problem(node, fmt::format("[simulation] confusion names group '{}', "
                                                    "which is not a group of the protocol",
                                                    group));
                    if (!node.is_string()) {
                        r.problem(node, fmt::format("confusion.{} in [simulation] must be a "
                                                    "string (a CSV file)",
                                                    group));
                        continue;
                    }
                    p.simulation.confusion[group] = node.as_string()->get();
                    relativePath(node, node.as_string()->get());
                }
            } else {
                r.problem(*c, "'confusion' in [simulation] must be a file name or a table of "
                              "group = file");
            }
        }
        if (auto m = r.string(*t, "rating_model", "[simulation]", false)) {
            relativePath(*t->get("rating_model"), *m);
            p.simulation.ratingModel = *m;
        }
    }

    if (!r.problems().empty()) {
        auto problems = r.problems();
        std::stable_sort(problems.begin(), problems.end(),
                         [](const ProtocolProblem& a, const ProtocolProblem& b) {
                             return std::tie(a.line, a.column) < std::tie(b.line, b.column);
                         });
        throw ProtocolError(std::move(problems));
    }
    return p;
}

Protocol loadProtocol(const std::string& path, const Catalogue& catalogue) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw ProtocolError({{path, 0, 0,
                              "cannot open the file; expected a readable TOML "
                              "protocol"}});
    std::ostringstream text;
    text << in.rdbuf();
    return parseProtocol(text.str(), path, catalogue);
}

// ----------------------------------------------------------------------------------------------
// Stimulus <-> TOML (stored with each trial)

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
