// SPDX-License-Identifier: GPL-3.0-or-later
// "Check means runs": a protocol whose stimulus cannot render is refused by the protocol reader
// (unknown walker keys, with a did-you-mean) or by wiring::checkStimuliRender (out-of-range
// walker values, a missing surface preset, soundscape definition, impulse response or GRF bank
// file), root cause first, before `protocol check` passes or `study create` makes a study.
#include "app/wiring/StimulusRender.h"
#include "base/DataDir.h"
#include "experiment/Protocol.h"
#include "tests/common/ScratchDir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace xp = underfoot::experiment;
namespace wir = underfoot::wiring;
namespace fs = std::filesystem;

namespace {

/// The walker-driven protocol of tests/app/replay_walk.toml with `walker` and extra stimulus
/// lines for its first stimulus.
std::string protocolText(const std::string& walker, const std::string& firstStimulusExtra = "") {
    return "[protocol]\nid = \"check_runs\"\nversion = 1\ntitle = \"Check means runs\"\n"
           "[design]\ntype = \"within\"\n"
           "[input]\ntype = \"walker\"\nwalker = " +
           walker +
           "\n"
           "[[stimuli]]\nid = \"GL\"\nsurface = \"gravel\"\n" +
           firstStimulusExtra +
           "[[stimuli]]\nid = \"WR\"\nsurface = \"wood_reverb\"\n"
           "[[stimuli]]\nid = \"BS\"\nsurface = \"beach_sand\"\nsoundscape = \"beach_summer\"\n"
           "[questions.surface]\noptions = [\"beach_sand\", \"gravel\", \"wood\", \"dont_know\"]\n";
}

/// The protocol reader's messages (empty when the text parses).
std::string parseProblems(const std::string& text) {
    try {
        (void)xp::parseProtocol(text, "check.toml");
    } catch (const xp::ProtocolError& e) {
        std::string all;
        for (const auto& p : e.problems()) all += p.toString() + "\n";
        return all;
    }
    return "";
}

/// Sets an environment variable for the scope of one test.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const std::string& value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        ::setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }

  private:
    const char* name_;
    std::optional<std::string> old_;
};

/// A copy of one shipped data folder without `missing` (a file name in it).
std::string copyWithout(underfoot::base::DataKind kind, const std::string& scratch,
                        const std::string& missing) {
    const fs::path to = underfoot::test::scratchDir(scratch);
    fs::copy(underfoot::base::dataDirectory(kind), to,
             fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    fs::remove(to / missing);
    return to.string();
}

} // namespace

TEST(StimulusCheck, WalkerSpeedKeyOfTheOldExampleIsAnUnknownKeyAtItsLine) {
    const std::string problems = parseProblems(protocolText("{ speed_mps = 1.2 }"));
    EXPECT_NE(problems.find("check.toml:7:"), std::string::npos) << problems;
    EXPECT_NE(problems.find("unknown walker key 'speed_mps'; expected one of: cadence, mass, "
                            "shoe, variability"),
              std::string::npos)
        << problems;
}

TEST(StimulusCheck, WalkerKeyTypoSuggestsTheKey) {
    const std::string problems = parseProblems(protocolText("{ cadnce = 100.0 }"));
    EXPECT_NE(problems.find("unknown walker key 'cadnce'"), std::string::npos) << problems;
    EXPECT_NE(problems.find("(did you mean 'cadence'?)"), std::string::npos) << problems;
    // One report for the [input] table, not one per stimulus that inherits it.
    EXPECT_EQ(std::count(problems.begin(), problems.end(), '\n'), 1) << problems;
}

TEST(StimulusCheck, WalkerCadenceOutOfRangeParsesButDoesNotRenderOneCauseFirst) {
    const xp::Protocol p = xp::parseProtocol(protocolText("{ cadence = 1000.0 }"), "check.toml");
    int rendered = -1;
    const auto problems = wir::checkStimuliRender(p, 0.3, &rendered);
    ASSERT_EQ(problems.size(), 2u);
    EXPECT_EQ(problems[0].rfind("stimulus 'GL' (gravel) cannot be rendered: ", 0), 0u)
        << problems[0];
    EXPECT_NE(problems[0].find("cadence = 1000 is outside the valid range [60, 150]"),
              std::string::npos)
        << problems[0];
    EXPECT_EQ(problems[1], "  the same cause stops 2 more stimuli: 'WR' (wood_reverb), 'BS' "
                           "(beach_sand + beach_summer)");
    EXPECT_EQ(rendered, 0);
}

TEST(StimulusCheck, AGoodProtocolRendersEveryDistinctStimulus) {
    const xp::Protocol p = xp::parseProtocol(protocolText("{ cadence = 100.0 }"), "check.toml");
    int rendered = -1;
    EXPECT_TRUE(wir::checkStimuliRender(p, 0.3, &rendered).empty());
    EXPECT_EQ(rendered, 3);
}

TEST(StimulusCheck, MissingImpulseResponseFileIsNamed) {
    const xp::Protocol p = xp::parseProtocol(
        protocolText("{ cadence = 100.0 }", "reverb = \"/nonexistent/hall.wav\"\n"), "check.toml");
    const auto problems = wir::checkStimuliRender(p);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].rfind("stimulus 'GL' (gravel, reverb /nonexistent/hall.wav) cannot be "
                                "rendered: ",
                                0),
              0u)
        << problems[0];
    EXPECT_NE(problems[0].find("/nonexistent/hall.wav"), std::string::npos) << problems[0];
}

TEST(StimulusCheck, MissingSoundscapeDefinitionFileIsNamed) {
    const ScopedEnv env(
        underfoot::base::dataEnvironmentVariable(underfoot::base::DataKind::Soundscapes),
        copyWithout(underfoot::base::DataKind::Soundscapes, "check_soundscapes",
                    "beach_summer.toml"));
    const xp::Protocol p = xp::parseProtocol(protocolText("{ cadence = 100.0 }"), "check.toml");
    const auto problems = wir::checkStimuliRender(p);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(
        problems[0].rfind("stimulus 'BS' (beach_sand + beach_summer) cannot be rendered: ", 0), 0u)
        << problems[0];
    EXPECT_NE(problems[0].find("beach_summer"), std::string::npos) << problems[0];
}

TEST(StimulusCheck, MissingSurfacePresetFileIsNamed) {
    const ScopedEnv env(
        underfoot::base::dataEnvironmentVariable(underfoot::base::DataKind::Surfaces),
        copyWithout(underfoot::base::DataKind::Surfaces, "check_surfaces", "gravel.toml"));
    const xp::Protocol p = xp::parseProtocol(protocolText("{ cadence = 100.0 }"), "check.toml");
    const auto problems = wir::checkStimuliRender(p);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].rfind("stimulus 'GL' (gravel) cannot be rendered: ", 0), 0u)
        << problems[0];
    EXPECT_NE(problems[0].find("gravel"), std::string::npos) << problems[0];
}

TEST(StimulusCheck, MissingGrfBankFileOfTheShoesIsTheFirstCause) {
    const ScopedEnv env(
        underfoot::base::dataEnvironmentVariable(underfoot::base::DataKind::GrfBank),
        copyWithout(underfoot::base::DataKind::GrfBank, "check_grf", "heel_1.wav"));
    const xp::Protocol p = xp::loadProtocol(xp::shippedProtocolDir() + "/eurohaptics2010.toml");
    const auto problems = wir::checkStimuliRender(p);
    ASSERT_FALSE(problems.empty());
    EXPECT_EQ(
        problems[0].rfind("the GRF bank of the shoes (sensor = \"fsr\") cannot be loaded: ", 0), 0u)
        << problems[0];
    EXPECT_NE(problems[0].find("heel_1.wav"), std::string::npos) << problems[0];
}

TEST(StimulusCheck, EveryShippedProtocolRenders) {
    for (const auto& entry : fs::directory_iterator(xp::shippedProtocolDir())) {
        if (entry.path().extension() != ".toml") continue;
        const xp::Protocol p = xp::loadProtocol(entry.path().string());
        const auto problems = wir::checkStimuliRender(p, 0.2);
        EXPECT_TRUE(problems.empty()) << entry.path() << ": " << problems.front();
    }
}
