// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Tests on the real recordings (scripts/fetch-recordings.sh): a fixture that loads the cache's
/// manifest, and skips the test, saying so, when there is no cache. The unseen source
/// (`fetch-recordings.sh --unseen`, docs/decisions/unseen-source.md) is left out: the tests'
/// bars are design goals set on the other sources, and the presets are judged on the unseen one
/// by `underfoot compare`, never tuned on it. A lab's own sources (`underfoot recordings add`)
/// are left out too: the bars are about the fetched packages every machine can have.
#include "realism/Recordings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace underfoot::realism::test {

class RecordingsCacheTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = defaultRecordingsDir();
        if (!std::filesystem::exists(std::filesystem::path(dir_) / "manifest.csv"))
            GTEST_SKIP()
                << "no recordings cache at " << dir_
                << ": run `bash scripts/fetch-recordings.sh` (or set UNDERFOOT_RECORDINGS)";
        const auto all = loadManifest(dir_);
        recs_ = withoutUnseenSources(all);
        if (recs_.size() < all.size())
            RecordProperty("unseen_files_left_out", static_cast<int>(all.size() - recs_.size()));
        const auto& fetched = fetchedSources();
        const auto before = recs_.size();
        std::erase_if(recs_, [&](const Recording& r) {
            return std::find(fetched.begin(), fetched.end(), r.source) == fetched.end();
        });
        if (recs_.size() < before)
            RecordProperty("lab_files_left_out", static_cast<int>(before - recs_.size()));
    }
    std::string dir_;
    std::vector<Recording> recs_;
};

} // namespace underfoot::realism::test
