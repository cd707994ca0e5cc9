// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Soundscape definitions: the TOML file that says which layers an environment is made of.
///
/// ```toml
/// [soundscape]
/// id = "forest"                      # letters, digits, '_'
/// name = "Forest"
/// description = "Many songbirds, a cuckoo, a woodpecker, wind in the leaves"
/// target_level_dbfs = -32.0          # long-term RMS of the mix (mean of both channels)
/// footstep_reference_gain_db = -10.0 # soundscape level relative to the footsteps' reference
///
/// [[bed]]                            # a continuous layer, looped when from a file
/// name = "canopy"
/// generator = "leaves"               # or: file = "recordings/canopy.flac"
/// level_db = 0.0                     # balance: a bed's long-term level, an event's level while
///                                    # it sounds; the mix is then scaled to target_level_dbfs
/// crossfade_s = 2.0                  # loop crossfade (file beds)
/// params = { density = 1.5 }         # generator parameters (see `underfoot soundscape
/// generators`)
///
/// [[event]]                          # stochastic one-shot events
/// name = "cuckoo"
/// generator = "cuckoo"               # or: files = ["cuckoo1.wav", "cuckoo2.wav"]
/// level_db = -6.0
/// rate_per_minute = 1.5              # or: mean_interval_s = 40
/// jitter = 1.0                       # 1 = Poisson onsets, 0 = perfectly regular
/// gain_db = [-6.0, 0.0]              # per-event gain, uniform in dB
/// pan = [-0.8, 0.8]                  # per-event position, -1 left .. 1 right
/// max_voices = 2                     # overlapping events (extra onsets are dropped, counted)
/// first_onset_s = [1.0, 4.0]         # optional: the first event falls in this window
/// ```
/// Relative file paths are resolved against the definition's folder. Errors name the file,
/// line:column and what was expected; unknown keys are errors (a typo never goes unnoticed).
#include "soundscapes/Generators.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::soundscapes {

/// A definition file could not be read or is invalid; the message names file:line:column.
struct DefinitionError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Where the sound of a layer comes from.
enum class LayerSource { Procedural, Recording };

/// One layer of a soundscape.
struct LayerDefinition {
    std::string name;
    LayerKind kind = LayerKind::Bed;
    LayerSource source = LayerSource::Procedural;
    std::string generator;          ///< procedural generator name
    ParamSet params;                ///< its parameters (defaults resolved through the catalogue)
    std::vector<std::string> files; ///< recordings (absolute or as written when no folder)
    std::string location;           ///< "file:line:column" of the layer, for later error messages
    double levelDb = 0.0; ///< balance: beds' long-term level, events' level while sounding
    // Beds.
    double crossfadeSeconds = 2.0; ///< loop crossfade of file beds
    // Events.
    double ratePerMinute = 0.0; ///< mean event rate
    double jitter = 1.0;        ///< 0 regular .. 1 Poisson
    double gainDbMin = 0.0, gainDbMax = 0.0;
    double panMin = 0.0, panMax = 0.0;
    int maxVoices = 4;
    std::optional<std::pair<double, double>> firstOnsetSeconds;
};

/// One environment.
struct SoundscapeDefinition {
    std::string id;
    std::string name;
    std::string description;
    double targetLevelDbfs = -30.0;
    double footstepReferenceGainDb = -10.0;
    std::vector<LayerDefinition> layers;
    std::string sourcePath; ///< the file it was read from (empty when parsed from text)
};

/// Reads and validates a definition file. Throws DefinitionError.
SoundscapeDefinition loadSoundscapeDefinition(const std::string& path);

/// Parses definition text; `sourceName` is used in messages and `baseDirectory` resolves
/// relative recording paths (empty: paths are kept as written). Throws DefinitionError.
SoundscapeDefinition parseSoundscapeDefinition(std::string_view text, const std::string& sourceName,
                                               const std::string& baseDirectory = {});

} // namespace underfoot::soundscapes
