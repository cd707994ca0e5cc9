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
///
/// ListenerOptions (defaults = the configuration docs/explanation/realism.md reports): each
/// source's files are first centred on that source's own per-feature median (a source's microphone,
/// room and processing shift all its files alike; the held-out source, and the renders as a source
/// of their own, are centred on their own median, which needs no labels), only the scalar
/// descriptors are used, and there is one centroid per (source, material) rather than per
/// material, so two sources that recorded a material differently each keep their own.
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

struct Recording;

/// One labelled example per recording: its steps described with `o` (the band every file of a
/// comparison shares, sharedMaxHz), then fileFeatures. A file in which no step is found is left
/// out, and its manifest name appended to `silent` when given. Throws engine::FileError for an
/// unreadable file.
std::vector<Example> recordingExamples(const std::vector<Recording>& recordings,
                                       const AnalysisOptions& o,
                                       std::vector<std::string>* silent = nullptr);

struct ListenerOptions {
    bool centrePerSource = true;   ///< subtract each source's per-feature median first
    bool scalarsOnly = true;       ///< leave the third-octave envelope out
    bool centroidPerSource = true; ///< one centroid per (source, material)
};

/// Subtracts from every example its source's per-feature median (examples of one source with
/// no label, e.g. the renders, are centred the same way).
void centreBySource(std::vector<Example>& examples);

class Listener {
  public:
    explicit Listener(ListenerOptions o = {}) : opt_(o) {}
    /// Trains on labelled examples (at least one; all of the same length). Throws
    /// std::invalid_argument otherwise. Centring by source is the caller's (centreBySource);
    /// leaveOneSourceOut does it.
    void train(const std::vector<Example>& examples);
    /// The nearest material.
    std::string classify(const std::vector<double>& features) const;
    /// Distance to every trained material's centroid, nearest first.
    std::vector<std::pair<std::string, double>> distances(const std::vector<double>& f) const;
    const std::vector<std::string>& materials() const { return materials_; }

  private:
    ListenerOptions opt_;
    std::vector<double> centre_, scale_, weight_;
    std::vector<std::string> materials_;
    std::vector<std::string> centroidMaterial_; ///< material of each centroid
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
    std::map<std::string, int> perSourceCategory;         ///< source -> category ok

    /// Counts one held-out file of `source` (true `material`, heard as `heard`) in the totals,
    /// the confusion and the source's figures.
    void score(const std::string& source, const std::string& material, const std::string& heard);
};

/// Leave-one-source-out evaluation over labelled examples of two or more sources (centred by
/// source first when the options say so).
LosoResult leaveOneSourceOut(const std::vector<Example>& examples, ListenerOptions o = {});

/// The renders judged by a listener that never heard `heldOut`: trained on the other sources of
/// the labelled `recordings` (centred by source when the options say so), it classifies every
/// render of `renders` (one unlabelled source, centred on its own median when the options say
/// so); element i is the material heard in renders[i]. Throws std::invalid_argument with fewer
/// than two sources, no recording of `heldOut` or no render.
std::vector<std::string> heardWithoutSource(const std::vector<Example>& recordings,
                                            const std::vector<Example>& renders,
                                            const std::string& heldOut, ListenerOptions o = {});

/// The renders judged by listeners that never heard a source: for every source S of the
/// labelled `recordings` (two or more sources), a listener trained on the other sources only
/// (centred by source when the options say so) classifies every render of `renders` (one
/// unlabelled source, centred on its own median when the options say so). heard[S][i] is the
/// material heard in renders[i] without S. Throws std::invalid_argument with fewer than two
/// sources or no render.
std::map<std::string, std::vector<std::string>>
heardWithoutEachSource(const std::vector<Example>& recordings, const std::vector<Example>& renders,
                       ListenerOptions o = {});

/// Files of one material judged by a listener: how many, put in the material's category, named
/// as the material.
struct JudgedCounts {
    int files = 0;
    int categoryRight = 0;
    int materialRight = 0; ///< 0 when the listener does not know the material
    /// Counts one file of `material` heard as `heard`.
    void add(const std::string& material, const std::string& heard);
    bool operator==(const JudgedCounts&) const = default;
};

/// The recordings' side of the nested figures: every source S's own recordings judged by the
/// listener trained without S (the listener heardWithoutEachSource judges the renders with).
/// counts[S][material] covers every file of S, also those of a material no other source
/// recorded (their category can still be right; leaveOneSourceOut leaves them out), as the
/// renders' figures count such a source. A render cannot be asked to be heard in its category
/// more often than the held-out source's own recordings of its material are. Throws
/// std::invalid_argument with fewer than two sources.
std::map<std::string, std::map<std::string, JudgedCounts>>
heldOutRecordings(const std::vector<Example>& recordings, ListenerOptions o = {});

/// What one source alone teaches the listener (trainedOnEachSource), per material it recorded.
struct OneSourceFigures {
    std::map<std::string, JudgedCounts> recordings; ///< the other sources' recordings of it
    std::map<std::string, JudgedCounts> renders;    ///< the renders of it
    /// heard[i]: the material heard in renders[i], "" when the source did not record its
    /// material.
    std::vector<std::string> heard;
    bool operator==(const OneSourceFigures&) const = default;
};

/// The nested figures turned round: for every source S of the labelled `recordings` that
/// recorded two materials or more, a listener trained on S's recordings only (centred by source
/// when the options say so) judges the other sources' recordings of every material S recorded,
/// and every render whose material (renderMaterials[i], "" for none) S recorded (the renders
/// centred on their own median). It asks whether a render carries to a recordist as well as the
/// other recordists' footsteps do; for a source no preset was tuned on (the unseen source of
/// scripts/fetch-recordings.sh), that is the presets judged on recordings nobody fitted them
/// to. Throws std::invalid_argument with fewer than two sources, or when renders and
/// renderMaterials differ in length.
std::map<std::string, OneSourceFigures>
trainedOnEachSource(const std::vector<Example>& recordings, const std::vector<Example>& renders,
                    const std::vector<std::string>& renderMaterials, ListenerOptions o = {});

} // namespace underfoot::realism
