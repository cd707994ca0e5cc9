// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Synthetic participants answering from a confusion matrix, so that a whole study can be
/// produced end to end (CI, demos, analysis tests).
#include "experiment/Protocol.h"
#include "experiment/Random.h"
#include "experiment/RatingModel.h"
#include "experiment/Store.h"

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::experiment {

/// A confusion matrix: rows are presented stimuli (surface, optional soundscape), columns are
/// answer option ids, cells are counts.
struct ConfusionMatrix {
    struct Row {
        std::string surface;
        std::string soundscape; ///< empty when the matrix has no soundscape column
        std::vector<double> counts;
        int line = 0;
    };
    std::string source;
    std::vector<std::string> answers; ///< answer option ids (surface ids or dont_know)
    std::vector<Row> rows;
    bool hasSoundscape = false;

    /// The row for a stimulus, or nullptr.
    const Row* find(const Stimulus& stimulus) const;
};

/// Reads the published CSV format (`stimulus[,soundscape],CODE,...,DK`; codes as in
/// protocols/data/README.md; surface ids are accepted too). Throws std::runtime_error naming
/// file:line and what was expected.
ConfusionMatrix loadConfusionMatrix(const std::string& path,
                                    const Catalogue& catalogue = defaultCatalogue());
ConfusionMatrix parseConfusionMatrix(const std::string& text, const std::string& source,
                                     const Catalogue& catalogue = defaultCatalogue());

/// Checks that the matrix can drive `protocol`: a row for every stimulus and every answer
/// column with a count is an option of the answer list. Returns the problems.
std::vector<std::string> checkMatrixAgainst(const ConfusionMatrix& matrix,
                                            const Protocol& protocol);

/// Settings of synthetic participants.
struct SimulationSettings {
    /// Probability of naming the soundscape correctly when asked.
    double soundscapeAccuracy = 0.85;
    /// Median response time (log-normal, sigma 0.4).
    double medianResponseS = 8.0;
    /// How ratings depend on the stimulus (null: around the middle of each scale, half a point
    /// higher after a correct surface answer). Also gives the replay probability of clips.
    std::shared_ptr<const RatingModel> ratingModel;
    /// The clip folder of a listening test (from `underfoot clips`), when given: each simulated
    /// trial stores the manifest's clip (seed, length, samples' SHA-256) as a booth trial does,
    /// so its replay is checked against those samples. Empty: the clip as `underfoot clips`
    /// would render it at 48 kHz, without a samples hash.
    std::string clipDir;
};

/// One synthetic participant: draws answers from the matrix row of each stimulus.
class SimulatedParticipant {
  public:
    SimulatedParticipant(const ConfusionMatrix& matrix, const Protocol& protocol,
                         std::string groupId, std::uint64_t seed, SimulationSettings settings = {});
    /// An answer to a trial (surface answer from the matrix; ratings around the scale middle,
    /// half a point higher when correct; soundscape answer with the configured accuracy).
    TrialAnswer answer(const TrialRecord& trial);
    /// Response time for the last answer (seconds).
    double responseTimeS();
    /// Who this participant is for the rating model: a seed for its constant per-scale biases
    /// (the same in every session of the participant) and its participant-field answers.
    void setParticipant(std::uint64_t biasSeed, std::map<std::string, std::string> fields);

  private:
    const ConfusionMatrix& matrix_;
    const Protocol& protocol_;
    std::string groupId_;
    Rng rng_;
    SimulationSettings settings_;
    std::uint64_t biasSeed_ = 0;
    std::map<std::string, std::string> fields_;
    std::map<std::string, double> biases_;
};

} // namespace underfoot::experiment

namespace underfoot::experiment {

/// Prefix of the control-stream reference a simulated participant's sensor trial stored in
/// place of a GRF recording before the walker's parameters were stored (studies made then):
/// "virtual-walker:seconds=S" means that the participant's feet were the engine's default
/// virtual walker for S seconds from the trial's render seed.
inline constexpr std::string_view kSimulatedWalkerPrefix = "virtual-walker:seconds=";
/// Prefix of the readable control-stream reference of a simulated participant's sensor trial:
/// "virtual-walker: { seconds = 50, cadence = 104.3, mass = 71.2, shoe = 0.43, variability =
/// 0.031 }" — a TOML inline table with the virtual walker's parameters (the engine's names:
/// steps/min, kg, 0 soft .. 1 hard, relative std) that walked for this participant, for
/// `seconds`, from the trial's render seed. `underfoot replay` regenerates it from this text;
/// `underfoot export` shows it in audio.csv's grf_recording column.
inline constexpr std::string_view kSimulatedWalkerTablePrefix = "virtual-walker: ";

/// The feet of a simulated participant in sensor trials.
struct SimulatedWalker {
    double seconds = 0;
    /// cadence, mass, shoe, variability (numbers); empty: the engine's default walker (studies
    /// stored with the older "virtual-walker:seconds=S" reference).
    Parameters walker;
};

/// The walker of one simulated participant, drawn from `seed` (uniform: cadence 90–120
/// steps/min, mass 55–95 kg, shoe 0.2–0.8, variability 0.02–0.05; rounded to the digits the
/// stored text shows, so the text is exactly what walked), walking `seconds` per trial.
SimulatedWalker drawSimulatedWalker(std::uint64_t seed, double seconds);
/// The stored reference (kSimulatedWalkerTablePrefix + TOML inline table).
std::string formatSimulatedWalker(const SimulatedWalker& walker);
/// Reads a stored reference: nullopt when it is not a simulated walker's (a recording path);
/// throws std::invalid_argument naming what was expected for a malformed one.
std::optional<SimulatedWalker> parseSimulatedWalker(const std::string& reference);

/// Confusion matrices by group id; the entry "" is used for groups without their own.
using MatrixByGroup = std::map<std::string, ConfusionMatrix>;

/// Finds a file a protocol names by a relative path ([simulation]): beside `protocolFile` when
/// given, beside the protocol's source file, then in the shipped protocols folder. Throws
/// std::runtime_error naming the places looked at.
std::string findProtocolFile(const Protocol& protocol, const std::string& relative,
                             const std::string& protocolFile = {});
/// The confusion matrices the protocol names in [simulation] (empty when it names none).
/// Throws std::runtime_error naming the file when one cannot be read.
MatrixByGroup defaultMatrices(const Protocol& protocol, const std::string& protocolFile = {});

/// Called after each answer is durably committed (participant code, trial index).
using CommitCallback = std::function<void(const std::string&, int)>;

/// Runs (or resumes) one simulated participant's session with a synthetic answerer, from the
/// first unanswered trial (and lap) to the end. Returns the number of answers committed. Throws
/// StoreError for a real (not simulated) participant.
int runSimulatedSession(StudyStore& store, const std::string& code, const ConfusionMatrix& matrix,
                        std::uint64_t seed, const SimulationSettings& settings,
                        const CommitCallback& onCommitted = {});

/// Produces simulated participants: first finishes every unfinished simulated participant, then
/// registers new ones flagged `simulated` (codes `<prefix>001`, ...) with balanced assignment
/// until `participants` simulated participants have completed. Real participants are never
/// touched nor counted. Deterministic for a given study seed. Returns the number of answers.
int simulateStudy(StudyStore& store, const MatrixByGroup& matrices, int participants,
                  const SimulationSettings& settings, const std::string& codePrefix = "S",
                  const CommitCallback& onCommitted = {});

} // namespace underfoot::experiment
