// SPDX-License-Identifier: GPL-3.0-or-later
// The shared TOML reader: file reading, syntax errors, typed accessors, unknown keys with a
// did-you-mean, collect vs throw.
#include "base/Suggest.h"
#include "base/TomlReader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

using namespace underfoot::base;

namespace {
std::string messageOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const TomlError& e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST(Suggest, ClosestNameIsCaseInsensitiveAndBounded) {
    EXPECT_EQ(closestName("gravle", {"wood", "gravel", "metal"}), "gravel");
    EXPECT_EQ(closestName("Wod", {"wood", "gravel", "metal"}), "wood");
    EXPECT_EQ(closestName("xyzzy", {"wood", "gravel", "metal"}), "");
    EXPECT_EQ(closestName("snow", {"deep_snow", "wood"}), "deep_snow");
    EXPECT_EQ(sortedIdsWithSuggestion("metl", {"wood", "metal"}),
              "metal, wood (did you mean 'metal'?)");
    EXPECT_EQ(sortedIdsWithSuggestion("qqqq", {"wood", "metal"}), "metal, wood");
}

TEST(TomlReader, SyntaxErrorHasFileLineColumn) {
    const std::string m = messageOf([] { parseToml("a = 1\nb = = 2\n", "x.toml"); });
    EXPECT_EQ(m.rfind("x.toml:2:", 0), 0u) << m;
    EXPECT_NE(m.find("TOML syntax error: "), std::string::npos) << m;
}

TEST(TomlReader, MissingDirectoryAndOversizedFiles) {
    const auto dir = std::filesystem::temp_directory_path() / "underfoot_toml_reader_test";
    std::filesystem::create_directories(dir);
    const std::string missing = (dir / "nope.toml").string();
    EXPECT_EQ(messageOf([&] { readTomlFile(missing, "a protocol"); }),
              missing + ": no such file; expected a protocol");
    EXPECT_EQ(messageOf([&] { readTomlFile(dir.string()); }),
              dir.string() + ": is a directory; expected a TOML file");
    const std::string big = (dir / "big.toml").string();
    {
        std::ofstream out(big);
        out << std::string(200, '#');
    }
    EXPECT_NE(messageOf([&] { readTomlFile(big, "a TOML file", 100); }).find("larger than 100"),
              std::string::npos);
    EXPECT_EQ(readTomlFile(big).size(), 200u);
    EXPECT_EQ(parseTomlFile(big).size(), 0u);
    std::filesystem::remove_all(dir);
}

TEST(TomlReader, UnknownKeyHasPositionAndDidYouMean) {
    const auto root = parseToml("[timing]\ntrial_s = 3\nbrake_s = 2\n", "p.toml");
    TomlReader r("p.toml");
    r.checkKeys(*root["timing"].as_table(), {"trial_s", "break_s"}, "[timing]");
    ASSERT_EQ(r.problems().size(), 1u);
    EXPECT_EQ(r.problems()[0].toString(),
              "p.toml:3:1: unknown key 'brake_s' in [timing]; expected one of: break_s, trial_s "
              "(did you mean 'break_s'?)");
}

TEST(TomlReader, TypedAccessorsCollectEveryProblem) {
    const auto root = parseToml("n = nan\nm = 12\ni = 2.0\ns = 3\nb = 'x'\nc = 'blue'\n"
                                "l = ['a', 1]\nt = 4\nok = 0.5\nk = 7\n",
                                "t.toml");
    TomlReader r("t.toml");
    EXPECT_FALSE(r.number(root, "n", "[x]", 0, 1));
    EXPECT_FALSE(r.number(root, "m", "[x]", 0, 10));
    EXPECT_FALSE(r.integer(root, "i", "[x]", true, 0, 5));
    EXPECT_FALSE(r.string(root, "s", "[x]", true));
    EXPECT_FALSE(r.boolean(root, "b", "[x]"));
    enum class Colour { Red, Green };
    EXPECT_FALSE(
        r.choice<Colour>(root, "c", "[x]", {{"red", Colour::Red}, {"green", Colour::Green}}));
    EXPECT_EQ(r.strings(root, "l", "[x]").size(), 1u);
    EXPECT_FALSE(r.table(root, "t", "[x]", false));
    EXPECT_FALSE(r.string(root, "absent", "[x]", true));
    EXPECT_EQ(r.number(root, "ok", "[x]", 0, 1), 0.5);
    EXPECT_EQ(r.integer(root, "k", "[x]", true, 0, 10), 7);
    EXPECT_EQ(r.number(root, "k", "[x]", 0, 10), 7.0); // an integer is a number
    const auto& p = r.problems();
    ASSERT_EQ(p.size(), 9u);
    EXPECT_EQ(p[0].toString(),
              "t.toml:1:5: 'n' in [x] is nan; expected a finite number from 0 to 1");
    EXPECT_EQ(p[1].toString(),
              "t.toml:2:5: 'm' in [x] is 12; expected a finite number from 0 to 10");
    EXPECT_EQ(p[2].toString(), "t.toml:3:5: 'i' in [x] must be an integer");
    EXPECT_EQ(p[3].toString(), "t.toml:4:5: 's' in [x] must be a string");
    EXPECT_EQ(p[4].toString(), "t.toml:5:5: 'b' in [x] must be true or false");
    EXPECT_EQ(p[5].toString(), "t.toml:6:5: 'c' in [x] is 'blue'; expected one of: red, green");
    EXPECT_EQ(p[6].toString(), "t.toml:7:11: elements of 'l' in [x] must be strings");
    EXPECT_EQ(p[7].toString(), "t.toml:8:5: 't' in [x] must be a table");
    EXPECT_EQ(p[8].message, "missing key 'absent' in [x]; expected a string");
}

TEST(TomlReader, ThrowModeStopsAtTheFirstAndRootCausesComeFirst) {
    const auto root = parseToml("a = 'x'\nb = 'y'\n", "t.toml");
    TomlReader thrower("t.toml", TomlReader::Mode::Throw);
    EXPECT_EQ(messageOf([&] { thrower.integer(root, "a", "[t]", true, 0, 1); }),
              "t.toml:1:5: 'a' in [t] must be an integer");
    TomlReader r("t.toml");
    r.derived(root["a"].node()->source(), "follows");
    r.problem(*root["b"].node(), "root cause");
    const std::string m = messageOf([&] { r.throwIfProblems(); });
    EXPECT_EQ(m, "t.toml:2:5: root cause\nt.toml:1:5: follows");
}

// Every reader of TOML goes through base/TomlReader: no other source file of the program calls
// toml++'s parser or catches its parse_error (each would bring its own message format back).
TEST(TomlReader, IsTheOnlyCallerOfTheTomlParser) {
    namespace fs = std::filesystem;
    const fs::path root = UNDERFOOT_SOURCE_DIR;
    std::vector<std::string> offenders;
    std::size_t scanned = 0;
    for (const char* part : {"base", "engine", "experiment", "analysis", "realism", "soundscapes",
                             "app", "hardware"}) {
        if (!fs::exists(root / part)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(root / part)) {
            const auto ext = entry.path().extension();
            if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".h")) continue;
            const std::string relative = fs::relative(entry.path(), root).generic_string();
            if (relative == "base/TomlReader.cpp") continue;
            std::ifstream in(entry.path(), std::ios::binary);
            const std::string text((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
            ++scanned;
            for (const char* call : {"toml::parse(", "toml::parse_file(", "toml::parse_error"})
                if (text.find(call) != std::string::npos)
                    offenders.push_back(relative + ": " + call);
        }
    }
    EXPECT_GT(scanned, 100u); // the tree was found
    EXPECT_TRUE(offenders.empty()) << ::testing::PrintToString(offenders);
}
