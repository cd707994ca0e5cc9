// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Protocol.h"
#include "experiment/ProtocolReader.h"

#include "base/DataDir.h"
#include "base/TomlReader.h"
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

// ----------------------------------------------------------------------------------------------

Protocol parseProtocol(const std::string& text, const std::string& sourceName,
                       const Catalogue& catalogue) {
    using namespace protocol_detail;
    Reader r(sourceName);
    toml::table root;
    try {
        root = base::parseToml(text, sourceName);
    } catch (const base::TomlError& e) {
        throw ProtocolError(e.problems());
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

    ProtocolParse x{r, root, p, catalogue, Input{}, {}, nullptr};
    readHeader(x);
    readStimuli(x);
    readFactorial(x);
    if (p.stimuli.empty() && !root.get("stimuli") && !root.get("factorial"))
        r.problem(root, "the protocol declares no stimuli; expected [[stimuli]] or [[factorial]]");
    readGroups(x);
    readOrdering(x);
    readQuestions(x);
    readSettings(x);
    checkDriverKeys(x);

    if (!r.problems().empty()) throw ProtocolError(r.sortedProblems()); // root causes first
    return p;
}

Protocol loadProtocol(const std::string& path, const Catalogue& catalogue) {
    std::string text;
    try {
        text = base::readTomlFile(path, "a readable TOML protocol");
    } catch (const base::TomlError& e) {
        throw ProtocolError(e.problems());
    }
    return parseProtocol(text, path, catalogue);
}

// ----------------------------------------------------------------------------------------------
// Stimulus <-> TOML (stored with each trial)

} // namespace underfoot::experiment
