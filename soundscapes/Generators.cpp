// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Generators.h"

#include "soundscapes/procedural/Procedural.h"

#include <algorithm>
#include <stdexcept>
#include <variant>

namespace underfoot::soundscapes {
namespace {

using procedural::BedFactory;
using procedural::VoiceFactory;

// One generator: what the catalogue says about it and its factory (which also gives its kind).
struct Entry {
    GeneratorInfo info;
    std::variant<BedFactory, VoiceFactory> make;
};

Entry entry(std::string name, std::string description, std::vector<ParamInfo> params,
            std::variant<BedFactory, VoiceFactory> make) {
    const LayerKind kind =
        std::holds_alternative<BedFactory>(make) ? LayerKind::Bed : LayerKind::Event;
    return {{std::move(name), kind, std::move(description), std::move(params)}, make};
}

const std::vector<Entry>& entries() {
    using namespace procedural;
    static const std::vector<Entry> all = [] {
        std::vector<Entry> e{
            entry("sea",
                  "Waves and surf: pink noise through a low-pass opened by each swell, high-passed "
                  "foam as it breaks, right channel a little behind the left.",
                  {{"wave_period_s", 9.0, 3.0, 30.0, "mean time between waves"},
                   {"brightness_hz", 1500.0, 200.0, 8000.0, "low-pass opening at a wave's crest"},
                   {"foam", 0.5, 0.0, 1.0, "level of the breaking foam"}},
                  makeSea),
            entry("wind",
                  "Wind: white noise through a band-pass whose centre and level follow slow random "
                  "gusts, with a low rumble and an optional whistle in strong gusts.",
                  {{"centre_hz", 400.0, 80.0, 4000.0, "centre of the wind band"},
                   {"gustiness", 0.6, 0.0, 1.0, "depth of the gust modulation"},
                   {"whistle", 0.2, 0.0, 1.0, "level of the narrow whistle band"}},
                  makeWind),
            entry(
                "leaves",
                "Wind in leaves / rustling: Poisson clicks of leaf contacts, their rate following "
                "the square of the gusts, ringing two broad bands, plus a breathy hiss.",
                {{"density", 1.0, 0.05, 5.0,
                  "click rate scale (1 = about 1800 clicks/s in a "
                  "full gust)"},
                 {"brightness_hz", 3500.0, 800.0, 10000.0, "centre of the upper band"},
                 {"gustiness", 0.7, 0.0, 1.0, "depth of the gust modulation"}},
                makeLeaves),
            entry(
                "traffic",
                "Distant traffic: low-passed brown-noise rumble plus passing cars (Gaussian swells "
                "of rumble and tyre hiss travelling across the stereo field).",
                {{"cars_per_minute", 12.0, 0.0, 200.0, "mean rate of passing cars (Poisson)"},
                 {"cutoff_hz", 350.0, 60.0, 3000.0, "distance low-pass of the rumble"},
                 {"hiss", 0.3, 0.0, 1.0, "level of the tyre hiss"}},
                makeTraffic),
            entry("babble",
                  "Distant voices: talkers made of a sawtooth glottal source and two formants "
                  "changing per syllable, speaking in utterances and pauses, low-passed by "
                  "distance. High pitch and excitement give children at play.",
                  {{"talkers", 4.0, 1.0, 12.0, "number of simultaneous talkers"},
                   {"pitch_hz", 160.0, 70.0, 450.0, "mean voice pitch"},
                   {"syllable_rate_hz", 4.0, 1.0, 8.0, "syllables per second"},
                   {"distance_hz", 2000.0, 300.0, 10000.0, "distance low-pass"},
                   {"activity", 0.6, 0.05, 0.95, "fraction of time each talker speaks"},
                   {"excitement", 0.2, 0.0, 1.0, "accents and pitch leaps (shouts, play)"}},
                  makeBabble),
            entry("tractor",
                  "Distant tractor: a four-cylinder diesel buzz at rpm/30 Hz with a half-rate "
                  "sub-harmonic and firing-gated combustion noise, low-passed by distance, moving "
                  "slowly around.",
                  {{"rpm", 1400.0, 500.0, 2600.0, "engine speed"},
                   {"distance_hz", 700.0, 100.0, 5000.0, "distance low-pass"},
                   {"drift", 0.5, 0.0, 1.0, "how much level and position wander"}},
                  makeTractor),
            entry("lift",
                  "Chairlift machinery: drive hum (fundamental and two harmonics), cable rumble "
                  "over the sheaves, a faint sheave whine.",
                  {{"hum_hz", 70.0, 30.0, 250.0, "drive hum fundamental"},
                   {"squeal", 0.3, 0.0, 1.0, "level of the sheave whine"}},
                  makeLift),
            entry("songbird",
                  "Songbirds: a repertoire of `species` songs (3-8 sine glides, some trilled) "
                  "drawn from the layer seed; each event sings one song 1-3 times.",
                  {{"species", 6.0, 1.0, 12.0, "number of different songs in the population"},
                   {"pitch_hz", 3500.0, 800.0, 8000.0, "typical note pitch"}},
                  makeSongbird),
            entry("gull",
                  "Gull: 2-6 harsh 'kyow' calls, a sawtooth leaping up then falling, through "
                  "nasal formants near 1.8 and 3.2 kHz.",
                  {{"pitch_hz", 850.0, 300.0, 2000.0, "call pitch"}}, makeGull),
            entry("cuckoo",
                  "Cuckoo: 3-9 'cu-coo' pairs about a second apart, the second note a third "
                  "below the first.",
                  {{"pitch_hz", 720.0, 400.0, 1200.0, "pitch of the first note"}}, makeCuckoo),
            entry("woodpecker",
                  "Woodpecker drumming: 10-24 knocks at about 18 Hz into four wood modes.",
                  {{"base_hz", 1100.0, 300.0, 4000.0, "lowest mode of the trunk"},
                   {"rate_hz", 18.0, 8.0, 30.0, "knocks per second"}},
                  makeWoodpecker),
            entry("hen",
                  "Hen: 3-8 clucks with falling pitch through two formants, sometimes a "
                  "'ba-GAWK'.",
                  {{"pitch_hz", 380.0, 150.0, 900.0, "cluck pitch"}}, makeHen),
            entry("rooster",
                  "Rooster crow: four rising syllables, the last long and falling, with vibrato "
                  "and changing vowels.",
                  {{"pitch_hz", 550.0, 250.0, 1000.0, "starting pitch"}}, makeRooster),
            entry("cow",
                  "Cow: a 1.2-2.4 s 'moo', low pitch rising then sinking while the mouth opens "
                  "and closes (moving formants).",
                  {{"pitch_hz", 125.0, 60.0, 250.0, "voice pitch"}}, makeCow),
            entry("dog",
                  "Dog: 1-7 barks of 90-180 ms, falling pitch, noisy source through two "
                  "formants.",
                  {{"pitch_hz", 480.0, 150.0, 1000.0, "bark pitch (lower = bigger dog)"}}, makeDog),
            entry("shout",
                  "A distant call or a child's shout: 2-5 syllables with exaggerated contours "
                  "and random vowels, low-passed by distance.",
                  {{"pitch_hz", 260.0, 80.0, 600.0, "voice pitch"},
                   {"distance_hz", 3000.0, 300.0, 12000.0, "distance low-pass"}},
                  makeShout),
            entry("swish",
                  "Ski swish: 1-4 turns of noise through a band sweeping up and back, with "
                  "granular flutter and a low carving component.",
                  {{"brightness_hz", 1800.0, 400.0, 6000.0, "centre of the swish band"},
                   {"turns_max", 3.0, 1.0, 8.0, "most turns in one event"}},
                  makeSwish),
            entry("scrape",
                  "Ski edge scraping ice: noise through two narrow chattering resonances over a "
                  "broadband hiss.",
                  {{"brightness_hz", 2600.0, 600.0, 8000.0, "main resonance"}}, makeScrape),
            entry("clank",
                  "Chairlift pylon clank: two metallic knocks into four free-bar modes and a low "
                  "thump.",
                  {{"base_hz", 420.0, 80.0, 3000.0, "lowest metal mode"}}, makeClank),
            entry("skitter",
                  "Leaves skittering along a path: a 0.4-1.5 s burst of dry crackles (short noise "
                  "grains).",
                  {{"brightness_hz", 4000.0, 800.0, 10000.0, "centre of the click band"}},
                  makeSkitter),
        };
        std::sort(e.begin(), e.end(),
                  [](const Entry& a, const Entry& b) { return a.info.name < b.info.name; });
        return e;
    }();
    return all;
}

// Makes the generator of that name with a Factory of that kind (a bed or an event voice), its
// parameters falling back to the catalogue's defaults.
template <class Factory>
auto make(std::string_view name, const ParamSet& params, std::string_view kind) {
    for (const auto& e : entries()) {
        const Factory* f = e.info.name == name ? std::get_if<Factory>(&e.make) : nullptr;
        if (!f) continue;
        ParamSet p = params;
        p.setGenerator(&e.info);
        return (*f)(p);
    }
    throw std::invalid_argument("no " + std::string(kind) + " generator named '" +
                                std::string(name) + "'");
}

} // namespace

const std::vector<GeneratorInfo>& generatorCatalogue() {
    static const std::vector<GeneratorInfo> infos = [] {
        std::vector<GeneratorInfo> v;
        for (const auto& e : entries()) v.push_back(e.info);
        return v;
    }();
    return infos;
}

const GeneratorInfo* findGenerator(std::string_view name) {
    for (const auto& g : generatorCatalogue())
        if (g.name == name) return &g;
    return nullptr;
}

double ParamSet::get(std::string_view name) const {
    if (auto it = values_.find(name); it != values_.end()) return it->second;
    if (info_)
        for (const auto& p : info_->params)
            if (p.name == name) return p.defaultValue;
    throw std::logic_error("generator parameter '" + std::string(name) +
                           "' is neither set nor declared in the catalogue");
}

std::unique_ptr<BedGenerator> makeBedGenerator(std::string_view name, const ParamSet& params) {
    return make<BedFactory>(name, params, "bed");
}

std::unique_ptr<EventVoice> makeEventVoice(std::string_view name, const ParamSet& params) {
    return make<VoiceFactory>(name, params, "event");
}

} // namespace underfoot::soundscapes
