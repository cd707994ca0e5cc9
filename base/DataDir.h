// SPDX-License-Identifier: GPL-3.0-or-later
// Where the programs find the data they ship (surface presets, impulse responses, GRF banks,
// wading presets, soundscapes, protocols, the console's demo study) and the recorded footsteps
// fetched for the realism tools. One resolver for every library, in this bottom library
// (underfoot_base) that depends on nothing, so engine/, experiment/ and analysis/ keep no
// dependency on one another.
//
// Order, first match wins:
//   1. the kind's own environment variable (e.g. UNDERFOOT_SURFACES_DIR), when set and non-empty;
//   2. UNDERFOOT_DATA_DIR/<kind>, a whole installed data tree somewhere else;
//   3. <folder of the running program>/../share/underfoot/<kind> (an installed, relocatable copy:
//      /usr/bin/underfoot reads /usr/share/underfoot);
//   4. the source tree, when the running program was built in this build tree;
//   5. <install prefix>/share/underfoot/<kind> as configured, then /usr/share/underfoot/<kind>
//      and /usr/local/share/underfoot/<kind> (when /proc is not mounted, e.g. in a chroot).
// The installed layout is share/underfoot/{surfaces,ir,grf,wading,soundscapes,protocols,gui}.
#pragma once

#include <string>

namespace underfoot::base {

enum class DataKind {
    Surfaces,         ///< surface presets (*.toml); source: engine/data/surfaces
    ImpulseResponses, ///< room impulse responses (*.wav); source: engine/data/ir
    GrfBank,          ///< heel/toe GRF bank for the shoes (*.wav); source: engine/data/grf
    WadingPresets,    ///< shallow/deep wading presets; source: engine/data/wading
    Soundscapes,      ///< soundscape definitions; source: soundscapes/data
    Protocols,        ///< shipped protocols, data/ and simulation/; source: protocols
    GuiDemo,          ///< the console's demo protocol and matrices; source: app/gui/data
};

/// The folder holding one kind of shipped data (see the order above). When no candidate exists
/// the last one is returned, so that a message about a missing file names a real place.
std::string dataDirectory(DataKind kind);

/// The environment variable that overrides one kind (e.g. "UNDERFOOT_SURFACES_DIR").
const char* dataEnvironmentVariable(DataKind kind);

/// Where the recorded footsteps of scripts/fetch-recordings.sh are: UNDERFOOT_RECORDINGS when
/// set, <source tree>/build/recordings for a program of a build tree, otherwise
/// $XDG_CACHE_HOME/underfoot/recordings (~/.cache/underfoot/recordings).
std::string recordingsDirectory();

/// The running program's own path (/proc/self/exe), empty when it cannot be read.
std::string executablePath();

} // namespace underfoot::base
