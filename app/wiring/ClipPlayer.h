// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Listening-test clips wired to the engine: rendering a protocol's clip folder (what
/// `underfoot clips` does, callable from the GUI's worker thread with progress) and playing one
/// clip file through a running LiveEngine.
///
/// Clip playback reuses the scene's ambience path (no new engine node): the scene is driven by a
/// silent external GRF (its surface voices stay asleep) and the clip is its stereo "ambience",
/// mixed into the headphone channels at unity gain with the engine's crossfade.
#include "engine/io/AudioFile.h"
#include "engine/scene/LiveEngine.h"
#include "experiment/Clips.h"

#include <functional>
#include <string>
#include <vector>

namespace underfoot::wiring {

/// Renders every clip of `protocol` into `clipDir` (lab-supplied clips are checked and
/// recorded), then writes the manifest. `progress(done, total, stimulusId)` is called before
/// each clip and once at the end; returning false stops (nothing written for the rest, no
/// manifest). Throws std::runtime_error naming the stimulus (and the protocol) on failure.
/// Returns the manifest rows (empty when stopped).
std::vector<experiment::ClipRecord> renderClipFolder(
    const experiment::Protocol& protocol, const std::string& clipDir, double sampleRateHz = 48000.0,
    const std::function<bool(int done, int total, const std::string& id)>& progress = {});

/// Plays clip files through a LiveEngine that the caller opened and started.
class ClipAudio {
  public:
    explicit ClipAudio(engine::LiveEngine& engine) : engine_(engine) {}
    ~ClipAudio();
    ClipAudio(const ClipAudio&) = delete;
    ClipAudio& operator=(const ClipAudio&) = delete;
    /// Loads `path` (resampled to the engine's rate) and plays it from the start, replacing a
    /// clip that plays. Throws engine::FileError / std::runtime_error with the reason.
    void play(const std::string& path);
    /// Fades the clip out (no-op when none plays).
    void stop();
    bool playing() const noexcept { return playing_; }
    /// Frames of the clip last loaded, at the engine's rate.
    std::size_t lastFrames() const noexcept { return lastFrames_; }

  private:
    engine::LiveEngine& engine_;
    bool playing_ = false;
    std::size_t lastFrames_ = 0;
};

} // namespace underfoot::wiring
