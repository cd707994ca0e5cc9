// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot protocol power FILE --effect ...`: how many participants. Whole studies are
// simulated by the experiment layer's synthetic participants and analysed by analysis/power.
#include "analysis/model/Catalog.h"
#include "analysis/power/Power.h"
#include "app/cli/CommandRegistry.h"
#include "app/cli/PowerSimulators.h"
#include "base/Plural.h"
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
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <thread>

namespace underfoot::cli::protocol_power_command {
namespace {

using namespace underfoot::experiment;
using namespace underfoot::cli::power;

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
    /// Folder of the [simulation] matrices; empty = where the protocol names them (beside the
    /// protocol file, then the shipped protocols folder).
    std::string publishedDir;
    std::string ratingModel; ///< rating protocols: the model (default: the protocol's [simulation])
    std::string scale;
    std::string factor;
    std::vector<std::string> levels;
    double oddsRatio = 0;       ///< > 0: the effect of --factor's second level as an odds ratio
    double baselineCorrect = 0; ///< identification at the first level (0 = from the matrices)
    double difference = std::numeric_limits<double>::quiet_NaN(); ///< ratings: effect in points
    bool noOrdinal = false;
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

/// --effect: "published" (the reference study's matrices, else the protocol's [simulation]
/// confusion matrices), or [GROUP=]FILE confusion matrices (published CSV format).
std::map<std::string, ConfusionMatrix> loadEffects(const PowerArgs& a, const Protocol& p) {
    std::map<std::string, ConfusionMatrix> matrices;
    for (const auto& spec : a.effect) {
        if (spec == "published") {
            MatrixByGroup defaults;
            try {
                if (a.publishedDir.empty()) {
                    defaults = defaultMatrices(p, a.file);
                } else {
                    for (const auto& [group, relative] : p.simulation.confusion) {
                        const auto slash = relative.find_last_of('/');
                        defaults[group] = loadConfusionMatrix(
                            a.publishedDir + "/" +
                            (slash == std::string::npos ? relative : relative.substr(slash + 1)));
                    }
                }
            } catch (const std::runtime_error& e) {
                throw underfoot::cli::UserError(
                    fmt::format("--effect published: {}{}", e.what(),
                                a.publishedDir.empty() ? "" : " (see --published-dir)"));
            }
            if (defaults.empty())
                throw underfoot::cli::UserError(fmt::format(
                    "--effect published: protocol {} names no published confusion matrices in "
                    "[simulation]; give --effect GROUP=FILE per group, or the effect of a factor "
                    "on identification as an odds ratio: --factor FACTOR --levels A,B "
                    "--odds-ratio OR [--baseline-correct P] (FACTOR a stimulus factor, or "
                    "'group' for between-participant groups)",
                    p.id));
            for (auto& [group, m] : defaults) matrices[group] = std::move(m);
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
    o.ordinalModel = !a.noOrdinal;
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
    fmt::print("classic: {}\nmixed:   {}\n", curve.classicMethod,
               o.mixedModel ? curve.mixedMethod : std::string("(not fitted: --no-mixed)"));
    if (curve.ordinal) fmt::print("ordinal: {}\n", curve.ordinalMethod);
    fmt::print("\n{:>12}  {:>7} {:>17} {:>17}", sizeLabel, "classic", "Wilson 95%",
               "Clopper-Pearson");
    if (o.mixedModel)
        fmt::print("  {:>7} {:>17} {:>17} {:>8}", "mixed", "Wilson 95%", "Clopper-Pearson",
                   "singular");
    if (curve.ordinal)
        fmt::print("  {:>7} {:>17} {:>17}", "ordinal", "Wilson 95%", "Clopper-Pearson");
    fmt::print("\n");
    auto interval = [](const underfoot::analysis::Interval& i) {
        return fmt::format("[{:.3f}, {:.3f}]", i.lower, i.upper);
    };
    int ordinalFailures = 0;
    for (const auto& pt : curve.points) {
        fmt::print("{:>12}  {:>7.3f} {:>17} {:>17}", pt.participantsPerGroup, pt.classic.power,
                   interval(pt.classic.wilson), interval(pt.classic.clopperPearson));
        if (o.mixedModel)
            fmt::print("  {:>7.3f} {:>17} {:>17} {:>8}", pt.mixed.power, interval(pt.mixed.wilson),
                       interval(pt.mixed.clopperPearson), pt.mixedSingular);
        if (curve.ordinal)
            fmt::print("  {:>7.3f} {:>17} {:>17}", pt.ordinal.power, interval(pt.ordinal.wilson),
                       interval(pt.ordinal.clopperPearson));
        ordinalFailures += pt.ordinalFailures;
        fmt::print("\n");
    }
    auto smallest = [&](int n) {
        return n < 0
                   ? fmt::format("none of the simulated sizes reaches {:g} %", 100 * a.target)
                   : fmt::format("{}{}", counted(n, "participant"),
                                 curve.groups > 0 && sizeLabel == "per group" ? " per group" : "");
    };
    fmt::print("\nsmallest {} reaching {:g} % power: classic test {}",
               sizeLabel == "per group" ? "group size" : "number of participants", 100 * a.target,
               smallest(curve.smallestClassic));
    if (o.mixedModel) fmt::print("; mixed model {}", smallest(curve.smallestMixed));
    if (curve.ordinal) fmt::print("; ordinal model {}", smallest(curve.smallestOrdinal));
    fmt::print("\n");
    if (ordinalFailures > 0)
        fmt::print("({} stopped and {} as not significant)\n", counted(ordinalFailures, "clmm fit"),
                   ordinalFailures == 1 ? "counts" : "count");
    fmt::print("({:.1f} s on {})\n", seconds,
               counted(a.threads ? a.threads : std::max(1u, std::thread::hardware_concurrency()),
                       "thread"));
}

/// Rating protocols (no surface question): a within-subject comparison of two levels of a
/// factor on one scale, ratings from the protocol's rating model ([simulation]).
int runRatingPower(const PowerArgs& a, const Protocol& p) {
    std::string modelFile = a.ratingModel;
    if (modelFile.empty()) {
        if (p.simulation.ratingModel.empty())
            throw underfoot::cli::UserError(
                fmt::format("{}: protocol {} asks no surface question and names no rating model in "
                            "[simulation]; give --rating-model FILE (docs/reference/protocol.md, "
                            "\"Rating models\")",
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

    // the effect, when given: the second level rated `shift` points above the first (the
    // compared stimuli's own effects dropped, the rest of the model as it is); an odds ratio of a
    // higher rating becomes points through the model's trial noise taken as a logistic variable (SD
    // noise: scale noise * sqrt(3) / pi)
    std::string effectText = "the rating model's effects";
    if (!std::isnan(a.difference) || a.oddsRatio > 0) {
        auto& sm = model->scales.at(scale->id);
        double shift = a.difference;
        if (std::isnan(shift)) {
            shift = std::log(a.oddsRatio) * sm.noiseSd * std::sqrt(3.0) / std::numbers::pi;
            effectText = fmt::format("odds ratio {:g} of a higher rating = {:.3g} points (noise "
                                     "SD {:g})",
                                     a.oddsRatio, shift, sm.noiseSd);
        } else {
            effectText = fmt::format("{:g} points (--difference)", shift);
        }
        auto& effect = sm.effects[factor];
        effect[compared[1]] = effect[compared[0]] + shift;
        // the compared stimuli lose their own effects: the levels then differ by `shift`
        for (const auto& st : stimuli)
            if (auto it = st.factors.find(factor);
                it != st.factors.end() && (it->second == compared[0] || it->second == compared[1]))
                sm.stimulusEffects.erase(st.id);
    }
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
               "stores them); effect: {}\n",
               modelFile, scale->min, scale->max, effectText);
    printCurve(a, curve, o, "participants", seconds);
    return 0;
}

/// The share of correct answers to `stimulus` in `m` (its row), NaN without a row.
double correctShare(const ConfusionMatrix& m, const Stimulus& stimulus) {
    const auto* row = m.find(stimulus);
    if (!row) return std::numeric_limits<double>::quiet_NaN();
    double correct = 0, total = 0;
    for (std::size_t c = 0; c < row->counts.size(); ++c) {
        total += row->counts[c];
        if (answerIsCorrect(m.answers[c], row->surface)) correct += row->counts[c];
    }
    return total > 0 ? correct / total : std::numeric_limits<double>::quiet_NaN();
}

/// Identification protocols, --odds-ratio: the effect of a factor (a stimulus factor within
/// participants, or "group" between them) on the odds of a correct answer. Every participant
/// answers each of its stimuli `repetitions` times; a trial is correct with probability
/// logistic(logit(p0) + ability + ln(OR) [second level]), p0 the stimulus's share of correct
/// answers in the protocol's [simulation] matrix (or --baseline-correct), ability ~ N(0, SD).
int runOddsRatioPower(const PowerArgs& a, const Protocol& p) {
    if (a.factor.empty())
        throw underfoot::cli::UserError(
            "--odds-ratio: name the factor whose effect it is, --factor FACTOR (a stimulus factor "
            "of the protocol, or 'group' for its between-participant groups)");
    const bool between = a.factor == "group";
    // levels: the groups, or the factor's levels in the order the stimuli declare them
    std::vector<std::string> levels;
    if (between) {
        for (const auto& g : p.groups) levels.push_back(g.id);
    } else {
        for (const auto& g : p.groups)
            for (const auto& st : groupStimuli(p, g))
                if (auto it = st.factors.find(a.factor);
                    it != st.factors.end() &&
                    std::find(levels.begin(), levels.end(), it->second) == levels.end())
                    levels.push_back(it->second);
        if (levels.empty())
            throw underfoot::cli::UserError(fmt::format(
                "--factor {}: no stimulus of protocol {} has this factor (give the stimuli "
                "factors = {{ {} = \"...\" }}, or --factor group for its groups)",
                a.factor, p.id, a.factor));
    }
    std::vector<std::string> compared = a.levels;
    if (compared.empty() && levels.size() >= 2) compared = {levels[0], levels[1]};
    if (compared.size() != 2 || compared[0] == compared[1])
        throw underfoot::cli::UserError(
            fmt::format("--levels: two different levels of {} to compare expected (levels: {})",
                        a.factor, fmt::join(levels, ", ")));
    for (const auto& l : compared)
        if (std::find(levels.begin(), levels.end(), l) == levels.end())
            throw underfoot::cli::UserError(
                fmt::format("--levels: '{}' is not a level of {} (levels: {})", l, a.factor,
                            fmt::join(levels, ", ")));
    if (between && p.design == DesignKind::Within)
        throw underfoot::cli::UserError(fmt::format(
            "--factor group: protocol {} is within-subject (one group); name a stimulus factor",
            p.id));
    // the baseline: the protocol's matrices (per stimulus) unless --baseline-correct is given
    MatrixByGroup matrices;
    if (a.baselineCorrect <= 0) {
        try {
            matrices = defaultMatrices(p, a.file);
        } catch (const std::runtime_error& e) {
            throw underfoot::cli::UserError(e.what());
        }
    }
    const double logOr = std::log(a.oddsRatio);
    struct Trial {
        int level = 0, surface = 0;
        double logit0 = 0;
    };
    std::map<std::string, int> surfaceIndex;
    std::vector<std::vector<Trial>> trialsOf; // per group of the protocol
    std::vector<int> usedGroups;              // groups whose participants are simulated
    std::string baseline =
        a.baselineCorrect > 0
            ? fmt::format("{:g} correct at every stimulus (--baseline-correct)", a.baselineCorrect)
            : std::string();
    for (std::size_t gi = 0; gi < p.groups.size(); ++gi) {
        const Group& g = p.groups[gi];
        std::vector<Trial> trials;
        int groupLevel = -1;
        if (between) {
            if (g.id == compared[0]) groupLevel = 0;
            if (g.id == compared[1]) groupLevel = 1;
            if (groupLevel < 0) {
                trialsOf.emplace_back();
                continue;
            }
        }
        const ConfusionMatrix* m = nullptr;
        if (!matrices.empty()) {
            // the first level's matrix is the baseline of both (the odds ratio is the effect)
            const std::string& source = between ? compared[0] : g.id;
            auto it = matrices.count(source) ? matrices.find(source) : matrices.find("");
            if (it == matrices.end()) it = matrices.begin();
            m = &it->second;
            baseline = fmt::format("each stimulus's share of correct answers in {}", m->source);
        }
        for (const auto& st : groupStimuli(p, g)) {
            if (st.practiceOnly) continue;
            int level = groupLevel;
            if (!between) {
                const auto it = st.factors.find(a.factor);
                if (it == st.factors.end()) continue;
                level = it->second == compared[0] ? 0 : it->second == compared[1] ? 1 : -1;
                if (level < 0) continue;
            }
            double p0 = a.baselineCorrect > 0 ? a.baselineCorrect : 0.5;
            if (m) {
                Stimulus reference = st;
                if (between) { // the same surface in the first level's matrix
                    reference.soundscape.reset();
                    for (const auto& row : m->rows)
                        if (row.surface == st.surface) {
                            if (!row.soundscape.empty()) reference.soundscape = row.soundscape;
                            break;
                        }
                }
                const double share = correctShare(*m, reference);
                if (std::isnan(share))
                    throw underfoot::cli::UserError(
                        fmt::format("{}: no row for stimulus {} ({}); give --baseline-correct P",
                                    m->source, st.id, st.surface));
                p0 = share;
            }
            const double total = 20; // a share of 0 or 1 moves by half an answer in 20
            p0 = std::clamp(p0, 0.5 / total, 1.0 - 0.5 / total);
            const int surface =
                surfaceIndex.try_emplace(st.surface, static_cast<int>(surfaceIndex.size()))
                    .first->second;
            for (int r = 0; r < std::max(1, p.ordering.repetitions); ++r)
                trials.push_back({level, surface, std::log(p0 / (1 - p0))});
        }
        if (!trials.empty()) usedGroups.push_back(static_cast<int>(gi));
        trialsOf.push_back(std::move(trials));
    }
    if (usedGroups.empty())
        throw underfoot::cli::UserError(
            fmt::format("protocol {}: no stimulus has level {} or {} of {}", p.id, compared[0],
                        compared[1], a.factor));
    const double sd = a.participantSd;
    auto o = powerOptions(a);
    const std::string sizeLabel = between ? "per group" : "participants";
    const underfoot::analysis::StudySimulator simulate = [&](int size, std::uint64_t seed) {
        std::vector<underfoot::analysis::SimulatedAnswer> answers;
        int participant = 0;
        // between: `size` participants in each compared group; within: `size` in all, spread
        // over the protocol's groups (orders) as sessions assign them
        const int total = between ? size * static_cast<int>(usedGroups.size()) : size;
        for (int i = 0; i < total; ++i, ++participant) {
            const int gi = between ? usedGroups[static_cast<std::size_t>(i / size)]
                                   : usedGroups[static_cast<std::size_t>(i) % usedGroups.size()];
            Rng rng(deriveSeed(seed, {static_cast<std::uint64_t>(i), 0x0DD5}));
            const double ability = sd > 0 ? sd * rng.gaussian() : 0.0;
            for (const Trial& t : trialsOf[static_cast<std::size_t>(gi)]) {
                const double eta = t.logit0 + ability + (t.level == 1 ? logOr : 0.0);
                underfoot::analysis::SimulatedAnswer out;
                out.participant = participant;
                out.group = t.level;
                out.surface = t.surface;
                out.correct = rng.uniform() < 1.0 / (1.0 + std::exp(-eta));
                answers.push_back(out);
            }
        }
        return answers;
    };
    const auto started = std::chrono::steady_clock::now();
    auto curve = underfoot::analysis::simulatePower(simulate, 2, o);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (!between) // the compared "groups" are the factor's levels
        for (std::string* text : {&curve.classicMethod, &curve.mixedMethod})
            for (const std::string from : {"~ group", "groups x", "test of group"})
                if (const auto at = text->find(from); at != std::string::npos)
                    text->replace(at + from.size() - 5, 5, a.factor);
    fmt::print("power of {} — identification, {} {} vs {} {} participants: odds ratio {:g} ({} "
               "simulated studies per size, seed {}, alpha {:g})\n",
               p.id, a.factor, compared[0], compared[1], between ? "between" : "within",
               a.oddsRatio, a.simulations, a.seed, a.alpha);
    fmt::print("baseline at {}: {}; participants differ: SD {:g} of ability on the logit scale\n",
               compared[0], baseline, sd);
    printCurve(a, curve, o, sizeLabel, seconds);
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
    if (!std::isnan(a.difference))
        throw underfoot::cli::UserError(fmt::format(
            "--difference: protocol {} asks which surface; give the effect on identification as "
            "--odds-ratio OR",
            p.id));
    if (a.oddsRatio > 0) return runOddsRatioPower(a, p);
    if (!a.factor.empty() || !a.levels.empty())
        throw underfoot::cli::UserError(fmt::format(
            "--factor/--levels: protocol {} asks which surface; compare the levels of a factor "
            "with --odds-ratio OR (the effect of the second level on the odds of a correct answer)",
            p.id));
    const auto matrices = loadEffects(a, p);
    const double sd = a.participantSd;
    auto o = powerOptions(a);
    std::vector<std::string> names;
    underfoot::analysis::StudySimulator simulate;
    std::string sizeLabel = "per group";
    std::vector<const Group*> groups;
    std::vector<const ConfusionMatrix*> byGroup;
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
                fmt::format("protocol {} has {} to compare; power needs at least two", p.id,
                            counted(groups.size(), "group")));
        for (const Group* g : groups) {
            byGroup.push_back(&matrixFor(matrices, p, *g));
            names.push_back(g->id);
        }
        simulate = betweenGroupsSimulator(p, groups, byGroup, sd);
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

/// Registered after "protocol" (the registry is sorted by name): adds `power` to it.
const underfoot::cli::CommandRegistrar registrar{
    "protocol power", [](CLI::App& app, int& exitCode) {
        auto* cmd = app.get_subcommand("protocol");
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
        power->add_option("--published-dir", pa.publishedDir,
                          "folder to read the [simulation] confusion matrices from (default: "
                          "where the protocol names them: beside it, then the shipped "
                          "protocols' data folder)");
        power
            ->add_option("--odds-ratio", pa.oddsRatio,
                         "the effect of --factor's second level against its first as an odds "
                         "ratio: of a correct answer (identification protocols; --factor group "
                         "compares groups) or of a higher rating (rating protocols)")
            ->check(CLI::Range(1e-6, 1e6));
        power
            ->add_option("--baseline-correct", pa.baselineCorrect,
                         "with --odds-ratio: share of correct answers at the first level "
                         "(default: each stimulus's share in the protocol's [simulation] "
                         "matrices, else 0.5)")
            ->check(CLI::Range(0.001, 0.999));
        power->add_option("--difference", pa.difference,
                          "rating protocols: the second level rated this many scale points above "
                          "the first (overrides the rating model's effect of --factor)");
        power->add_flag("--no-ordinal", pa.noOrdinal,
                        "rating protocols: no cumulative link mixed model (faster)");
        power->add_option("--rating-model", pa.ratingModel,
                          "rating protocols: rating model TOML (default: the protocol's "
                          "[simulation] rating_model)");
        power->add_option("--scale", pa.scale,
                          "rating protocols: the scale compared (default: the first modelled one)");
        power->add_option("--factor", pa.factor,
                          "the stimulus factor compared (rating protocols default: the first the "
                          "model gives the scale an effect of; with --odds-ratio, 'group' for "
                          "the groups)");
        power
            ->add_option("--levels", pa.levels,
                         "the two levels compared, A,B (default: the first two)")
            ->delimiter(',');
        power->callback([&exitCode] {
            try {
                exitCode = runPower(pa);
            } catch (const std::invalid_argument& e) {
                throw underfoot::cli::UserError(e.what());
            }
        });
    }};

} // namespace
} // namespace underfoot::cli::protocol_power_command
