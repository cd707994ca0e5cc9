// SPDX-License-Identifier: GPL-3.0-or-later
// Issue #16: a damaged study file is refused with its name and what is wrong, never indexed or run.
#include "TestSupport.h"
#include "experiment/Store.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
std::string openError(const std::string& path) {
    try {
        (void)StudyStore::open(path);
    } catch (const StoreError& e) {
        return e.what();
    }
    return "";
}

void setUserVersion(const std::string& path, long long v) {
    SQLite::Database db(path, SQLite::OPEN_READWRITE);
    db.exec("PRAGMA user_version = " + std::to_string(v));
}
} // namespace

TEST(StoreHardening, UnknownSchemaVersionsAreRefusedWithTheFileName) {
    TempDir dir;
    const std::string path = dir.file("damaged.db");
    {
        StudyStore::create(path, loadProtocol(shipped("tvcg2011_exp1.toml")),
                           {"D1", "lab", 1, "test"});
    }
    for (long long v : {-1LL, -2147483648LL, 0LL, 99LL, 2147483647LL}) {
        setUserVersion(path, v);
        const std::string msg = openError(path);
        ASSERT_FALSE(msg.empty()) << "user_version " << v << " was accepted";
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("schema version " + std::to_string(v)), std::string::npos) << msg;
    }
    // Back to ours: the study opens again (the refusal wrote nothing).
    setUserVersion(path, kSchemaVersion);
    EXPECT_EQ(openError(path), "");
}
