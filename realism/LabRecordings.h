// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A lab's own recorded footsteps in the recordings cache, as a source of their own beside the
/// packages scripts/fetch-recordings.sh fetches: the files are copied to
/// DIR/<source>/<material>/ and listed in DIR/lab-manifest.csv, which the script never rewrites.
/// Every figure of `underfoot compare` then counts the lab as one more independent source: the
/// nested listener holds it out like any package (docs/howto/judge-on-your-recordings.md).
#include "realism/Recordings.h"

#include <cstddef>
#include <string>
#include <vector>

namespace underfoot::realism {

/// What every file of one `addLabRecordings` call shares.
struct LabSource {
    std::string name;      ///< the source: lower-case letters, digits, '-' and '_', at most 40
    std::string material;  ///< one of knownMaterials()
    std::string licence;   ///< of the audio, e.g. "CC-BY-4.0" or "lab-internal"
    std::string recordist; ///< who recorded it (may be empty)
    std::string date;      ///< the manifest's version column (YYYY-MM-DD, the day it was added)
};

/// A file added to the cache: its manifest name (relative to the cache) and the steps found.
struct AddedRecording {
    std::string file;
    std::size_t steps = 0;
};

/// Copies audio files (named, or found below folders as collectRecordings does) into
/// DIR/<name>/<material>/ and lists them in DIR/lab-manifest.csv (written to a temporary file,
/// then renamed over the old one). Everything is checked before anything is written:
///  - the name: its characters, not a fetched source (fetchedSources), not "synthetic" (the
///    renders' source) or "user"; the material known; licence, recordist and date without
///    commas, quotes or line breaks, the licence and date not empty;
///  - every file: an audio file (.wav .ogg .flac .aiff) that reads (engine::FileError names
///    it) and holds at least one step at the default analysis (describeFile);
///  - no two files with one name, none already in the manifest or in the folder.
/// Throws std::invalid_argument (bad name, material, text or duplicate), std::runtime_error (a
/// file without steps, a missing path, a manifest that does not read) or engine::FileError,
/// each naming the file or value; the cache is then as it was.
std::vector<AddedRecording> addLabRecordings(const std::string& dir, const LabSource& source,
                                             const std::vector<std::string>& paths);

/// Removes a lab source: its rows of DIR/lab-manifest.csv and its folder DIR/<source>/.
/// Returns the number of files removed. Throws std::invalid_argument for a fetched source or a
/// source the lab's manifest does not list (naming the sources it lists).
std::size_t removeLabSource(const std::string& dir, const std::string& source);

/// One line per source of a cache: files per material, whether the fetch script or the lab
/// added it, and whether it is the unseen source.
struct SourceSummary {
    std::string source, package;
    bool lab = false, unseen = false;
    std::vector<std::pair<std::string, std::size_t>> files; ///< (material, files), by material
};
std::vector<SourceSummary> summariseSources(const std::vector<Recording>& recordings);

} // namespace underfoot::realism
