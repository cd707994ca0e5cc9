// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Re-rendering a stored trial: what `underfoot replay` writes and the console's Results view
/// plays. From the study: the stimulus, the render seed and the trial's recording — a GRF
/// (footsteps) or a gait (wading) recorded live, else the stimulus's virtual walker or gait —
/// rendered at the sample rate and block size the live engine ran at (read from the recording's
/// `.meters.toml`; the surfaces decide per block, so only the live block size reproduces a live
/// trial exactly), with the soundscape mixed in as the live scene mixed it.
#include "engine/io/AudioFile.h"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace underfoot::wiring {

/// A trial that cannot be re-rendered, or a broken file; the message says which and why.
class ReplayError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct ReplayRequest {
    std::string study;       ///< study file (.db)
    std::string participant; ///< participant code
    int trial = 0;           ///< trial index as stored (0-based; the export's trial_index);
                             ///< people read and type trial + 1 (`replay --trial`, messages)
    double walkSeconds = 10; ///< length when a virtual walker or gait drove the trial
    std::optional<double> sampleRateHz; ///< default: the live trial's, else 48 kHz
    std::optional<int> blockSize;       ///< default: the live trial's, else 256
    /// Clip folder, for trials that played a lab-supplied clip (default: the session's).
    std::string clipsDir;
};

struct ReplayRender {
    engine::AudioBuffer audio; ///< stereo
    std::string description;   ///< "P01 trial 3 (gravel + forest): 8.0 s from ..., seed ..."
    std::uint64_t seed = 0;
    double sampleRateHz = 0;
    int blockSize = 0;
    /// Listening-test trials: whether the samples are those of the clip the participant heard
    /// (SHA-256 stored with the trial); nullopt when the trial stored none.
    std::optional<bool> matchesHeard;
    std::string clipSha256; ///< the stored samples hash ("" when none)
};

/// What the live engine wrote next to a trial's recording, `<recording>.meters.toml`
/// (LivePlayer): the rate and block size the replay reproduces (absent or out of range: unset).
struct LiveMeters {
    std::optional<double> sampleRateHz;
    std::optional<int> blockSize;
};
/// Parses the text of a `.meters.toml` file; throws ReplayError naming `file`:line:column.
LiveMeters parseLiveMeters(const std::string& text, const std::string& file);

/// Renders one stored trial. A listening-test trial renders its clip again (the same stimulus,
/// seed and length through the one renderer) and says whether the samples are those heard.
/// Throws ReplayError with a message naming the study, the trial and what is missing (a live
/// sensor trial without recording, a lab-supplied clip without its folder, a bad file).
ReplayRender renderTrialReplay(const ReplayRequest& request);

} // namespace underfoot::wiring
