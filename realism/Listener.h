// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The project's listener: a nearest-centroid classifier trained on recorded footsteps only.
///
/// Each file (recording or render) becomes one feature vector: the median over its steps of
/// the scalar descriptors on their comparison scale (octaves, dB) and of the third-octave
/// envelope. Features are standardised with the training set's robust spread (IQR / 1.349,
/// pooled over all classes, with the descriptors' floors); the third-octave bands together
/// weigh as much as the scalar descriptors together. A file is given the material whose
/// centroid (per-dimension median of its training files) is nearest in Euclidean distance; its
/// category follows from the material. It is evaluated leave-one-source-out: trained on every
/// source but one, tested on the held-out source's files.
#include "realism/Descriptors.h"

#include <map>
#include <string>
#include <vector>

namespace underfoot::realism {

struct Example {
    std::string name, source, material; ///< material "" for an unlabelled (synthetic) file
    std::vector<double> features;
};

/// The feature vector of a file from its steps (all described with the same AnalysisOptions).
/// Throws std::invalid_argument when there are no steps.
std::vector<double> fileFeatures(const std::vector<StepDescriptors>& steps);

class Listener {
  public:
    /// Trains on labelled examples (at least one; all of the same length). Throws
    /// std::invalid_argument otherwise.
    void train(const std::vector<Example>& examples);
    /// The nearest material.
    std::string classify(const std::vector<double>& features) const;
    /// Distance to every trained material's centroid, nearest first.
    std::vector<std::pair<std::string, double>> distances(const std::vector<double>& f) const;
    const std::vector<std::string>& materials() const { return materials_; }

  private:
    std::vector<double> centre_, scale_, weight_;
    std::vector<std::string> materials_;
    std::vector<std::vector<double>> centroids_;
};

struct LosoResult {
    /// confusion[true material][predicted material] = count of held-out files
    std::map<std::string, std::map<std::string, int>> confusion;
    int files = 0;               ///< held-out files whose material some other source has
    int materialCorrect = 0;     ///< of those, named as their material
    int categoryCorrect = 0;     ///< of those, put in their category
    int unseenMaterialFiles = 0; ///< held-out files of a material no other source recorded
    std::map<std::string, std::pair<int, int>> perSource; ///< source -> (material ok, files)
};

/// Leave-one-source-out evaluation over labelled examples of two or more sources.
LosoResult leaveOneSourceOut(const std::vector<Example>& examples);

} // namespace underfoot::realism
