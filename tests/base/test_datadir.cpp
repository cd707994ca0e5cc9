// SPDX-License-Identifier: GPL-3.0-or-later
// The data-folder resolver (base/DataDir.h): overrides first, then an installed tree next to the
// program, then (for a program of this build tree, as this test is) the source tree. The
// installed, relocatable case with a real program is tests/package/install_tree.sh.
#include "base/DataDir.h"
#include "base/Version.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <string>

namespace {
namespace fs = std::filesystem;
using underfoot::base::dataDirectory;
using underfoot::base::DataKind;

/// Sets (or unsets, with nullopt) one environment variable for a test's lifetime.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, std::optional<std::string> value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value)
            ::setenv(name, value->c_str(), 1);
        else
            ::unsetenv(name);
    }
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

  private:
    const char* name_;
    std::optional<std::string> old_;
};

constexpr DataKind kAll[] = {
    DataKind::Surfaces,    DataKind::ImpulseResponses, DataKind::GrfBank, DataKind::WadingPresets,
    DataKind::Soundscapes, DataKind::Protocols,        DataKind::GuiDemo};

TEST(DataDir, BuildTreeProgramReadsTheSourceTree) {
    ScopedEnv root("UNDERFOOT_DATA_DIR", std::nullopt);
    for (DataKind k : kAll) {
        ScopedEnv own(underfoot::base::dataEnvironmentVariable(k), std::nullopt);
        const fs::path dir = dataDirectory(k);
        EXPECT_TRUE(fs::is_directory(dir)) << dir;
        EXPECT_EQ(dir.string().rfind(UNDERFOOT_SOURCE_DIR, 0), 0u) << dir;
    }
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::Surfaces)) / "wood.toml"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::ImpulseResponses)) / "hall.wav"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::GrfBank)) / "heel_1.wav"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::WadingPresets)) / "deep.toml"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::Soundscapes)) / "forest.toml"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::Protocols)) / "tvcg2011_exp2.toml"));
    EXPECT_TRUE(fs::exists(fs::path(dataDirectory(DataKind::GuiDemo)) / "demo_walker.toml"));
}

TEST(DataDir, KindVariableWinsOverTheRootVariable) {
    ScopedEnv root("UNDERFOOT_DATA_DIR", "/opt/underfoot-data");
    {
        ScopedEnv own("UNDERFOOT_SURFACES_DIR", "/elsewhere/surfaces");
        EXPECT_EQ(dataDirectory(DataKind::Surfaces), "/elsewhere/surfaces");
    }
    ScopedEnv own("UNDERFOOT_SURFACES_DIR", "");
    EXPECT_EQ(dataDirectory(DataKind::Surfaces), "/opt/underfoot-data/surfaces");
    ScopedEnv proto("UNDERFOOT_PROTOCOLS_DIR", std::nullopt);
    EXPECT_EQ(dataDirectory(DataKind::Protocols), "/opt/underfoot-data/protocols");
    ScopedEnv ir("UNDERFOOT_IR_DIR", std::nullopt);
    EXPECT_EQ(dataDirectory(DataKind::ImpulseResponses), "/opt/underfoot-data/ir");
}

TEST(DataDir, EveryKindHasItsOwnVariable) {
    std::set<std::string> names;
    for (DataKind k : kAll) names.insert(underfoot::base::dataEnvironmentVariable(k));
    EXPECT_EQ(names.size(), std::size(kAll));
    EXPECT_FALSE(names.count("UNDERFOOT_DATA_DIR"));
}

TEST(DataDir, RecordingsFollowTheirVariableThenTheSourceTree) {
    {
        ScopedEnv rec("UNDERFOOT_RECORDINGS", "/data/steps");
        EXPECT_EQ(underfoot::base::recordingsDirectory(), "/data/steps");
    }
    ScopedEnv rec("UNDERFOOT_RECORDINGS", std::nullopt);
    EXPECT_EQ(underfoot::base::recordingsDirectory(),
              (fs::path(UNDERFOOT_SOURCE_DIR) / "build/recordings").string());
}

TEST(DataDir, ExecutablePathIsThisTest) {
    const fs::path exe = underfoot::base::executablePath();
    EXPECT_EQ(exe.filename(), "test_base");
}

TEST(Version, NamesTheProjectVersionAndACommit) {
    const std::string v = underfoot::base::version(), c = underfoot::base::gitCommit();
    EXPECT_FALSE(v.empty());
    EXPECT_FALSE(c.empty());
    EXPECT_EQ(std::string(underfoot::base::versionLine()), v + " (commit " + c + ")");
}

} // namespace
