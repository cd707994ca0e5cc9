// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot protocol check FILE`: validates a protocol and prints its plan summary.
// `underfoot protocol power FILE --effect ...`: how many participants (issue #15).
#include "analysis/model/Catalog.h"
#include "analysis/power/Power.h"
#include "app/cli/CommandRegistry.h"
#include "app/wiring/StimulusRender.h"
#include "experiment/Catalogue.h"
#include "experiment/Plan.h"
#include "experiment/Protocol.h"
#include "experiment/Random.h"
#include "experiment/RatingModel.h"
#include "experiment/Simulation.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <thread>

namespace underfoot::cli::protocol_command {
namespace {

using namespace underfoot::experiment;

std::string minutes(double seconds) {
    return fmt::format("{:.0f} min {:02.0f} s", std::floor(seconds / 60.0),
                       std::fmod(seconds, 60.0));
}

void printSummary(const Protocol& p, std::uint64_t seed, int participants) {
    fmt::print("{} — {} (version {})\n", p.id, p.title, p.version);
    if (!p.reference.empty()) fmt::print("reference: {}\n", p.reference);
    fmt::print("sha256: {}\n", p.hash);
    fmt::print("design: {}-subject, {} stimuli, {} repetition(s), order {}{}{}\n",
               toString(p.design), p.stimuli.size(), p.ordering.repetitions,
               p.ordering.order == OrderKind::Random ? "random per participant" : "fixed",
               p.ordering.blocks == BlockKind::Repetition ? ", one block per repetition"
               : p.ordering.blocks == BlockKind::Scale    ? ", one block per scale"
                                                          : "",
               p.ordering.noImmediateRepeat ? ", no immediate repeat" : "");
    if (p.ordering.counterbalance == Counterbalance::LatinSquare)
        fmt::print("counterbalanced: Williams Latin square, {} orders (groups order1..order{})\n",
                   p.groups.size(), p.groups.size());
    if (p.laps.total() > 0)
        fmt::print("laps per condition: {} silent baseline, then {} with sound\n", p.laps.baseline,
                   p.laps.feedback);
    if (p.clips.enabled) {
        int lab = 0;
        for (const auto& s : p.stimuli) lab += s.clip ? 1 : 0;
        fmt::print("listening test: {} clip(s) rendered by `underfoot clips` ({:g} s, seed {}), {} "
                   "supplied by the lab; replay {}\n",
                   static_cast<int>(p.stimuli.size()) - lab, p.clips.seconds, p.clips.seed, lab,
                   p.clips.replay ? "allowed (counted)" : "not allowed");
    }
    for (const auto& f : p.participantFields)
        fmt::print("participant field: {} ({}){}\n", f.id, f.label,
                   f.options.empty() ? std::string(" free text")
                                     : fmt::format(": {}", fmt::join(f.options, ", ")));
    fmt::print("questions: {}{}{}{}\n",
               p.questions.asksSurface()
                   ? fmt::format("surface ({} options)", p.questions.surfaceOptions.size())
                   : "no surface question",
               p.questions.scales.empty() ? ""
                                          : fmt::format(", {} scale(s)", p.questions.scales.size()),
               p.questions.soundscapeOptions.empty() ? "" : ", soundscape",
               p.questions.comment ? ", comment" : "");
    const PlanSummary summary = summarizePlans(p, seed, participants);
    fmt::print("\nPer participant\n");
    fmt::print("  {:<14} {:>8} {:>6} {:>6} {:>7}  {}\n", "group", "practice", "trials", "breaks",
               "target", "estimated duration");
    for (std::size_t i = 0; i < summary.groups.size(); ++i) {
        const auto& g = summary.groups[i];
        fmt::print("  {:<14} {:>8} {:>6} {:>6} {:>7}  {}\n", g.groupId, g.practiceTrials,
                   g.mainTrials, g.breaks,
                   p.groups[i].target > 0 ? std::to_string(p.groups[i].target) : "-",
                   minutes(g.estimatedDurationS));
    }
    fmt::print("\nBalance over {} simulated participant{} per group (seed {}); positions count "
               "from 1\n",
               participants, participants == 1 ? "" : "s", seed);
    for (const auto& table : summary.balance) {
        fmt::print("  group {}\n", table.groupId);
        fmt::print("    {:<20} {:>13} {:>11} {:>13} {:>7}\n", "stimulus", "presentations",
                   "times first", "mean position", "(ideal)");
        const std::size_t positions = table.counts.empty() ? 0 : table.counts[0].size();
        const double ideal = positions > 0 ? (static_cast<double>(positions) + 1.0) / 2.0 : 0.0;
        for (std::size_t s = 0; s < table.stimulusIds.size(); ++s) {
            int total = 0;
            double weighted = 0;
            for (std::size_t pos = 0; pos < positions; ++pos) {
                total += table.counts[s][pos];
                weighted += static_cast<double>(table.counts[s][pos] * (static_cast<int>(pos) + 1));
            }
            fmt::print("    {:<20} {:>13} {:>11} {:>13.2f} {:>7.1f}\n", table.stimulusIds[s], total,
                       positions ? table.counts[s][0] : 0, total ? weighted / total : 0.0, ideal);
        }
    }
}

// ------------------------------------------------------------------ power (issue #15)

struct PowerArgs {
    std::string file;
    std::vector<std::string> effect{"published"};
    std::string participants = "10..60";
    int simulations = 2000;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double participantSd = 0.8;
    double alpha = 0.05;
    double target = 0.8;
    std::vector<std::string> groups;
    bool noMixed = false;
    int nAGQ = 1;
    std::string publishedDir = std::string(UNDERFOOT_SOURCE_DIR) + "/tests/analysis/data/published";
    std::string ratingModel; ///< rating protocols: the model (default: the protocol's [simulation])
    std::string scale;
    std::string factor;
    std::vector<std::string> levels;
};

/// "10..60" (step 10), "10..60:5" or "10,15,20".
std::vector<int> parseSizes(const std::string& text) {
    std::vector<int> out;
    auto number = [&](const std::string& t) {
        std::size_t used = 0;
        int v = 0;
        try {
            v = std::stoi(t, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != t.size() || v < 2 || v > 100000)
            throw underfoot::cli::UserError(fmt::format(
                "--participants {}: '{}' is not a group size (an integer from 2)", text, t));
        return v;
    };
    if (const auto dots = text.find(".."); dots != std::string::npos) {
        std::string rest = text.substr(dots + 2);
        int step = 10;
        if (const auto colon = rest.find(':'); colon != std::string::npos) {
            step = number(rest.substr(colon + 1));
            rest = rest.substr(0, colon);
        }
        const int from = number(text.substr(0, dots)), to = number(rest);
        if (to < from)
            throw underfoot::cli::UserError(
                fmt::format("--participants {}: the range is empty", text));
        for (int v = from; v <= to; v += step) out.push_back(v);
        if (out.back() != to) out.push_back(to);
    } else {
        std::size_t start = 0;
        while (start <= text.size()) {
            const auto comma = text.find(',', start);
            out.push_back(number(text.substr(start, comma - start)));
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
    }
    return out;
}

/// The published confusion matrices of the reference studies, by protocol and group.
std::map<std::string, std::string> publishedFiles(const std::string& protocolId) {
    if (protocolId == "tvcg2011_exp2")
        return {{"none", "tvcg2011_exp2_cond1_no_soundscape_confusion.csv"},
                {"coherent", "tvcg2011_exp2_cond2_coherent_confusion.csv"},
                {"incoherent", "tvcg2011_exp2_cond3_incoherent_confusion.csv"}};
    if (protocolId == "eurohaptics2010")
        return {{"audio", "eurohaptics2010_audio_confusion.csv"},
                {"haptic", "eurohaptics2010_haptic_confusion.csv"},
                {"audiohaptic", "eurohaptics2010_audiohaptic_confusion.csv"}};
    return {};
}

/// A participant's own matrix: the row's share of correct answers shifted by `ability` on the
/// logit scale (a row with every answer correct or none counts as half an answer off, so that it
/// can move), the wrong answers keeping their proportions: participants differ as real ones do.
ConfusionMatrix withAbility(const ConfusionMatrix& m, double ability) {
    if (ability == 0.0) return m;
    ConfusionMatrix out = m;
    for (auto& row : out.rows) {
        double correct = 0, total = 0;
        std::size_t rightColumn = row.counts.size(), wrongColumn = row.counts.size();
        for (std::size_t c = 0; c < row.counts.size(); ++c) {
            total += row.counts[c];
            const bool right = answerIsCorrect(m.answers[c], row.surface);
            if (right) correct += row.counts[c];
            if (right && rightColumn == row.counts.size()) rightColumn = c;
            if (!right && m.answers[c] == kDontKnow) wrongColumn = c;
        }
        if (total <= 0 || rightColumn == row.counts.size()) continue;
        const double p = std::clamp(correct / total, 0.5 / total, 1.0 - 0.5 / total);
        const double shifted = 1.0 / (1.0 + std::exp(-(std::log(p / (1 - p)) + ability)));
        const double wrong = total - correct;
        for (std::size_t c = 0; c < row.counts.size(); ++c) {
            const bool right = answerIsCorrect(m.answers[c], row.surface);
            if (right)
                row.counts[c] = correct > 0 ? row.counts[c] * shifted * total / correct : 0.0;
            else
                row.counts[c] = wrong > 0 ? row.counts[c] * (1 - shifted) * total / wrong : 0.0;
        }
        if (correct <= 0) row.counts[rightColumn] = shifted * total;
        if (wrong <= 0 && wrongColumn < row.counts.size())
            row.counts[wrongColumn] = (1 - shifted) * total;
    }
    return out;
}

/// --effect: "published" (the reference study's matrices, else the protocol's [simulation]
/// confusion matrices), or [GROUP=]FILE confusion matrices (published CSV format).
std::map<std::string, ConfusionMatrix> loadEffects(const PowerArgs& a, const Protocol& p) {
    std::map<std::string, ConfusionMatrix> matrices;
    for (const auto& spec : a.effect) {
        if (spec == "published") {
            const auto files = publishedFiles(p.id);
            if (files.empty()) {
                MatrixByGroup defaults;
                try {
                    defaults = defaultMatrices(p, a.file);
                } catch (const std::runtime_error& e) {
                    throw underfoot::cli::UserError(
                        fmt::format("--effect published: {}", e.what()));
                }
                if (defaults.empty())
                    throw underfoot::cli::UserError(fmt::format(
                        "--effect published: no published confusion matrices for protocol {} "
                        "(known: tvcg2011_exp2, eurohaptics2010, or a protocol naming them in "
                        "[simulation]); give --effect GROUP=FILE per group",
                        p.id));
                for (auto& [group, m] : defaults) matrices[group] = std::move(m);
                continue;
            }
            for (const auto& [group, name] : files) {
                try {
                    matrices[group] = loadConfusionMatrix(a.publishedDir + "/" + name);
                } catch (const std::runtime_error& e) {
                    throw underfoot::cli::UserError(
                        fmt::format("--effect published: {} (see --published-dir)", e.what()));
                }
            }
            continue;
        }
        const auto eq = spec.find('=');
        const std::string group = eq == std::string::npos ? "" : spec.substr(0, eq);
        const std::string path = eq == std::string::npos ? spec : spec.substr(eq + 1);
        if (!group.empty() && !p.group(group))
            throw underfoot::cli::UserError(
                fmt::format("--effect {}: '{}' is not a group of protocol {}", spec, group, p.id));
        try {
            matrices[group] = loadConfusionMatrix(path);
        } catch (const std::runtime_error& e) {
            throw underfoot::cli::UserError(fmt::format("--effect {}: {}", spec, e.what()));
        }
    }
    return matrices;
}

/// The matrix of group `g` (its own or the "" entry), checked against the protocol.
const ConfusionMatrix& matrixFor(const std::map<std::string, ConfusionMatrix>& matrices,
                                 const Protocol& p, const Group& g) {
    auto it = matrices.count(g.id) ? matrices.find(g.id) : matrices.find("");
    if (it == matrices.end())
        throw underfoot::cli::UserError(
            fmt::format("--effect: no confusion matrix for group '{}' (give {}=FILE)", g.id, g.id));
    Protocol one = p;
    one.groups = {g};
    if (auto problems = checkMatrixAgainst(it->second, one); !problems.empty())
        throw underfoot::cli::UserError(fmt::format("{}", fmt::join(problems, "\n")));
    return it->second;
}

underfoot::analysis::PowerOptions powerOptions(const PowerArgs& a) {
    underfoot::analysis::PowerOptions o;
    o.participantsPerGroup = parseSizes(a.participants);
    o.simulations = a.simulations;
    o.seed = a.seed;
    o.threads = a.threads;
    o.alpha = a.alpha;
    o.target = a.target;
    o.mixedModel = !a.noMixed;
    o.nAGQ = a.nAGQ;
    o.progress = [last = -1](std::size_t done, std::size_t total) mutable {
        const int percent = static_cast<int>(100 * done / total);
        if (percent == last) return;
        last = percent;
        const int width = 40, filled = percent * width / 100;
        fmt::print(stderr, "\r[{:<{}}] {:3d}% {} / {} studies",
                   std::string(static_cast<std::size_t>(filled), '#'), width, percent, done, total);
        if (done == total) fmt::print(stderr, "\n");
        std::fflush(stderr);
    };
    return o;
}

/// The power table, the smallest size reaching the target and the time taken.
void printCurve(const PowerArgs& a, const underfoot::analysis::PowerCurve& curve,
                const underfoot::analysis::PowerOptions& o, const std::string& sizeLabel,
                double seconds) {
    fmt::print("classic: {}\nmixed:   {}\n\n", curve.classicMethod,
               o.mixedModel ? curve.mixedMethod : std::string("(not fitted: --no-mixed)"));
    fmt::print("{:>12}  {:>7} {:>17} {:>17}", sizeLabel, "classic", "Wilson 95%",
               "Clopper-Pearson");
    if (o.mixedModel)
        fmt::print("  {:>7} {:>17} {:>17} {:>8}", "mixed", "Wilson 95%", "Clopper-Pearson",
                   "singular");
    fmt::print("\n");
    auto interval = [](const underfoot::analysis::Interval& i) {
        return fmt::format("[{:.3f}, {:.3f}]", i.lower, i.upper);
    };
    for (const auto& pt : curve.points) {
        fmt::print("{:>12}  {:>7.3f} {:>17} {:>17}", pt.participantsPerGroup, pt.classic.power,
                   interval(pt.classic.wilson), interval(pt.classic.clopperPearson));
        if (o.mixedModel)
            fmt::print("  {:>7.3f} {:>17} {:>17} {:>8}", pt.mixed.power, interval(pt.mixed.wilson),
                       interval(pt.mixed.clopperPearson), pt.mixedSingular);
        fmt::print("\n");
    }
    auto smallest = [&](int n) {
        return n < 0
                   ? fmt::format("none of the simulated sizes reaches {:g} %", 100 * a.target)
                   : fmt::format("{} participants{}", n,
                                 curve.groups > 0 && sizeLabel == "per group" ? " per group" : "");
    };
    fmt::print("\nsmallest {} reaching {:g} % power: classic test {}",
               sizeLabel == "per group" ? "group size" : "number of participants", 100 * a.target,
               smallest(curve.smallestClassic));
    if (o.mixedModel) fmt::print("; mixed model {}", smallest(curve.smallestMixed));
    fmt::print("\n({:.1f} s on {} thread(s))\n", seconds,
               a.threads ? a.threads : std::max(1u, std::thread::hardware_concurrency()));
}

/// Answers of participant `index` of a simulated study (plan from the study seed `seed`, the
/// participant's own draws from `ps`) by the experiment layer's synthetic answerer.
template <typename Emit>
void answerPlan(const Protocol& p, const Group& group, const ConfusionMatrix& matrix,
                double abilitySd, std::uint64_t seed, std::uint64_t ps, int index,
                const std::shared_ptr<const RatingModel>& ratingModel, Emit&& emit) {
    Rng abilityRng(deriveSeed(ps, {0xAB1E}));
    const ConfusionMatrix own =
        abilitySd > 0 ? withAbility(matrix, abilitySd * abilityRng.gaussian()) : matrix;
    SimulationSettings settings;
    settings.ratingModel = ratingModel;
    SimulatedParticipant answerer(own, p, group.id, deriveSeed(ps, {0xA5}), settings);
    if (ratingModel) { // participant fields uniformly among their options, as simulateStudy
        std::map<std::string, std::string> fields;
        Rng fieldRng(deriveSeed(ps, {0xF1E1D}));
        for (const auto& f : p.participantFields)
            fields[f.id] =
                f.options.empty()
                    ? std::string("simulated")
                    : f.options[static_cast<std::size_t>(fieldRng.below(f.options.size()))];
        answerer.setParticipant(deriveSeed(ps, {0xB1A5}), std::move(fields));
    }
    for (const auto& planned : generatePlan(p, group.id, seed, index)) {
        if (planned.practice) continue;
        TrialRecord trial;
        trial.index = planned.index;
        trial.block = planned.block;
        trial.stimulus = planned.stimulus;
        trial.repetition = planned.repetition;
        emit(planned, answerer.answer(trial));
    }
}

/// Rating protocols (no surface question): a within-subject comparison of two levels of a
/// factor on one scale, ratings from the protocol's rating model ([simulation]).
int runRatingPower(const PowerArgs& a, const Protocol& p) {
    std::string modelFile = a.ratingModel;
    if (modelFile.empty()) {
        if (p.simulation.ratingModel.empty())
            throw underfoot::cli::UserError(fmt::format(
                "{}: protocol {} asks no surface question and names no rating model in "
                "[simulation]; give --rating-model FILE (protocols/README.md, \"Rating models\")",
                a.file, p.id));
        try {
            modelFile = findProtocolFile(p, p.simulation.ratingModel, a.file);
        } catch (const std::runtime_error& e) {
            throw underfoot::cli::UserError(e.what());
        }
    }
    std::shared_ptr<RatingModel> model;
    try {
        model = std::make_shared<RatingModel>(loadRatingModel(modelFile));
    } catch (const ProtocolError& e) {
        throw underfoot::cli::UserError(e.what());
    }
    if (auto problems = checkRatingModel(*model, p); !problems.empty())
        throw underfoot::cli::UserError(fmt::format("{}", fmt::join(problems, "\n")));
    if (p.design != DesignKind::Within)
        throw underfoot::cli::UserError(fmt::format(
            "{}: rating power is computed for within-subject protocols; {} is between-subject",
            a.file, p.id));
    if (!a.groups.empty())
        throw underfoot::cli::UserError(fmt::format(
            "--groups: protocol {} rates within participants; choose what is compared with "
            "--scale, --factor and --levels",
            p.id));
    // the scale: --scale, else the protocol's first modelled scale
    const Scale* scale = nullptr;
    for (const auto& sc : p.questions.scales)
        if (a.scale.empty() ? model->scales.count(sc.id) > 0 : sc.id == a.scale) {
            scale = &sc;
            break;
        }
    if (!scale)
        throw underfoot::cli::UserError(
            a.scale.empty() ? fmt::format("{}: the rating model {} models no scale of protocol {}",
                                          a.file, modelFile, p.id)
                            : fmt::format("--scale {}: not a scale of protocol {} (scales: {})",
                                          a.scale, p.id, [&] {
                                              std::vector<std::string> ids;
                                              for (const auto& sc : p.questions.scales)
                                                  ids.push_back(sc.id);
                                              return fmt::format("{}", fmt::join(ids, ", "));
                                          }()));
    // the factor: --factor, else the first factor the model gives this scale an effect of, else
    // the first factor of the stimuli; levels in the order the stimuli declare them
    const auto& main = p.groups.front();
    const auto stimuli = groupStimuli(p, main);
    std::vector<std::string> factorNames;
    for (const auto& st : stimuli)
        for (const auto& [f, level] : st.factors)
            if (std::find(factorNames.begin(), factorNames.end(), f) == factorNames.end())
                factorNames.push_back(f);
    std::string factor = a.factor;
    if (factor.empty()) {
        const auto& effects = model->scales.at(scale->id).effects;
        for (const auto& f : factorNames)
            if (effects.count(f)) {
                factor = f;
                break;
            }
        if (factor.empty() && !factorNames.empty()) factor = factorNames.front();
    }
    if (factor.empty() ||
        std::find(factorNames.begin(), factorNames.end(), factor) == factorNames.end())
        throw underfoot::cli::UserError(fmt::format(
            "{}: {} (factors of the stimuli: {})", a.file,
            factor.empty() ? std::string("the stimuli have no factors to compare")
                           : fmt::format("--factor {}: no stimulus has this factor", factor),
            factorNames.empty() ? std::string("none")
                                : fmt::format("{}", fmt::join(factorNames, ", "))));
    std::vector<std::string> levels;
    for (const auto& st : stimuli)
        if (auto it = st.factors.find(factor);
            it != st.factors.end() &&
            std::find(levels.begin(), levels.end(), it->second) == levels.end())
            levels.push_back(it->second);
    std::vector<std::string> compared = a.levels;
    if (compared.empty() && levels.size() >= 2) compared = {levels[0], levels[1]};
    if (compared.size() != 2 || compared[0] == compared[1])
        throw underfoot::cli::UserError(
            fmt::format("--levels: two different levels of {} to compare expected (levels: {})",
                        factor, fmt::join(levels, ", ")));
    for (const auto& l : compared)
        if (std::find(levels.begin(), levels.end(), l) == levels.end())
            throw underfoot::cli::UserError(
                fmt::format("--levels: '{}' is not a level of {} (levels: {})", l, factor,
                            fmt::join(levels, ", ")));

    const ConfusionMatrix none;
    const std::string scaleId = scale->id;
    const underfoot::analysis::RatingStudySimulator simulate = [&](int participants,
                                                                   std::uint64_t seed) {
        std::vector<underfoot::analysis::SimulatedRating> ratings;
        for (int i = 0; i < participants; ++i) {
            const Group& g = p.groups[static_cast<std::size_t>(i) % p.groups.size()];
            answerPlan(p, g, none, 0.0, seed, deriveSeed(seed, {0, static_cast<std::uint64_t>(i)}),
                       i, model, [&](const PlannedTrial& planned, const TrialAnswer& answer) {
                           const auto level = planned.stimulus.factors.find(factor);
                           const auto rating = answer.ratings.find(scaleId);
                           if (level == planned.stimulus.factors.end() ||
                               rating == answer.ratings.end())
                               return;
                           const int condition = level->second == compared[0]   ? 0
                                                 : level->second == compared[1] ? 1
                                                                                : -1;
                           if (condition >= 0)
                               ratings.push_back({i, condition, double(rating->second)});
                       });
        }
        return ratings;
    };
    auto o = powerOptions(a);
    const auto started = std::chrono::steady_clock::now();
    const auto curve = underfoot::analysis::simulateRatingPower(simulate, o);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    fmt::print("power of {} — scale {}: {} {} vs {} within participants ({} simulated studies per "
               "size, seed {}, alpha {:g})\n",
               p.id, scaleId, factor, compared[0], compared[1], a.simulations, a.seed, a.alpha);
    fmt::print("ratings from the rating model {} (rounded and clamped to {}..{}, as a session "
               "stores them)\n",
               modelFile, scale->min, scale->max);
    printCurve(a, curve, o, "participants", seconds);
    return 0;
}

int runPower(const PowerArgs& a) {
    Protocol p;
    try {
        p = loadProtocol(a.file);
    } catch (const ProtocolError& e) {
        throw underfoot::cli::UserError(e.what());
    }
    if (!p.questions.asksSurface()) return runRatingPower(a, p);
    const auto matrices = loadEffects(a, p);
    const double sd = a.participantSd;
    auto o = powerOptions(a);
    std::vector<std::string> names;
    underfoot::analysis::StudySimulator simulate;
    std::string sizeLabel = "per group";
    std::vector<const Group*> groups;
    std::vector<const ConfusionMatrix*> byGroup;
    std::map<std::string, int> surfaceIndex;
    std::map<std::string, int> categoryIndex; // within: surface id -> compared category
    if (p.design == DesignKind::Within) {
        // one group of participants: the surface categories (solid, aggregate, ...) are
        // compared within participants, as the papers' category analyses
        if (!a.groups.empty())
            throw underfoot::cli::UserError(fmt::format(
                "--groups: protocol {} is within-subject; its surface categories are compared",
                p.id));
        std::vector<underfoot::analysis::SurfaceCategory> categories;
        for (const auto& st : groupStimuli(p, p.groups.front())) {
            const auto c = underfoot::analysis::surfaceCategory(st.surface);
            if (c != underfoot::analysis::SurfaceCategory::Unknown &&
                std::find(categories.begin(), categories.end(), c) == categories.end())
                categories.push_back(c);
        }
        std::sort(categories.begin(), categories.end());
        if (categories.size() < 2)
            throw underfoot::cli::UserError(fmt::format(
                "protocol {} is within-subject and its stimuli are of {} surface category; "
                "nothing to compare",
                p.id, categories.size()));
        for (const auto c : categories) names.emplace_back(underfoot::analysis::categoryName(c));
        for (const auto& st : groupStimuli(p, p.groups.front())) {
            const auto c = underfoot::analysis::surfaceCategory(st.surface);
            const auto it = std::find(categories.begin(), categories.end(), c);
            if (it != categories.end())
                categoryIndex[st.surface] = static_cast<int>(it - categories.begin());
        }
        for (const auto& g : p.groups) byGroup.push_back(&matrixFor(matrices, p, g));
        o.withSurface = false; // surfaces are nested in the categories
        sizeLabel = "participants";
        simulate = [&](int participants, std::uint64_t seed) {
            std::vector<underfoot::analysis::SimulatedAnswer> answers;
            for (int i = 0; i < participants; ++i) {
                const std::size_t gi = static_cast<std::size_t>(i) % p.groups.size();
                answerPlan(p, p.groups[gi], *byGroup[gi], sd, seed,
                           deriveSeed(seed, {0, static_cast<std::uint64_t>(i)}), i, nullptr,
                           [&](const PlannedTrial& planned, const TrialAnswer& answer) {
                               const auto c = categoryIndex.find(planned.stimulus.surface);
                               if (c == categoryIndex.end()) return;
                               underfoot::analysis::SimulatedAnswer out;
                               out.participant = i;
                               out.group = c->second;
                               out.correct =
                                   answerIsCorrect(answer.answer, planned.stimulus.surface);
                               answers.push_back(out);
                           });
            }
            return answers;
        };
    } else {
        for (const auto& g : p.groups)
            if (a.groups.empty() ||
                std::find(a.groups.begin(), a.groups.end(), g.id) != a.groups.end())
                groups.push_back(&g);
        for (const auto& id : a.groups)
            if (!p.group(id))
                throw underfoot::cli::UserError(
                    fmt::format("--groups: '{}' is not a group of protocol {}", id, p.id));
        if (groups.size() < 2)
            throw underfoot::cli::UserError(
                fmt::format("protocol {} has {} group(s) to compare; power needs at least two",
                            p.id, groups.size()));
        for (const Group* g : groups) {
            byGroup.push_back(&matrixFor(matrices, p, *g));
            names.push_back(g->id);
        }
        // surfaces as indices for the mixed model's surface factor
        for (const Group* g : groups)
            for (const auto& st : groupStimuli(p, *g))
                surfaceIndex.try_emplace(st.surface, static_cast<int>(surfaceIndex.size()));
        simulate = [&](int perGroup, std::uint64_t seed) {
            std::vector<underfoot::analysis::SimulatedAnswer> answers;
            int participant = 0;
            for (std::size_t gi = 0; gi < groups.size(); ++gi) {
                for (int i = 0; i < perGroup; ++i, ++participant) {
                    answerPlan(p, *groups[gi], *byGroup[gi], sd, seed,
                               deriveSeed(seed, {gi, static_cast<std::uint64_t>(i)}), i, nullptr,
                               [&](const PlannedTrial& planned, const TrialAnswer& answer) {
                                   underfoot::analysis::SimulatedAnswer out;
                                   out.participant = participant;
                                   out.group = static_cast<int>(gi);
                                   out.surface = surfaceIndex.at(planned.stimulus.surface);
                                   out.correct =
                                       answerIsCorrect(answer.answer, planned.stimulus.surface);
                                   answers.push_back(out);
                               });
                }
            }
            return answers;
        };
    }
    const auto started = std::chrono::steady_clock::now();
    const auto curve =
        underfoot::analysis::simulatePower(simulate, static_cast<int>(names.size()), o);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    fmt::print("power of {} — {} {} ({} simulated studies per size, seed {}, alpha {:g})\n", p.id,
               p.design == DesignKind::Within ? "surface categories (within participants)"
                                              : "groups",
               fmt::join(names, ", "), a.simulations, a.seed, a.alpha);
    fmt::print("answers from {}; participants differ: SD {:g} of ability on the logit scale\n",
               fmt::join(a.effect, ", "), sd);
    printCurve(a, curve, o, sizeLabel, seconds);
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "protocol", [](CLI::App& app, int& exitCode) {
        auto* cmd = app.add_subcommand("protocol", "Protocol files: validate and summarise");
        cmd->require_subcommand(1);
        auto* check = cmd->add_subcommand(
            "check", "Validate a protocol (every problem with file:line:column) and print the "
                     "plan summary: trials per participant, balance table, estimated duration");
        static std::string file;
        static std::uint64_t seed = 1;
        static int participants = 0;
        check->add_option("FILE", file, "protocol TOML file")->required();
        check->add_option("--seed", seed, "study seed for the balance table")->default_val(1);
        check
            ->add_option("--participants", participants,
                         "participants per group for the balance table (default: the group "
                         "target, else 20)")
            ->check(CLI::Range(0, 100000));
        auto* power = cmd->add_subcommand(
            "power", "How many participants: simulate whole studies (synthetic participants, "
                     "per-participant variability) and give the power of the classic test and of "
                     "the mixed model per group size, with Monte-Carlo intervals");
        static PowerArgs pa;
        power->add_option("FILE", pa.file, "protocol TOML file")->required();
        power->add_option("--effect", pa.effect,
                          "'published' (the reference study's confusion matrices) or "
                          "[GROUP=]FILE confusion matrix CSV per group (repeat)");
        power
            ->add_option("--participants", pa.participants,
                         "group sizes: FROM..TO (step 10), FROM..TO:STEP or a,b,c")
            ->capture_default_str();
        power->add_option("--simulations", pa.simulations, "simulated studies per group size")
            ->check(CLI::Range(1, 1000000))
            ->capture_default_str();
        power->add_option("--seed", pa.seed, "seed of the simulations")->capture_default_str();
        power->add_option("--threads", pa.threads, "worker threads (0 = all cores)")
            ->capture_default_str();
        power
            ->add_option("--participant-sd", pa.participantSd,
                         "SD of participants' ability on the logit scale (0 = identical)")
            ->check(CLI::Range(0.0, 10.0))
            ->capture_default_str();
        power->add_option("--alpha", pa.alpha, "significance level")
            ->check(CLI::Range(1e-6, 0.5))
            ->capture_default_str();
        power->add_option("--target", pa.target, "power to reach")
            ->check(CLI::Range(0.01, 0.999))
            ->capture_default_str();
        power->add_option("--groups", pa.groups, "compare only these groups (ids, comma separated)")
            ->delimiter(',');
        power->add_flag("--no-mixed", pa.noMixed, "classic test only (faster)");
        power->add_option("--nagq", pa.nAGQ, "quadrature points of the mixed model (1 = Laplace)")
            ->check(CLI::Range(1, 25))
            ->capture_default_str();
        power
            ->add_option("--published-dir", pa.publishedDir,
                         "folder of the published confusion matrices")
            ->capture_default_str();
        power->add_option("--rating-model", pa.ratingModel,
                          "rating protocols: rating model TOML (default: the protocol's "
                          "[simulation] rating_model)");
        power->add_option("--scale", pa.scale,
                          "rating protocols: the scale compared (default: the first modelled one)");
        power->add_option("--factor", pa.factor,
                          "rating protocols: the stimulus factor compared (default: the first the "
                          "model gives the scale an effect of)");
        power
            ->add_option("--levels", pa.levels,
                         "rating protocols: the two levels compared, A,B (default: the first two)")
            ->delimiter(',');
        power->callback([&exitCode] {
            try {
                exitCode = runPower(pa);
            } catch (const std::invalid_argument& e) {
                throw underfoot::cli::UserError(e.what());
            }
        });
        check->callback([&exitCode] {
            Protocol p;
            try {
                p = loadProtocol(file);
            } catch (const ProtocolError& e) {
                fmt::print(stderr, "{}\n", e.what());
                fmt::print(stderr, "underfoot: {} problem(s) in {}\n", e.problems().size(), file);
                exitCode = 2;
                return;
            }
            int n = participants;
            if (n == 0) {
                for (const auto& g : p.groups) n = std::max(n, g.target);
                if (n == 0) n = 20;
            }
            for (const auto& w : p.warnings) fmt::print(stderr, "{}\n", w.toString());
            // Check means runs: every distinct stimulus renders a short piece now, so that a
            // protocol that passes never fails at `clips`, `replay` or in a session.
            int rendered = 0;
            const auto problems = wiring::checkStimuliRender(p, 0.3, &rendered);
            if (!problems.empty()) {
                std::size_t causes = 0;
                for (const auto& line : problems) {
                    const bool more = line.rfind("  ", 0) == 0; // the stimuli a cause also stops
                    causes += more ? 0 : 1;
                    fmt::print(stderr, "{}{}\n", more ? "" : file + ": ", line);
                }
                fmt::print(stderr, "underfoot: {} stimulus problem{} in {}\n", causes,
                           causes == 1 ? "" : "s", file);
                exitCode = 2;
                return;
            }
            printSummary(p, seed, n);
            fmt::print("\nrenders: {} distinct stimulus render(s) made, every stimulus renders\n",
                       rendered);
            exitCode = 0;
        });
    }};

} // namespace
} // namespace underfoot::cli::protocol_command
