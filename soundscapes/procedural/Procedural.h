// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Factories of the procedural generators (internal to soundscapes/; use Generators.h): each
/// makes one generator from its parameters; the catalogue in Generators.cpp names them.
#include "soundscapes/Generators.h"

namespace underfoot::soundscapes::procedural {

using BedFactory = std::unique_ptr<BedGenerator> (*)(const ParamSet&);
using VoiceFactory = std::unique_ptr<EventVoice> (*)(const ParamSet&);

extern const BedFactory makeSea;
extern const BedFactory makeWind;
extern const BedFactory makeLeaves;
extern const BedFactory makeTraffic;
extern const BedFactory makeBabble;
extern const BedFactory makeTractor;
extern const BedFactory makeLift;

extern const VoiceFactory makeSongbird;
extern const VoiceFactory makeGull;
extern const VoiceFactory makeCuckoo;
extern const VoiceFactory makeWoodpecker;
extern const VoiceFactory makeHen;
extern const VoiceFactory makeRooster;
extern const VoiceFactory makeCow;
extern const VoiceFactory makeDog;
extern const VoiceFactory makeSwish;
extern const VoiceFactory makeScrape;
extern const VoiceFactory makeClank;
extern const VoiceFactory makeShout;
extern const VoiceFactory makeSkitter;

} // namespace underfoot::soundscapes::procedural
