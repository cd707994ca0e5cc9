// SPDX-License-Identifier: GPL-3.0-or-later
#include "soundscapes/Coherence.h"
#include "soundscapes/Definition.h"
#include "soundscapes/Library.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

using namespace underfoot::soundscapes;

namespace {

std::string errorOf(const std::string& text) {
    try {
        parseSoundscapeDefinition(text, "test.toml", "/base");
    } catch (const DefinitionError& e) {
        return e.what();
    }
    return "(no error)";
}

const char* kHead = R"([soundscape]
id = "t"
name = "Test"
target_level_dbfs = -30.0
)";

} // namespace

TEST(SoundscapeDefinition, ParsesBedsEventsParamsAndRanges) {
    const auto def = parseSoundscapeDefinition(std::string(kHead) + R"(
[[bed]]
name = "sea"
generator = "sea"
level_db = -3
params = { wave_period_s = 6.5 }

[[event]]
name = "gulls"
generator = "gull"
mean_interval_s = 12.0
jitter = 0.5
gain_db = [-6.0, -1.0]
pan = [-0.5, 0.25]
max_voices = 2
first_onset_s = [1, 2]

[[event]]
name = "clips"
files = ["a.wav", "/abs/b.flac"]
rate_per_minute = 3
)",
                                               "test.toml", "/base");
    EXPECT_EQ(def.id, "t");
    ASSERT_EQ(def.layers.size(), 3u);
    EXPECT_EQ(def.layers[0].kind, LayerKind::Bed);
    EXPECT_DOUBLE_EQ(def.layers[0].levelDb, -3.0);
    EXPECT_DOUBLE_EQ(def.layers[0].params.get("wave_period_s"), 6.5);
    EXPECT_DOUBLE_EQ(def.layers[0].params.get("foam"), 0.5); // catalogue default
    const auto& gulls = def.layers[1];
    EXPECT_DOUBLE_EQ(gulls.ratePerMinute, 5.0);
    EXPECT_DOUBLE_EQ(gulls.jitter, 0.5);
    EXPECT_DOUBLE_EQ(gulls.gainDbMin, -6.0);
    EXPECT_DOUBLE_EQ(gulls.panMax, 0.25);
    EXPECT_EQ(gulls.maxVoices, 2);
    ASSERT_TRUE(gulls.firstOnsetSeconds.has_value());
    EXPECT_EQ(gulls.location, "test.toml:12:1");
    const auto& clips = def.layers[2];
    EXPECT_EQ(clips.source, LayerSource::Recording);
    ASSERT_EQ(clips.files.size(), 2u);
    EXPECT_EQ(clips.files[0], "/base/a.wav");
    EXPECT_EQ(clips.files[1], "/abs/b.flac");
}

TEST(SoundscapeDefinition, ErrorsNameFileLineColumnAndWhatWasExpected) {
    EXPECT_EQ(errorOf("bed = 3\n" + std::string(kHead)),
              "test.toml:1:7: 'bed' must be an array of tables: [[bed]]");
    EXPECT_EQ(errorOf("event = [1]\n" + std::string(kHead)),
              "test.toml:1:10: [[event]] entries must be tables");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[bed]]\nname = \"w\"\ngenerator = \"wnd\"\n"),
              "test.toml:7:13: unknown bed generator 'wnd' (expected one of: babble, leaves, lift, "
              "sea, tractor, traffic, wind)");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[bed]]\nname = \"w\"\ngenerator = \"wind\"\n"
                                           "params = { centre_hz = 99999 }\n"),
              "test.toml:8:24: 'centre_hz' is 99999; expected a finite number from 80 to 4000");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[bed]]\nname = \"w\"\ngenerator = \"wind\"\n"
                                           "params = { center_hz = 500 }\n"),
              "test.toml:8:24: generator 'wind' has no parameter 'center_hz' (expected one of: "
              "centre_hz, gustiness, whistle)");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[event]]\nname = \"g\"\ngenerator = \"gull\"\n"),
              "test.toml:5:1: event layer 'g' needs exactly one of 'rate_per_minute' or "
              "'mean_interval_s'");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[event]]\nname = \"g\"\ngenerator = \"gull\"\n"
                                           "rate_per_minute = 2\nlevel = 3\n"),
              "test.toml:9:1: unknown key 'level' in [[event]]; expected one of: enabled, "
              "file, files, first_onset_s, gain_db, generator, jitter, level_db, max_voices, "
              "mean_interval_s, name, pan, params, rate_per_minute (did you mean 'level_db'?)");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[event]]\nname = \"g\"\ngenerator = \"gull\"\n"
                                           "rate_per_minute = 2\ngain_db = [0, -6]\n"),
              "test.toml:9:11: 'gain_db' must be [min, max] with min <= max");
    EXPECT_EQ(errorOf(std::string(kHead) + "[[bed]]\nname = \"g\"\ngenerator = \"gull\"\n"),
              "test.toml:7:13: unknown bed generator 'gull' (expected one of: babble, leaves, "
              "lift, sea, tractor, traffic, wind)");
    EXPECT_NE(errorOf(std::string(kHead) + "[[bed]]\nname = \"w\"\ngenerator = \"wind\"\n"
                                           "file = \"x.wav\"\n")
                  .find("test.toml:5:1: layer 'w' needs exactly one of 'generator', 'file' or "
                        "'files'"),
              std::string::npos);
    EXPECT_EQ(errorOf("[soundscape]\nid = \"x\"\nname = \"n\"\n"),
              "test.toml:1:1: [soundscape] needs 'target_level_dbfs' (long-term RMS level of the "
              "mix)");
    EXPECT_EQ(errorOf(std::string(kHead)),
              "test.toml: a soundscape needs at least one enabled [[bed]] or [[event]] layer");
    // A TOML syntax error keeps the parser's position.
    EXPECT_EQ(errorOf("[soundscape\n").rfind("test.toml:1:", 0), 0u) << errorOf("[soundscape\n");
    EXPECT_NE(errorOf(std::string(kHead) + "[[bed]]\nname = \"w\"\ngenerator = \"wind\"\n"
                                           "level_db = nan\n")
                  .find("test.toml:8:12: 'level_db' is nan; expected a finite number"),
              std::string::npos);
}

TEST(SoundscapeDefinition, DisabledLayersAreNotPartOfTheSoundscape) {
    const auto def = parseSoundscapeDefinition(std::string(kHead) + R"(
[[bed]]
name = "a"
generator = "wind"
[[bed]]
name = "b"
generator = "sea"
enabled = false
)",
                                               "t.toml");
    ASSERT_EQ(def.layers.size(), 1u);
    EXPECT_EQ(def.layers[0].name, "a");
}

TEST(SoundscapeDefinition, MissingFileIsReportedWithItsPath) {
    try {
        loadSoundscapeDefinition("/nonexistent/x.toml");
        FAIL();
    } catch (const DefinitionError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "/nonexistent/x.toml: no such file; expected a readable TOML soundscape"),
                  std::string::npos);
    }
}

TEST(SoundscapeLibrary, ShipsTheFiveEnvironmentsOfTheStudy) {
    const auto ids = builtinSoundscapeIds();
    EXPECT_EQ(ids, (std::vector<std::string>{"beach_summer", "farm_courtyard", "forest",
                                             "park_fall", "ski_slope"}));
    for (const auto& id : ids) {
        const auto def = loadSoundscape(id);
        EXPECT_EQ(def.id, id) << "the id inside a file must match its name";
        EXPECT_FALSE(def.description.empty());
    }
    try {
        loadSoundscape("beach");
        FAIL();
    } catch (const DefinitionError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown soundscape 'beach' (expected one of: "
                                             "beach_summer, farm_courtyard"),
                  std::string::npos);
    }
}

TEST(SoundscapeLibrary, ForestIsDenserInNaturalEventsThanThePark) {
    // The study's forest is "denser in natural sounds than the park" (fewer birds in the park).
    auto birdRate = [](const SoundscapeDefinition& d) {
        double r = 0;
        for (const auto& l : d.layers)
            if (l.generator == "songbird" || l.generator == "cuckoo" || l.generator == "woodpecker")
                r += l.ratePerMinute;
        return r;
    };
    EXPECT_GT(birdRate(loadSoundscape("forest")), 3 * birdRate(loadSoundscape("park_fall")));
}

TEST(Coherence, UnknownKeysAndWrongTypesNameTheirPlace) {
    auto errorOf = [](const std::string& text) {
        try {
            (void)CoherenceTable::parse(text, "c.toml");
        } catch (const DefinitionError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(errorOf("[[coherent]]\nsurface = \"wood\"\nsoundscap = \"forest\"\n"),
              "c.toml:3:1: unknown key 'soundscap' in [[coherent]]; expected one of: soundscape, "
              "surface (did you mean 'soundscape'?)");
    EXPECT_EQ(
        errorOf("[[incoherent]]\nsurface = \"wood\"\nsoundscapes = [3]\n").rfind("c.toml:3:", 0),
        0u);
    EXPECT_EQ(errorOf("incoherent = 3\n"),
              "c.toml:1:14: 'incoherent' must be an array of tables: [[incoherent]]");
    EXPECT_EQ(errorOf("coherent = [1]\n"), "c.toml:1:13: [[coherent]] entries must be tables");
}

TEST(Coherence, AnswersTheCoherentPairsOfTheStudy) {
    const auto& t = CoherenceTable::builtin();
    EXPECT_EQ(t.coherentSoundscapeFor("beach_sand"), "beach_summer");
    EXPECT_EQ(t.coherentSoundscapeFor("gravel"), "farm_courtyard");
    EXPECT_EQ(t.coherentSoundscapeFor("deep_snow"), "ski_slope");
    EXPECT_EQ(t.coherentSoundscapeFor("frozen_snow"), "ski_slope");
    EXPECT_EQ(t.coherentSoundscapeFor("forest_underbrush"), "forest");
    EXPECT_EQ(t.coherentSoundscapeFor("dry_leaves"), "park_fall");
    EXPECT_FALSE(t.coherentSoundscapeFor("metal").has_value());
    EXPECT_TRUE(t.isCoherent("gravel", "farm_courtyard"));
    EXPECT_FALSE(t.isCoherent("gravel", "forest"));
    EXPECT_EQ(t.surfacesCoherentWith("ski_slope"),
              (std::vector<std::string>{"deep_snow", "frozen_snow"}));
}

TEST(Coherence, AnswersTheIncoherentPairsOfGroupThree) {
    // TVCG 2011 experiment 2, group 3: beach sand with forest and ski slope; snow with forest and
    // beach; forest underbrush with beach and ski slope.
    const auto& t = CoherenceTable::builtin();
    EXPECT_EQ(t.incoherentSoundscapesFor("beach_sand"),
              (std::vector<std::string>{"forest", "ski_slope"}));
    EXPECT_EQ(t.incoherentSoundscapesFor("deep_snow"),
              (std::vector<std::string>{"forest", "beach_summer"}));
    EXPECT_EQ(t.incoherentSoundscapesFor("forest_underbrush"),
              (std::vector<std::string>{"beach_summer", "ski_slope"}));
    EXPECT_TRUE(t.incoherentSoundscapesFor("gravel").empty());
    std::size_t stimuli = 0;
    for (const auto& e : t.entries()) stimuli += e.incoherent.size();
    EXPECT_EQ(stimuli, 6u);
}

TEST(Coherence, EverySoundscapeItNamesExists) {
    const auto ids = builtinSoundscapeIds();
    for (const auto& s : CoherenceTable::builtin().soundscapes())
        EXPECT_NE(std::find(ids.begin(), ids.end(), s), ids.end()) << s;
}

TEST(Coherence, RejectsContradictionsWithPositions) {
    EXPECT_THROW(CoherenceTable::parse("[[coherent]]\nsurface = \"a\"\nsoundscape = \"x\"\n"
                                       "[[incoherent]]\nsurface = \"a\"\nsoundscapes = [\"x\"]\n",
                                       "c.toml"),
                 DefinitionError);
    try {
        CoherenceTable::parse("[[coherent]]\nsurface = \"a\"\nsoundscape = \"x\"\n"
                              "[[coherent]]\nsurface = \"a\"\nsoundscape = \"y\"\n",
                              "c.toml");
        FAIL();
    } catch (const DefinitionError& e) {
        EXPECT_STREQ(e.what(), "c.toml:4:1: surface 'a' already has a coherent soundscape ('x')");
    }
}
