// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The listener on onset features (docs/explanation/realism.md, "The listener"): trained on
/// recorded footsteps only, meant to name the material and category of a file from a source it
/// never saw (another library, a lab, the renders).
///
/// Every step of a file is described by the 14 scalar descriptors (realism/Descriptors.h, on
/// their comparison scale) and the onset features (realism/OnsetFeatures.h); a file's vector is
/// the per-feature median over its steps. Each source (a package, a lab, the renders) is first
/// normalised on its own files without labels: centred on its per-feature median, and
/// optionally divided by its per-feature robust spread. Features are then standardised by the
/// training set's robust spread (IQR / 1.349, with each feature's floor). A configuration
/// chooses the features (onset, onset + scalars, scalars), the per-source normalisation and
/// the decision:
///  - centroid: nearest (source, material) centroid (per-feature median of its files);
///  - hierarchical: the category of the nearest (source, category) centroid first, then the
///    nearest (source, material) centroid within that category;
///  - 3-nn: the commonest material among the 3 nearest training files (ties: the nearest);
///  - step vote: every step is given the material of its nearest (source, material) centroid;
///    the file gets the commonest (ties: the smaller summed distance).
/// The configuration is chosen by leave-one-source-out on the training sources only;
/// nestedLeaveOneSourceOut() scores that whole procedure on each held-out source in turn.
#include "realism/Listener.h"

#include <map>
#include <string>
#include <vector>

namespace underfoot::realism {

/// One file as the listener sees it.
struct ListenerFile {
    std::string name, source, material;     ///< material "" for an unlabelled (synthetic) file
    std::vector<std::vector<double>> steps; ///< per step: the scalars then the onset features
};

/// Number of features per step (kDescriptorCount scalars + onset features).
std::size_t listenerFeatureCount();
/// Key of feature k (descriptor keys, then onset feature keys).
std::string listenerFeatureKey(std::size_t k);

/// Describes every step of a buffer (steps silent in the analysed band are left out). Throws
/// std::invalid_argument when no step is left.
ListenerFile describeListenerFile(const std::string& name, const std::string& source,
                                  const std::string& material, const engine::AudioBuffer& audio,
                                  const AnalysisOptions& o);

enum class FeatureSet { Onset, OnsetAndScalars, Scalars };
enum class Decision { Centroid, Hierarchical, NearestNeighbours, StepVote };

struct ListenerConfig {
    FeatureSet features = FeatureSet::Onset;
    bool standardisePerSource = false; ///< divide by each source's spread after centring it
    Decision decision = Decision::Centroid;
    std::string name() const;
    bool operator==(const ListenerConfig&) const = default;
};

/// The fixed grid the configuration is chosen from (3 feature sets x 2 normalisations x 4
/// decisions). Includes the previous default listener: scalars, centred, centroid.
std::vector<ListenerConfig> listenerGrid();

/// Centres (and with `standardise` scales) every file's steps by its source's per-feature
/// median (and robust spread, with the features' floors) of the files' medians.
void normaliseBySource(std::vector<ListenerFile>& files, bool standardise);

class OnsetListener {
  public:
    explicit OnsetListener(ListenerConfig c) : cfg_(c) {}
    /// Trains on labelled, source-normalised files. Throws std::invalid_argument when there
    /// are none or one has no label or steps of another length.
    void train(const std::vector<ListenerFile>& files);
    /// The material heard in a (source-normalised) file.
    std::string classify(const ListenerFile& file) const;
    const std::vector<std::string>& materials() const { return materials_; }

  private:
    std::vector<double> select(const std::vector<double>& v) const; // chosen, standardised
    std::pair<std::string, double> nearest(const std::vector<double>& z,
                                           const std::string& category) const;
    ListenerConfig cfg_;
    std::vector<std::size_t> features_;
    std::vector<double> centre_, scale_;
    std::vector<std::string> materials_;
    struct Centroid {
        std::string material, category;
        std::vector<double> z;
    };
    std::vector<Centroid> centroids_, categoryCentroids_;
    std::vector<std::pair<std::string, std::vector<double>>> train_; // material, z (3-nn)
};

/// Leave-one-source-out of one configuration over labelled files of two or more sources (the
/// files are normalised by source first, as the configuration says).
LosoResult leaveOneSourceOut(const std::vector<ListenerFile>& files, const ListenerConfig& c);

struct NestedResult {
    LosoResult heldOut; ///< every held-out source scored with the configuration chosen without it
    std::map<std::string, ListenerConfig> chosen; ///< held-out source -> chosen configuration
};

/// Chooses the grid's best configuration by leave-one-source-out (most categories right, then
/// most materials, then the earlier in the grid).
ListenerConfig chooseConfig(const std::vector<ListenerFile>& files,
                            const std::vector<ListenerConfig>& grid);

/// The honest estimate for an unseen source: for each source, the configuration is chosen on
/// the other sources only (chooseConfig over them, which needs three or more), then trained on
/// them and scored on the held-out source.
NestedResult nestedLeaveOneSourceOut(const std::vector<ListenerFile>& files,
                                     const std::vector<ListenerConfig>& grid);

} // namespace underfoot::realism
