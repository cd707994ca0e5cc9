// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The impulse responses shipped in engine/data/ir/ (see engine/data/ir/README.md).
#include <string>
#include <vector>

namespace underfoot::engine {

/// Folder of the shipped IRs ($UNDERFOOT_IR_DIR, else as base::dataDirectory finds it).
std::string impulseResponseDirectory();

/// Names (file stems) of the .wav files in the IR folder, sorted.
std::vector<std::string> availableImpulseResponses();

/// Resolves a bare name ("wooden_room") to engine/data/ir/wooden_room.wav; a name with a folder
/// or an extension is taken as a path and must exist. Throws FileError (engine/io/AudioFile.h)
/// listing the available names when nothing matches.
std::string findImpulseResponse(const std::string& nameOrPath);

} // namespace underfoot::engine
