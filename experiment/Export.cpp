// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Export.h"

#include "base/CsvCell.h"

#include <fmt/format.h>

#include <set>

namespace underfoot::experiment {

std::string csvField(std::string_view value) {
    return base::csvCell(value);
}

namespace {
std::string ratingCell(const TrialRecord& t, const char* scale) {
    const auto it = t.answer.ratings.find(scale);
    return it == t.answer.ratings.end() ? std::string() : std::to_string(it->second);
}

void writeRow(std::ostream& out, const std::vector<std::string>& cells) {
    for (std::size_t i = 0; i < cells.size(); ++i) {
        if (i) out << ',';
        out << csvField(cells[i]);
    }
    out << "\r\n";
}
} // namespace

int writeTrialsCsv(const StudyStore& store, std::ostream& out, ExportScope scope,
                   SimulatedRows simulated) {
    const StudyInfo info = store.info();
    const Protocol& protocol = store.protocol();
    const Questions& q = protocol.questions;
    std::vector<std::string> header(kTrialColumns.begin(), kTrialColumns.end());
    writeRow(out, header);
    int rows = 0;
    for (const auto& p : store.participants()) {
        if (p.simulated && simulated == SimulatedRows::Exclude) continue;
        const std::string group = protocol.design == DesignKind::Between ? p.groupId : "";
        for (const auto& t : store.trials(p.code)) {
            if (scope == ExportScope::Answered && !t.answered) continue;
            const AnswerOption* option =
                t.answer.answer.empty() ? nullptr : q.surfaceOption(t.answer.answer);
            std::string correct;
            if (t.answered && q.asksSurface())
                correct = answerIsCorrect(t.answer.answer, t.stimulus.surface) ? "1" : "0";
            std::string soundscapeCorrect;
            if (!t.answer.soundscapeAnswer.empty())
                soundscapeCorrect =
                    t.answer.soundscapeAnswer == t.stimulus.soundscape.value_or("") ? "1" : "0";
            writeRow(out, {info.code,
                           info.site,
                           info.protocolId,
                           info.protocolHash,
                           p.code,
                           group,
                           t.sessionNumber ? std::to_string(*t.sessionNumber) : "",
                           std::to_string(t.index),
                           std::to_string(t.block),
                           t.practice ? "1" : "0",
                           t.stimulus.id,
                           t.stimulus.surface,
                           t.stimulus.soundscape.value_or(""),
                           toString(t.stimulus.modalities),
                           t.stimulus.reverb.value_or(""),
                           std::to_string(t.repetition),
                           t.renderSeed ? std::to_string(*t.renderSeed) : "",
                           t.answer.answer,
                           option ? option->label : "",
                           correct,
                           ratingCell(t, "realism"),
                           ratingCell(t, "quality"),
                           t.answer.soundscapeAnswer,
                           soundscapeCorrect,
                           t.responseTimeS ? fmt::format("{:.3f}", *t.responseTimeS) : "",
                           t.excluded ? "1" : "0",
                           t.exclusionReason,
                           t.answer.comment,
                           t.startedAt,
                           t.answeredAt,
                           std::to_string(t.index + 1),
                           p.simulated ? "1" : "0",
                           t.clip ? t.clip->file : "",
                           t.clip ? std::to_string(t.clip->frames) : "",
                           t.clip ? fmt::format("{}", t.clip->sampleRateHz) : "",
                           t.clip ? t.clip->samplesSha256 : ""});
            ++rows;
        }
    }
    return rows;
}

int writeParticipantsCsv(const StudyStore& store, std::ostream& out, SimulatedRows simulated) {
    const Protocol& protocol = store.protocol();
    // `simulated` before `hearing`: readers take the columns after `hearing` as the protocol's
    // participant fields (analysis/ratings/RatingData.cpp).
    std::vector<std::string> header{"participant", "group",  "status", "simulated",
                                    "age",         "gender", "shoes",  "hearing"};
    for (const auto& f : protocol.participantFields) header.push_back(f.id);
    writeRow(out, header);
    int rows = 0;
    for (const auto& p : store.participants()) {
        if (p.simulated && simulated == SimulatedRows::Exclude) continue;
        std::vector<std::string> row{p.code,
                                     p.groupId,
                                     toString(p.status),
                                     p.simulated ? "1" : "0",
                                     p.age ? std::to_string(*p.age) : "",
                                     p.gender,
                                     p.shoes,
                                     p.hearing};
        for (const auto& f : protocol.participantFields) {
            const auto it = p.fields.find(f.id);
            row.push_back(it == p.fields.end() ? "" : it->second);
        }
        writeRow(out, row);
        ++rows;
    }
    return rows;
}

int writeAudioCsv(const StudyStore& store, std::ostream& out, ExportScope scope) {
    const StudyInfo info = store.info();
    writeRow(out, std::vector<std::string>(kAudioColumns.begin(), kAudioColumns.end()));
    int rows = 0;
    for (const auto& p : store.participants())
        for (const auto& t : store.trials(p.code)) {
            if (t.startedAt.empty()) continue;
            if (scope == ExportScope::Answered && !t.answered) continue;
            std::vector<std::string> row{info.code,
                                         p.code,
                                         std::to_string(t.index),
                                         t.stimulus.id,
                                         t.sessionNumber ? std::to_string(*t.sessionNumber) : "",
                                         t.answered ? "1" : "0",
                                         t.excluded ? "1" : "0"};
            if (t.audio) {
                const TrialAudioStats& a = *t.audio;
                for (std::string cell :
                     {fmt::format("{}", a.sampleRateHz), std::to_string(a.blockSize),
                      std::to_string(a.frames), std::to_string(a.xruns),
                      fmt::format("{:.3f}", a.averageLoadPercent),
                      fmt::format("{:.3f}", a.maxLoadPercent), fmt::format("{:.4f}", a.maxBlockMs),
                      std::to_string(a.droppedGrfFrames)})
                    row.push_back(std::move(cell));
            } else {
                row.insert(row.end(), 8, "");
            }
            row.push_back(t.grfRecording.value_or(""));
            row.push_back(t.sensorLog.value_or(""));
            row.push_back(std::to_string(t.interruptions));
            row.push_back(t.interruptionReason);
            row.push_back(t.startedAt);
            row.push_back(t.answeredAt);
            writeRow(out, row);
            ++rows;
        }
    return rows;
}

int writeScalesCsv(const StudyStore& store, std::ostream& out) {
    writeRow(out, {"scale", "prompt", "min", "max", "anchors", "stimuli"});
    int rows = 0;
    for (const auto& s : store.protocol().questions.scales) {
        std::string anchors, stimuli;
        for (const auto& [v, label] : s.anchors)
            anchors += (anchors.empty() ? "" : "; ") + std::to_string(v) + "=" + label;
        for (const auto& id : s.stimuli) stimuli += (stimuli.empty() ? "" : " ") + id;
        writeRow(out,
                 {s.id, s.prompt, std::to_string(s.min), std::to_string(s.max), anchors, stimuli});
        ++rows;
    }
    return rows;
}

int writeRatingsCsv(const StudyStore& store, std::ostream& out, ExportScope scope,
                    SimulatedRows simulated) {
    const StudyInfo info = store.info();
    const Protocol& protocol = store.protocol();
    // One column per factor of [[factorial]] stimuli (sorted), so that factorial designs can be
    // analysed without decoding stimulus ids.
    std::set<std::string> factorNames;
    for (const auto& s : protocol.stimuli)
        for (const auto& [name, level] : s.factors) factorNames.insert(name);
    std::vector<std::string> header{"study",       "participant", "group",   "trial_index",
                                    "stimulus_id", "practice",    "excluded"};
    header.insert(header.end(), factorNames.begin(), factorNames.end());
    header.push_back("scale");
    header.push_back("value");
    header.push_back("simulated");
    writeRow(out, header);
    int rows = 0;
    for (const auto& p : store.participants()) {
        if (p.simulated && simulated == SimulatedRows::Exclude) continue;
        const std::string group = protocol.design == DesignKind::Between ? p.groupId : "";
        for (const auto& t : store.trials(p.code)) {
            if (scope == ExportScope::Answered && !t.answered) continue;
            for (const auto& [scale, value] : t.answer.ratings) {
                std::vector<std::string> row{info.code,
                                             p.code,
                                             group,
                                             std::to_string(t.index),
                                             t.stimulus.id,
                                             t.practice ? "1" : "0",
                                             t.excluded ? "1" : "0"};
                for (const auto& name : factorNames) {
                    const auto it = t.stimulus.factors.find(name);
                    row.push_back(it == t.stimulus.factors.end() ? "" : it->second);
                }
                row.push_back(scale);
                row.push_back(std::to_string(value));
                row.push_back(p.simulated ? "1" : "0");
                writeRow(out, row);
                ++rows;
            }
        }
    }
    return rows;
}

namespace {
/// One row of the codebook's trials.csv table.
struct ColumnMeaning {
    std::string_view name, type, meaning;
};

/// Whether the codebook names exactly kTrialColumns, in order (checked when compiling).
template <std::size_t N>
constexpr bool namesAreTheTrialColumns(const ColumnMeaning (&rows)[N]) {
    if (N != kTrialColumns.size()) return false;
    for (std::size_t i = 0; i < N; ++i)
        if (rows[i].name != kTrialColumns[i]) return false;
    return true;
}

/// A codebook table of answer options: heading with the question, then key, id and label.
void writeOptionTable(std::ostream& out, std::string_view title, const std::string& prompt,
                      const std::vector<AnswerOption>& options) {
    out << fmt::format("\n## {} — {}\n\n| key | id | label |\n|---|---|---|\n", title, prompt);
    for (const auto& o : options)
        out << fmt::format("| {} | `{}` | {} |\n", o.letter, o.id, o.label);
}
} // namespace

void writeCodebook(const StudyStore& store, std::ostream& out) {
    const StudyInfo info = store.info();
    const Protocol& p = store.protocol();
    out << fmt::format("# Codebook: study {} ({})\n\n", info.code, info.site);
    out << fmt::format("Protocol `{}` version {} — {}  \nSHA-256 of the protocol text: `{}`  \n"
                       "Study seed: {}; created {}; schema version {}.\n\n",
                       p.id, p.version, p.title, info.protocolHash, info.seed, info.createdAt,
                       info.schemaVersion);
    out << "## trials.csv — one row per trial\n\n"
           "CSV (RFC 4180, CRLF line ends, UTF-8). An empty cell is a missing value; booleans "
           "are 0/1; times are ISO 8601 UTC with milliseconds. A text cell that would start "
           "a spreadsheet formula (=, +, -, @, tab or CR) is written with a leading apostrophe "
           "('=x); numbers such as -1.5 are written as they are.\n\n"
           "| column | type | meaning |\n|---|---|---|\n";
    constexpr ColumnMeaning rows[] = {
        {"study", "text", "study code"},
        {"site", "text", "site (lab) code"},
        {"protocol_id", "text", "protocol id"},
        {"protocol_hash", "text", "SHA-256 of the exact protocol text the study ran"},
        {"participant", "text", "pseudonymous participant code"},
        {"group", "text", "between-subject group id (empty in within-subject designs)"},
        {"session", "integer", "session number of the participant (1, 2, ... after resumes)"},
        {"trial_index", "integer",
         "stored index: 0-based position in the participant's plan (practice first); the "
         "number people see is `trial`"},
        {"block", "integer", "0 = practice; 1..repetitions for blocked orders; otherwise 1"},
        {"practice", "0/1", "1 for practice trials (normally left out of analyses)"},
        {"stimulus_id", "text", "stimulus id of the protocol"},
        {"surface", "text", "surface walked on (a *_reverb id is the base surface with reverb)"},
        {"soundscape", "text", "soundscape played with the footsteps (empty: none)"},
        {"modalities", "audio/haptic/both", "senses the stimulus was rendered to"},
        {"reverb", "text", "impulse-response name when convolution reverb was applied"},
        {"repetition", "integer", "1-based repetition of this stimulus for this participant"},
        {"render_seed", "unsigned 64-bit", "seed the renderer used (replay re-renders with it)"},
        {"answer", "text", "answer option id (surface id or dont_know)"},
        {"answer_label", "text", "the option's label as shown"},
        {"correct", "0/1",
         "1 when the answer names the surface walked on (its base surface "
         "for a reverb variant), not the soundscape; dont_know is 0"},
        {"realism", "integer", "rating on the scale `realism` (see scales below)"},
        {"quality", "integer", "rating on the scale `quality`"},
        {"soundscape_answer", "text", "answer to the environment question (soundscape id)"},
        {"soundscape_correct", "0/1", "1 when soundscape_answer is the soundscape played"},
        {"response_time_s", "seconds", "from stimulus start to the committed answer"},
        {"excluded", "0/1", "1 when the experimenter excluded the trial"},
        {"exclusion_reason", "text", "why it was excluded"},
        {"comment", "text", "free comment"},
        {"started_at", "ISO 8601 UTC", "when the stimulus started"},
        {"answered_at", "ISO 8601 UTC", "when the answer was committed"},
        {"trial", "integer",
         "trial number as people read and type it (1-based: trial_index + 1; \"trial 3 of 40\" "
         "in the session, `underfoot replay --trial 3`)"},
        {"simulated", "0/1",
         "1 for a synthetic participant of `underfoot session --simulate` (not a person; left "
         "out of `underfoot analyze` unless --include-simulated)"},
        {"clip_file", "text",
         "the clip a listening-test trial played, relative to the clip folder (empty for live "
         "and booth trials without a clip); its seed is `render_seed`"},
        {"clip_frames", "integer", "frames of the clip file"},
        {"clip_rate", "Hz", "sample rate of the clip file"},
        {"clip_sha256", "hex text",
         "SHA-256 of the clip's float32 samples (`underfoot replay` renders the trial again and "
         "compares)"}};
    static_assert(namesAreTheTrialColumns(rows), "codebook rows must follow kTrialColumns");
    for (const auto& r : rows)
        out << fmt::format("| `{}` | {} | {} |\n", r.name, r.type, r.meaning);
    out << "\n## ratings.csv — one row per rating\n\n"
           "Columns: study, participant, group, trial_index, stimulus_id, practice, excluded, "
           "one column per factor of the protocol's [[factorial]] stimuli (their level; empty "
           "for other stimuli), scale, value, simulated (0/1, as in trials.csv: 1 for a "
           "synthetic participant of `underfoot session --simulate`). Every scale of the "
           "protocol, including those without a column in trials.csv.\n"
           "\n## participants.csv — one row per participant\n\n"
           "Columns: participant, group, status, simulated (0/1: 1 for a synthetic participant "
           "of `underfoot session --simulate`, not a person; left out of `underfoot analyze` "
           "unless --include-simulated), age, gender, shoes, hearing, then one column per "
           "participant field of the protocol.\n";
    if (!p.questions.scales.empty()) {
        out << "\n## Scales\n\n| id | range | anchors | prompt |\n|---|---|---|---|\n";
        for (const auto& s : p.questions.scales)
            out << fmt::format("| `{}` | {}–{} | {} … {} | {} |\n", s.id, s.min, s.max, s.minLabel,
                               s.maxLabel, s.prompt);
    }
    if (p.questions.asksSurface())
        writeOptionTable(out, "Answer options", p.questions.surfacePrompt,
                         p.questions.surfaceOptions);
    if (!p.questions.soundscapeOptions.empty())
        writeOptionTable(out, "Soundscape options", p.questions.soundscapePrompt,
                         p.questions.soundscapeOptions);
    out << "\n## Stimuli\n\n| id | surface | soundscape | modalities | reverb | factors |\n"
           "|---|---|---|---|---|---|\n";
    for (const auto& s : p.stimuli) {
        std::string factors;
        for (const auto& [k, v] : s.factors) factors += (factors.empty() ? "" : ", ") + k + "=" + v;
        out << fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", s.id, s.surface,
                           s.soundscape.value_or(""), toString(s.modalities), s.reverb.value_or(""),
                           factors);
    }
    if (p.design == DesignKind::Between) {
        out << "\n## Groups\n\n| id | label | stimuli | modalities override |\n|---|---|---|---|\n";
        for (const auto& g : p.groups) {
            std::string ids;
            for (const auto& s : g.stimuli) ids += (ids.empty() ? "" : ", ") + s;
            out << fmt::format("| `{}` | {} | {} | {} |\n", g.id, g.label, ids,
                               g.modalities ? toString(*g.modalities) : "");
        }
    }
}

std::map<std::string, std::string> stimulusDisplayLabels(const Protocol& protocol) {
    std::map<std::string, int> uses;
    for (const auto& s : protocol.stimuli)
        if (!s.label.empty()) ++uses[s.label];
    std::map<std::string, std::string> out;
    for (const auto& s : protocol.stimuli) {
        if (s.label.empty()) {
            out[s.id] = s.id;
        } else if (uses[s.label] == 1) {
            out[s.id] = s.label;
        } else {
            std::string levels;
            for (const auto& [factor, level] : s.factors)
                levels += (levels.empty() ? "" : ", ") + factor + " " + level;
            out[s.id] = s.label + " (" + (levels.empty() ? s.id : levels) + ")";
        }
    }
    // Levels that still do not tell two stimuli apart: add the id.
    std::map<std::string, int> shown;
    for (const auto& [id, label] : out) ++shown[label];
    for (auto& [id, label] : out)
        if (shown[label] > 1) label += " [" + id + "]";
    return out;
}

} // namespace underfoot::experiment
