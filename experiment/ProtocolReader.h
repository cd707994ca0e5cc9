// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The protocol reader's parts, shared by the files that read one table each (Protocol.cpp,
/// ProtocolStimuli.cpp, ProtocolQuestions.cpp, ProtocolOrdering.cpp, ProtocolSettings.cpp): the
/// collecting TOML reader (base/TomlReader.h) and the state of one parse.
#include "base/TomlReader.h"
#include "experiment/Protocol.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::experiment::protocol_detail {

inline std::string joinIds(const std::vector<CatalogueEntry>& entries) {
    std::string out;
    for (const auto& e : entries) out += (out.empty() ? "" : ", ") + e.id;
    return out;
}

inline std::vector<std::string> ids(const std::vector<CatalogueEntry>& entries) {
    std::vector<std::string> out;
    for (const auto& e : entries) out.push_back(e.id);
    return out;
}

inline std::string joinList(const std::vector<std::string>& values) {
    std::string out;
    for (const auto& v : values) out += (out.empty() ? "" : ", ") + v;
    return out;
}

/// The collecting reader of base/TomlReader.h: every problem with its position.
using Reader = base::TomlReader;

/// Free parameters (a stimulus's walker or wading table): numbers (finite), strings, booleans.
Parameters readParameters(Reader& r, const toml::table& t, std::string_view context);

inline const std::initializer_list<std::pair<std::string_view, Modalities>> kModalityNames = {
    {"audio", Modalities::Audio},
    {"haptic", Modalities::Haptic},
    {"both", Modalities::AudioHaptic},
    {"audio_haptic", Modalities::AudioHaptic}};

/// One parse: the reader, the document, the protocol being filled and what the tables share.
struct ProtocolParse {
    Reader& r;
    const toml::table& root;
    Protocol& p;
    const Catalogue& catalogue;
    /// [input]: the default input of every stimulus.
    Input defaultInput;
    /// Where each stimulus id was declared.
    std::map<std::string, toml::source_region> stimulusPlace;
    /// [ordering] (null when absent).
    const toml::table* orderingTable = nullptr;
    /// Adds a stimulus unless its id is empty or already used (reported).
    void addStimulus(Stimulus s, const toml::source_region& where);
};

Input readInput(Reader& r, const toml::table& t, std::string_view context, const Input& fallback);
std::string levelText(const toml::node& node);

// One function per table, in the order parseProtocol calls them.
void readHeader(ProtocolParse& x);    // [protocol], [design], [timing], [input]
void readStimuli(ProtocolParse& x);   // [[stimuli]]
void readFactorial(ProtocolParse& x); // [[factorial]]
void readGroups(ProtocolParse& x);    // [[groups]]
void readOrdering(ProtocolParse& x);  // [ordering]
void readQuestions(ProtocolParse& x); // [questions]
void readSettings(
    ProtocolParse& x); // [laps], [clips], [[participant_fields]], [rules], [simulation]
void checkDriverKeys(ProtocolParse& x); // the walker and wading keys of every stimulus
/// The plans' feasibility: no-immediate-repeat, breaks (after [questions]: per-scale blocks).
void checkOrdering(Reader& r, const toml::table* orderingTable, const toml::table& root,
                   const Protocol& p);

} // namespace underfoot::experiment::protocol_detail
