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
/// data/published/README.md; surface ids are accepted too). Throws std::runtime_error naming
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

/// Prefix of the control-stream reference a simulated participant's sensor trial stores in
/// place of a GRF recording: "virtual-walker:seconds=S" means that the participant's feet were
/// the stimulus's virtual walker (the engine's default walker for sensor stimuli) for S seconds
/// from the trial's render seed, which `underfoot replay` regenerates exactly.
inline constexpr std::string_view kSimulatedWalkerPrefix = "virtual-walker:seconds=";

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
