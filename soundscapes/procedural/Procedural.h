// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Factories of the procedural generators (internal to soundscapes/; use Generators.h).
#include "soundscapes/Generators.h"

namespace underfoot::soundscapes::procedural {

std::unique_ptr<BedGenerator> makeSea(const ParamSet& p);
std::unique_ptr<BedGenerator> makeWind(const ParamSet& p);
std::unique_ptr<BedGenerator> makeLeaves(const ParamSet& p);
std::unique_ptr<BedGenerator> makeTraffic(const ParamSet& p);
std::unique_ptr<BedGenerator> makeBabble(const ParamSet& p);
std::unique_ptr<BedGenerator> makeTractor(const ParamSet& p);
std::unique_ptr<BedGenerator> makeLift(const ParamSet& p);

std::unique_ptr<EventVoice> makeSongbird(const ParamSet& p);
std::unique_ptr<EventVoice> makeGull(const ParamSet& p);
std::unique_ptr<EventVoice> makeCuckoo(const ParamSet& p);
std::unique_ptr<EventVoice> makeWoodpecker(const ParamSet& p);
std::unique_ptr<EventVoice> makeHen(const ParamSet& p);
std::unique_ptr<EventVoice> makeRooster(const ParamSet& p);
std::unique_ptr<EventVoice> makeCow(const ParamSet& p);
std::unique_ptr<EventVoice> makeDog(const ParamSet& p);
std::unique_ptr<EventVoice> makeSwish(const ParamSet& p);
std::unique_ptr<EventVoice> makeScrape(const ParamSet& p);
std::unique_ptr<EventVoice> makeClank(const ParamSet& p);
std::unique_ptr<EventVoice> makeShout(const ParamSet& p);
std::unique_ptr<EventVoice> makeSkitter(const ParamSet& p);

} // namespace underfoot::soundscapes::procedural
