// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Listening tests: the clips of a protocol (rendered once from the protocol, or supplied by the
/// lab), their manifest, and a StimulusPlayer that presents them.
///
/// Rendering itself needs the engine, which experiment/ does not link: `underfoot clips` (app)
/// renders what clipJobs() lists and records it with writeClipManifest().
#include "experiment/Session.h"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::experiment {

/// Where a clip comes from.
enum class ClipSource { Wading, Footsteps, Lab };
const char* toString(ClipSource source);

/// One clip to render or to check.
struct ClipJob {
    Stimulus stimulus;
    ClipSource source = ClipSource::Lab;
    /// File path (clip folder + file name).
    std::string path;
    /// Render seed (rendered clips; lab clips: the same derivation, for the record).
    std::uint64_t seed = 0;
    /// Length to render (lab clips keep their own).
    double seconds = 0.0;
};

/// Every distinct clip of the protocol (main and practice stimuli), in protocol order.
/// Throws std::invalid_argument when the protocol is not a listening test ([clips] or `clip`).
std::vector<ClipJob> clipJobs(const Protocol& protocol, const std::string& clipDir);

/// A stimulus's parameters as text (numbers without trailing zeros: 27 -> "27"), as the
/// engine's option parsers take them.
std::map<std::string, std::string> parameterStrings(const Parameters& parameters);

/// One manifest row: what was written where, from what.
struct ClipRecord {
    std::string stimulusId;
    std::string file; ///< relative to the clip folder
    ClipSource source = ClipSource::Lab;
    std::uint64_t seed = 0;
    double seconds = 0.0;
    double sampleRateHz = 0.0;
    std::size_t frames = 0;
    std::string sha256;        ///< of the file's bytes
    std::string samplesSha256; ///< of its float32 samples (wiring::samplesSha256); "" in old
                               ///< manifests
};

/// The manifest file name inside a clip folder.
inline constexpr const char* kClipManifest = "clips.csv";
/// Writes `clipDir/clips.csv` (stimulus_id,file,source,seed,seconds,sample_rate_hz,frames,
/// sha256,samples_sha256); `seconds` is the file's length, frames / sample_rate_hz.
void writeClipManifest(const std::string& clipDir, const std::vector<ClipRecord>& records);
/// Reads `clipDir/clips.csv` (8 columns in manifests written before samples_sha256); an absent
/// manifest gives an empty list. Throws std::runtime_error naming file:line for a malformed one.
std::vector<ClipRecord> readClipManifest(const std::string& clipDir);
/// SHA-256 of a file's bytes (lower-case hex). Throws std::runtime_error when unreadable.
std::string fileSha256(const std::string& path);

/// Problems that stop a listening test from starting: lab-supplied clips missing (located in
/// the protocol file), rendered clips not yet rendered, or files changed since the manifest.
std::vector<std::string> checkClips(const Protocol& protocol, const std::string& clipDir);

/// Presents pre-rendered and lab-supplied clips. The audio itself is the application's: the
/// `play` callback receives each file path (the GUI and the terminal wire their audio output;
/// the web server and simulations pass none: the browser fetches the clip). Every start checks
/// the file against the manifest's SHA-256 (a replaced file is refused) and reports the clip's
/// seed from the manifest as the render seed, and the clip itself (StimulusStart::clip), which
/// the session stores with the trial.
class ClipPlayer final : public StimulusPlayer {
  public:
    using PlayFunction = std::function<void(const std::string& path)>;
    /// Throws StoreError listing checkClips() problems.
    ClipPlayer(const Protocol& protocol, std::string clipDir, PlayFunction play = {},
               std::function<void()> stop = {});
    StimulusStart start(const Stimulus& stimulus, std::uint64_t plannedSeed) override;
    void stop() override;
    /// Path of the clip presented last (empty before the first).
    const std::string& lastPath() const { return lastPath_; }
    /// Number of start() calls (first presentations and replays).
    int presentations() const { return presentations_; }
    /// The manifest row of a stimulus's clip (nullptr when absent).
    const ClipRecord* record(const std::string& stimulusId) const;
    const std::string& clipDir() const { return clipDir_; }

  private:
    const Protocol& protocol_;
    std::string clipDir_;
    PlayFunction play_;
    std::function<void()> stop_;
    std::map<std::string, ClipRecord> manifest_;
    std::string lastPath_;
    int presentations_ = 0;
};

} // namespace underfoot::experiment
