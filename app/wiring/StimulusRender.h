// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The one offline stimulus renderer: what a participant hears from a stimulus (surface or
/// wading, its reverb, its soundscape at unity gain from the same seed, the output limiter),
/// driven by the stimulus's virtual walker or gait, or by a recorded GRF. Listening-test clips,
/// trial replays, simulated participants' trials and the console's previews all render here;
/// the live path builds the same scene from describeStimulus() (Players.h), and live trials
/// replay to its samples (docs/explanation/architecture.md, "Determinism and seeds").
///
/// A clip is the stimulus rendered to exactly `clip.seconds` (see docs/reference/protocol.md,
/// [clips]): the feet walk for the length minus a ring-out tail of min(1 s, a fifth of the
/// length), the soundscape plays throughout, and the last 20 ms fade out to silence, so the file
/// holds llround(seconds * rate) frames and the manifest's length is the file's.
#include "engine/control/GrfFile.h"
#include "engine/io/AudioFile.h"
#include "experiment/Protocol.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::wiring {

/// What drives a render. Without a GRF, the stimulus's own walker (or the default walker for a
/// sensor input) walks for `walkSeconds`; water stimuli use their virtual gait.
struct StimulusRender {
    experiment::Stimulus stimulus;
    std::uint64_t seed = 1;
    double sampleRateHz = 48000.0;
    int blockSize = 256;
    double walkSeconds = 10.0;
    /// A recorded (or simulated walker's) GRF instead of the stimulus's walker.
    const engine::GrfSignal* grf = nullptr;
    /// Render a clip of exactly this length (listening tests) instead of a walk plus a tail.
    std::optional<double> clipSeconds;
};

/// Renders a stimulus (stereo). Throws std::invalid_argument (walker keys, wading options),
/// PresetError / DefinitionError (surface, soundscape, impulse response) with the reason.
engine::AudioBuffer renderStimulus(const StimulusRender& request);

/// What `protocol check` and `study create` prove before a study starts: every distinct
/// stimulus (surface, soundscape, reverb, walker or wading settings, modalities) renders a short
/// piece (`seconds` of walking) through renderStimulus, and the shoes' GRF bank loads when a
/// stimulus is driven by force-sensing shoes. Lab-supplied clips are not rendered.
/// Returns one line per cause ("stimulus 'X' (gravel + forest) cannot be rendered: <why>"),
/// followed, when the same cause stops other stimuli, by an indented line naming them;
/// empty when every one renders; `rendered` (when given) receives the number of renders made.
std::vector<std::string> checkStimuliRender(const experiment::Protocol& protocol,
                                            double seconds = 0.3, int* rendered = nullptr);

/// The length of a clip in frames: llround(seconds * rate).
std::size_t clipFrames(double seconds, double sampleRateHz);

/// SHA-256 (lower-case hex) of a buffer's samples: the float32 values, interleaved, as
/// little-endian bytes. What the manifest and each clip trial store, and what replay compares.
std::string samplesSha256(const engine::AudioBuffer& audio);

} // namespace underfoot::wiring
