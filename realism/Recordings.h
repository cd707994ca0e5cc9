// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Recorded footsteps: the manifest written by scripts/fetch-recordings.sh, the material each
/// bundled surface is compared with, and loading recordings into per-step descriptors.
#include "realism/Descriptors.h"

#include <optional>
#include <string>
#include <vector>

namespace underfoot::realism {

struct Recording {
    std::string path;     ///< absolute path of the audio file
    std::string file;     ///< as named in the manifest (relative to the cache)
    std::string source;   ///< independent source (package or lab), e.g. "minetest"
    std::string package;  ///< Debian package (or "lab")
    std::string version;  ///< the package's version (a lab's recordings: the day they were added)
    std::string licence;  ///< SPDX-like licence of the audio
    std::string material; ///< wood, metal, hard, gravel, sand, snow, dirt, grass, ice, water
    std::string recordist;
};

/// Where the recordings cache is: $UNDERFOOT_RECORDINGS, else <source tree>/build/recordings for
/// a program of the build tree, else ~/.cache/underfoot/recordings (base::recordingsDirectory).
std::string defaultRecordingsDir();

/// Reads DIR/manifest.csv (the packages scripts/fetch-recordings.sh fetched, which it rewrites)
/// and then DIR/lab-manifest.csv (a lab's own recordings, realism/LabRecordings.h, which the
/// script never touches), each when present; the same columns in both. Throws
/// std::runtime_error naming the file and line when neither is there or one is malformed (a
/// line with the wrong number of columns, an empty field, or in the lab's manifest a source the
/// script fetches).
std::vector<Recording> loadManifest(const std::string& dir);

/// The header line of both manifests.
inline constexpr const char* kManifestHeader =
    "file,source,package,version,licence,material,recordist";

/// The sources scripts/fetch-recordings.sh fetches (and rewrites on every run).
const std::vector<std::string>& fetchedSources();

/// The sources `scripts/fetch-recordings.sh --unseen` adds (0 A.D.'s and Berusky 2's
/// footsteps): no preset is fitted or chosen on them, so `underfoot fit`, the preset search and
/// the realism tests leave them out of a cache's recordings; `underfoot compare` judges the
/// presets on them (docs/decisions/unseen-source.md).
const std::vector<std::string>& unseenSources();
bool isUnseenSource(const std::string& source);

/// The recordings without the unseen sources'.
std::vector<Recording> withoutUnseenSources(std::vector<Recording> recordings);

/// Audio files (.wav .ogg .flac .aiff) named directly or found below the given folders,
/// sorted; material and source unknown. Throws std::runtime_error for a path that does not exist.
std::vector<Recording> collectRecordings(const std::vector<std::string>& paths);

/// The recorded material a bundled surface is compared with ("" when none was recorded, e.g.
/// dry leaves, underbrush).
std::string materialOfSurface(const std::string& surfaceId);

/// "solid", "aggregate" or "liquid" for a recorded material; throws for an unknown one.
std::string categoryOfMaterial(const std::string& material);

/// The materials the listener knows, in a fixed order.
const std::vector<std::string>& knownMaterials();

/// Descriptors of every step of one recording file. Throws engine::FileError for a bad file.
std::vector<StepDescriptors> describeFile(const std::string& path, const AnalysisOptions& o);

/// The analysis band limit for a set of files: 0.95 x the lowest Nyquist among them and
/// `otherRateHz` (the synthetic render's rate), at most 16 kHz.
double sharedMaxHz(const std::vector<Recording>& recordings, double otherRateHz);

} // namespace underfoot::realism
