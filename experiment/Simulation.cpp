// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Simulation.h"
#include "base/TomlReader.h"
#include "base/Version.h"
#include "experiment/Clips.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace underfoot::experiment {

namespace {
std::vector<std::string> splitCsvLine(const std::string& line) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                cell += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                cell += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            cells.push_back(cell);
            cell.clear();
        } else if (c != '\r') {
            cell += c;
        }
    }
    cells.push_back(cell);
    return cells;
}

std::string normalize(std::string s) {
    for (auto& c : s)
        c = c == ' ' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string surfaceFor(const std::string& cell, const Catalogue& catalogue) {
    if (const auto* e = catalogue.surfaceByCode(cell)) return e->id;
    if (catalogue.surface(cell)) return cell;
    return {};
}

std::string soundscapeFor(const std::string& cell, const Catalogue& catalogue) {
    const std::string n = normalize(cell);
    if (n.empty()) return {};
    if (catalogue.soundscape(n)) return n;
    for (const auto& e : catalogue.soundscapes)
        if (e.id.rfind(n + "_", 0) == 0 || normalize(e.label) == n) return e.id;
    return {};
}
} // namespace

const ConfusionMatrix::Row* ConfusionMatrix::find(const Stimulus& stimulus) const {
    for (const auto& row : rows) {
        if (row.surface != stimulus.surface) continue;
        if (hasSoundscape && row.soundscape != stimulus.soundscape.value_or("")) continue;
        return &row;
    }
    return nullptr;
}

ConfusionMatrix parseConfusionMatrix(const std::string& text, const std::string& source,
                                     const Catalogue& catalogue) {
    ConfusionMatrix m;
    m.source = source;
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    std::size_t firstAnswer = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line == "\r") continue;
        const auto cells = splitCsvLine(line);
        if (m.answers.empty()) {
            if (cells.size() < 3 || normalize(cells[0]) != "stimulus")
                throw std::runtime_error(fmt::format(
                    "{}:{}: expected a header 'stimulus[,soundscape],CODE,...'", source, lineNo));
            m.hasSoundscape = normalize(cells[1]) == "soundscape";
            firstAnswer = m.hasSoundscape ? 2 : 1;
            for (std::size_t i = firstAnswer; i < cells.size(); ++i) {
                if (cells[i] == "DK" || cells[i] == kDontKnow) {
                    m.answers.emplace_back(kDontKnow);
                    continue;
                }
                const std::string id = surfaceFor(cells[i], catalogue);
                if (id.empty()) {
                    std::string codes;
                    for (const auto& e : catalogue.surfaces)
                        if (!e.code.empty()) codes += (codes.empty() ? "" : ", ") + e.code;
                    throw std::runtime_error(fmt::format(
                        "{}:{}: column {} header '{}' is not a surface code or id (expected one "
                        "of {}, a surface id, or DK)",
                        source, lineNo, i + 1, cells[i], codes));
                }
                m.answers.push_back(id);
            }
            continue;
        }
        if (cells.size() != firstAnswer + m.answers.size())
            throw std::runtime_error(fmt::format("{}:{}: {} cells; expected {} as in the header",
                                                 source, lineNo, cells.size(),
                                                 firstAnswer + m.answers.size()));
        ConfusionMatrix::Row row;
        row.line = lineNo;
        row.surface = surfaceFor(cells[0], catalogue);
        if (row.surface.empty())
            throw std::runtime_error(fmt::format("{}:{}: stimulus '{}' is not a surface code or id",
                                                 source, lineNo, cells[0]));
        if (m.hasSoundscape) {
            row.soundscape = soundscapeFor(cells[1], catalogue);
            if (row.soundscape.empty() && !cells[1].empty())
                throw std::runtime_error(fmt::format("{}:{}: soundscape '{}' is not a known "
                                                     "soundscape",
                                                     source, lineNo, cells[1]));
        }
        double total = 0.0;
        for (std::size_t i = firstAnswer; i < cells.size(); ++i) {
            double v = 0.0;
            try {
                std::size_t used = 0;
                v = cells[i].empty() ? 0.0 : std::stod(cells[i], &used);
                if (!cells[i].empty() && used != cells[i].size()) throw std::invalid_argument("");
            } catch (const std::exception&) {
                throw std::runtime_error(fmt::format("{}:{}: column {} is '{}'; expected a count",
                                                     source, lineNo, i + 1, cells[i]));
            }
            if (!std::isfinite(v) || v < 0)
                throw std::runtime_error(fmt::format("{}:{}: column {} is '{}'; expected a "
                                                     "finite count >= 0",
                                                     source, lineNo, i + 1, cells[i]));
            row.counts.push_back(v);
            total += v;
        }
        if (total <= 0)
            throw std::runtime_error(fmt::format("{}:{}: the row has no answers", source, lineNo));
        m.rows.push_back(std::move(row));
    }
    if (m.rows.empty())
        throw std::runtime_error(fmt::format("{}: no rows; expected a confusion matrix", source));
    return m;
}

ConfusionMatrix loadConfusionMatrix(const std::string& path, const Catalogue& catalogue) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("{}: cannot open the confusion matrix", path));
    std::ostringstream text;
    text << in.rdbuf();
    return parseConfusionMatrix(text.str(), path, catalogue);
}

std::vector<std::string> checkMatrixAgainst(const ConfusionMatrix& m, const Protocol& protocol) {
    std::vector<std::string> problems;
    for (const auto& g : protocol.groups)
        for (const auto& s : groupStimuli(protocol, g))
            if (!m.find(s))
                problems.push_back(fmt::format(
                    "{}: no row for stimulus '{}' (surface {}{}{})", m.source, s.id, s.surface,
                    s.soundscape ? ", soundscape " : "", s.soundscape.value_or("")));
    for (const auto& practiceId : protocol.ordering.practice)
        if (const Stimulus* s = protocol.stimulus(practiceId); s && !m.find(*s))
            problems.push_back(
                fmt::format("{}: no row for practice stimulus '{}'", m.source, practiceId));
    if (protocol.questions.asksSurface())
        for (std::size_t c = 0; c < m.answers.size(); ++c) {
            if (protocol.questions.surfaceOption(m.answers[c])) continue;
            double used = 0;
            for (const auto& row : m.rows) used += row.counts[c];
            if (used > 0)
                problems.push_back(fmt::format("{}: answer '{}' has counts but is not an option "
                                               "of protocol {}'s answer list",
                                               m.source, m.answers[c], protocol.id));
        }
    return problems;
}

SimulatedParticipant::SimulatedParticipant(const ConfusionMatrix& matrix, const Protocol& protocol,
                                           std::string groupId, std::uint64_t seed,
                                           SimulationSettings settings)
    : matrix_(matrix), protocol_(protocol), groupId_(std::move(groupId)), rng_(seed),
      settings_(settings) {}

TrialAnswer SimulatedParticipant::answer(const TrialRecord& trial) {
    TrialAnswer a;
    const Questions& q = protocol_.questions;
    bool correct = false;
    if (q.asksSurface()) {
        const auto* row = matrix_.find(trial.stimulus);
        if (!row)
            throw std::runtime_error(
                fmt::format("{}: no row for stimulus '{}'", matrix_.source, trial.stimulus.id));
        double total = 0;
        for (std::size_t c = 0; c < row->counts.size(); ++c)
            if (q.surfaceOption(matrix_.answers[c])) total += row->counts[c];
        if (total <= 0)
            throw std::runtime_error(fmt::format("{}:{}: no count for an option of the answer "
                                                 "list",
                                                 matrix_.source, row->line));
        double pick = rng_.uniform() * total;
        std::size_t chosen = 0;
        for (std::size_t c = 0; c < row->counts.size(); ++c) {
            if (!q.surfaceOption(matrix_.answers[c]) || row->counts[c] <= 0) continue;
            chosen = c;
            pick -= row->counts[c];
            if (pick < 0) break;
        }
        a.answer = matrix_.answers[chosen];
        correct = answerIsCorrect(a.answer, trial.stimulus.surface);
    }
    for (const Scale* asked : askedScales(protocol_, trial.stimulus, trial.block)) {
        const Scale& scale = *asked;
        const RatingModel* model = settings_.ratingModel.get();
        const double expected =
            model ? model->expected(scale.id, trial.stimulus, fields_) : std::nan("");
        double value = 0.0;
        if (!std::isnan(expected)) {
            const ScaleRatingModel& m = model->scales.at(scale.id);
            auto bias = biases_.find(scale.id);
            if (bias == biases_.end()) {
                // A constant per participant and scale, from its own stream (resume-safe).
                std::uint64_t h = 1469598103934665603ULL;
                for (const char c : scale.id)
                    h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
                Rng biasRng(deriveSeed(biasSeed_, {h}));
                bias = biases_.emplace(scale.id, m.participantSd * biasRng.gaussian()).first;
            }
            value = expected + bias->second + m.noiseSd * rng_.gaussian();
        } else {
            const double mid = 0.5 * (scale.min + scale.max);
            const double spread = 0.2 * (scale.max - scale.min);
            value = mid + (correct ? 0.5 : 0.0) + spread * rng_.gaussian();
        }
        a.ratings[scale.id] =
            std::clamp(static_cast<int>(std::lround(value)), scale.min, scale.max);
    }
    if (q.asksSoundscape(groupId_)) {
        const auto& options = q.soundscapeOptions;
        const std::string truth = trial.stimulus.soundscape.value_or("");
        if (!truth.empty() && q.soundscapeOption(truth) &&
            rng_.uniform() < settings_.soundscapeAccuracy) {
            a.soundscapeAnswer = truth;
        } else {
            std::vector<std::string> others;
            for (const auto& o : options)
                if (o.id != truth) others.push_back(o.id);
            a.soundscapeAnswer = others[static_cast<std::size_t>(rng_.below(others.size()))];
        }
    }
    return a;
}

void SimulatedParticipant::setParticipant(std::uint64_t biasSeed,
                                          std::map<std::string, std::string> fields) {
    biasSeed_ = biasSeed;
    fields_ = std::move(fields);
    biases_.clear();
}

double SimulatedParticipant::responseTimeS() {
    return settings_.medianResponseS * std::exp(0.4 * rng_.gaussian());
}

} // namespace underfoot::experiment

#include "experiment/Session.h"
#include "experiment/TrialFlow.h"

namespace underfoot::experiment {

namespace {
/// A silent player for simulations that reports each clip's own seed in listening tests (the
/// seed the clip was rendered with), and the planned seed otherwise.
class SimulationPlayer final : public StimulusPlayer {
  public:
    SimulationPlayer(const Protocol& protocol, std::string walker, const std::string& clipDir)
        : protocol_(protocol), walker_(std::move(walker)) {
        if (protocol.clips.enabled && !clipDir.empty())
            clips_ = std::make_unique<ClipPlayer>(protocol, clipDir); // plays nothing
    }
    StimulusStart start(const Stimulus& stimulus, std::uint64_t plannedSeed) override {
        if (clips_) return clips_->start(stimulus, plannedSeed);
        if (protocol_.clips.enabled) {
            // The clip as `underfoot clips` renders it at 48 kHz (its seed and length), so that
            // replay renders a simulated trial's clip like any other; no samples hash, since no
            // file was played.
            StimulusStart started;
            started.renderSeed = clipSeed(protocol_, stimulus);
            if (!stimulus.clip) {
                const double rate = 48000.0;
                const auto frames =
                    static_cast<std::uint64_t>(std::llround(protocol_.clips.seconds * rate));
                started.clip = PlayedClip{clipPath(stimulus, ""),
                                          static_cast<double>(frames) / rate, frames, rate, ""};
            }
            return started;
        }
        // A sensor stimulus (microphones, shoes, gyroscopes) has no person walking: the
        // simulated participant walks as the virtual walker, for the protocol's trial time, and
        // that control stream is what the trial records (replay regenerates it from the seed).
        // Water stimuli replay from the virtual gait of their wading parameters already.
        if (stimulus.input.kind == InputKind::Sensor && stimulus.wading.empty() &&
            stimulus.surface != "water")
            return {plannedSeed, walker_};
        return {plannedSeed, std::nullopt};
    }
    void stop() override {}

  private:
    const Protocol& protocol_;
    std::string walker_;                ///< formatSimulatedWalker() of this participant's feet
    std::unique_ptr<ClipPlayer> clips_; ///< the clip folder's manifest, when one is given
};
} // namespace

int runSimulatedSession(StudyStore& store, const std::string& code, const ConfusionMatrix& matrix,
                        std::uint64_t seed, const SimulationSettings& settings,
                        const CommitCallback& onCommitted) {
    const ParticipantInfo info = store.participant(code);
    if (!info.simulated)
        throw StoreError(fmt::format("{}: participant '{}' is a real participant; a simulation "
                                     "only answers for the simulated participants it creates",
                                     store.path(), code));
    const auto first = store.firstUnanswered(code);
    if (!first) return 0;
    // The answerer's stream depends on where the session resumes, so a resumed participant
    // still gets reproducible answers.
    SimulatedParticipant answerer(matrix, store.protocol(), info.groupId,
                                  deriveSeed(seed, {static_cast<std::uint64_t>(info.index),
                                                    static_cast<std::uint64_t>(*first)}),
                                  settings);
    answerer.setParticipant(deriveSeed(seed, {static_cast<std::uint64_t>(info.index), 0xB1A5}),
                            info.fields);
    const Protocol& protocol = store.protocol();
    // Replays and laps draw from their own stream so that they never shift the answers.
    Rng listening(deriveSeed(seed, {static_cast<std::uint64_t>(info.index),
                                    static_cast<std::uint64_t>(*first), 0x11571}));
    const double replayProbability =
        settings.ratingModel ? settings.ratingModel->replayProbability : 0.2;
    double simulatedTimeS = 0.0;
    // The participant's own gait (the same in every session of the participant).
    SimulationPlayer player(store.protocol(),
                            formatSimulatedWalker(drawSimulatedWalker(
                                deriveSeed(seed, {static_cast<std::uint64_t>(info.index), 0x3A1C}),
                                store.protocol().timing.trialS)),
                            settings.clipDir);
    Session session(store, code, player,
                    SessionSettings{"simulation", "none (simulated)", "none (simulated)",
                                    underfoot::base::version(), false},
                    [&] { return simulatedTimeS; });
    // The simulated participant answers through the trial core like a person (TrialFlow: its
    // checks against the protocol before anything is stored).
    TrialFlow flow(store, session);
    const auto check = [&](const FlowResult& r) {
        if (!r)
            throw StoreError(
                fmt::format("{}: simulated participant '{}': {}", store.path(), code, r.message));
    };
    int committed = 0;
    while (session.phase() != SessionPhase::Finished) {
        switch (session.phase()) {
        case SessionPhase::Briefing:
            session.finishBriefing();
            flow.reset();
            break;
        case SessionPhase::Break:
            session.finishBreak();
            flow.reset();
            break;
        case SessionPhase::Practice:
        case SessionPhase::Trial: {
            const TrialRecord trial = session.current();
            check(flow.start());
            if (protocol.clips.enabled) {
                // Listening-test mode: the clip on demand, replays counted.
                for (int n = 0;
                     protocol.clips.replay && n < 5 && listening.uniform() < replayProbability;
                     ++n) {
                    simulatedTimeS += protocol.clips.seconds;
                    check(flow.replay());
                }
            } else {
                // A resumed trial continues from the laps already walked.
                for (int lap = session.lapsDone(); lap < session.lapCount(); ++lap) {
                    simulatedTimeS += 30.0 * std::exp(0.1 * listening.gaussian());
                    check(flow.completeLap());
                }
            }
            const TrialAnswer a = answerer.answer(trial);
            simulatedTimeS += answerer.responseTimeS();
            check(flow.submit(a)); // every question of the trial: surface, scales, soundscape
            ++committed;
            if (onCommitted) onCommitted(code, trial.index);
            break;
        }
        case SessionPhase::Finished:
            break;
        }
    }
    return committed;
}

int simulateStudy(StudyStore& store, const MatrixByGroup& matrices, int participants,
                  const SimulationSettings& settings, const std::string& codePrefix,
                  const CommitCallback& onCommitted) {
    auto matrixFor = [&](const std::string& groupId) -> const ConfusionMatrix& {
        if (auto it = matrices.find(groupId); it != matrices.end()) return it->second;
        if (auto it = matrices.find(""); it != matrices.end()) return it->second;
        throw std::runtime_error(fmt::format("no confusion matrix for group '{}'", groupId));
    };
    const std::uint64_t seed = deriveSeed(store.info().seed, {0x5157}); // "simulation" stream
    int committed = 0;
    int completed = 0;
    for (const auto& p : store.participants()) {
        // Real participants (registered, interrupted or done) are never touched nor counted.
        if (!p.simulated || p.status == ParticipantStatus::Dropped) continue;
        if (p.status != ParticipantStatus::Completed) {
            if (store.firstUnanswered(p.code))
                committed += runSimulatedSession(store, p.code, matrixFor(p.groupId), seed,
                                                 settings, onCommitted);
            else
                store.markCompleted(p.code);
        }
        ++completed;
    }
    int next = static_cast<int>(store.participants().size()) + 1;
    while (completed < participants) {
        std::string code;
        do {
            code = fmt::format("{}{:03}", codePrefix, next++);
        } while ([&] {
            try {
                store.participant(code);
                return true;
            } catch (const StoreError&) {
                return false;
            }
        }());
        // Participant fields drawn uniformly from their options (free text: "simulated").
        std::map<std::string, std::string> fields;
        Rng fieldRng(deriveSeed(seed, {static_cast<std::uint64_t>(next), 0xF1E1D}));
        for (const auto& f : store.protocol().participantFields)
            fields[f.id] =
                f.options.empty()
                    ? std::string("simulated")
                    : f.options[static_cast<std::size_t>(fieldRng.below(f.options.size()))];
        const ParticipantInfo p =
            store.registerParticipant({code, std::nullopt, "", "", "", {}, "", true}, fields);
        committed +=
            runSimulatedSession(store, p.code, matrixFor(p.groupId), seed, settings, onCommitted);
        ++completed;
    }
    return committed;
}

std::string findProtocolFile(const Protocol& protocol, const std::string& relative,
                             const std::string& protocolFile) {
    namespace fs = std::filesystem;
    std::vector<fs::path> folders;
    if (!protocolFile.empty()) folders.push_back(fs::path(protocolFile).parent_path());
    if (!protocol.sourceName.empty())
        folders.push_back(fs::path(protocol.sourceName).parent_path());
    folders.push_back(fs::path(shippedProtocolDir()));
    std::string looked;
    for (const auto& folder : folders) {
        const fs::path candidate = folder / relative;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec)) return candidate.string();
        looked += (looked.empty() ? "" : ", ") + candidate.string();
    }
    throw std::runtime_error(fmt::format("protocol {}: [simulation] names '{}', which is not "
                                         "found (looked at {})",
                                         protocol.id, relative, looked));
}

MatrixByGroup defaultMatrices(const Protocol& protocol, const std::string& protocolFile) {
    MatrixByGroup out;
    for (const auto& [group, file] : protocol.simulation.confusion)
        out[group] = loadConfusionMatrix(findProtocolFile(protocol, file, protocolFile));
    return out;
}

} // namespace underfoot::experiment

namespace underfoot::experiment {

SimulatedWalker drawSimulatedWalker(std::uint64_t seed, double seconds) {
    Rng rng(seed);
    const auto draw = [&](double lo, double hi, double step) {
        return std::round((lo + (hi - lo) * rng.uniform()) / step) * step;
    };
    SimulatedWalker w;
    w.seconds = seconds;
    // Rounded through text so that the stored digits are exactly the values used.
    const auto exact = [](double v, int decimals) {
        return std::stod(fmt::format("{:.{}f}", v, decimals));
    };
    w.walker["cadence"] = exact(draw(90, 120, 0.1), 1);
    w.walker["mass"] = exact(draw(55, 95, 0.1), 1);
    w.walker["shoe"] = exact(draw(0.2, 0.8, 0.01), 2);
    w.walker["variability"] = exact(draw(0.02, 0.05, 0.001), 3);
    return w;
}

std::string formatSimulatedWalker(const SimulatedWalker& w) {
    std::string text = fmt::format("{}{{ seconds = {}", kSimulatedWalkerTablePrefix, w.seconds);
    for (const auto& [key, value] : w.walker)
        if (const double* v = std::get_if<double>(&value))
            text += fmt::format(", {} = {}", key, *v);
    return text + " }";
}

std::optional<SimulatedWalker> parseSimulatedWalker(const std::string& reference) {
    SimulatedWalker w;
    const auto checkSeconds = [&](double s) {
        if (!(s > 0 && s <= 3600))
            throw std::invalid_argument(fmt::format(
                "stored control stream '{}': seconds = {}; expected 0 < seconds <= 3600", reference,
                s));
    };
    if (reference.rfind(kSimulatedWalkerPrefix, 0) == 0) {
        const std::string value = reference.substr(kSimulatedWalkerPrefix.size());
        std::size_t used = 0;
        try {
            w.seconds = std::stod(value, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != value.size())
            throw std::invalid_argument(
                fmt::format("stored control stream '{}': expected {}SECONDS", reference,
                            kSimulatedWalkerPrefix));
        checkSeconds(w.seconds);
        return w;
    }
    if (reference.rfind(kSimulatedWalkerTablePrefix, 0) != 0) return std::nullopt;
    toml::table doc;
    try {
        doc = base::parseToml("walker = " + reference.substr(kSimulatedWalkerTablePrefix.size()),
                              "stored control stream");
    } catch (const base::TomlError& e) {
        throw std::invalid_argument(fmt::format(
            "stored control stream '{}': expected {}{{ seconds = S, cadence = ..., mass = ..., "
            "shoe = ..., variability = ... }} ({})",
            reference, kSimulatedWalkerTablePrefix, e.problems().front().message));
    }
    const toml::table* t = doc["walker"].as_table();
    if (!t)
        throw std::invalid_argument(
            fmt::format("stored control stream '{}': expected an inline table", reference));
    for (const auto& [key, node] : *t) {
        const auto v = node.value<double>();
        if (!v || !std::isfinite(*v))
            throw std::invalid_argument(
                fmt::format("stored control stream '{}': `{}`: expected a finite number", reference,
                            key.str()));
        if (key.str() == "seconds")
            w.seconds = *v;
        else
            w.walker[std::string(key.str())] = *v;
    }
    checkSeconds(w.seconds);
    return w;
}

} // namespace underfoot::experiment
