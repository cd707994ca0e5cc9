// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A scratch folder per test program and purpose, removed when the program ends.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <system_error>

#include <unistd.h>

namespace underfoot::test {

/// `<tmp>/underfoot_<purpose>_<pid>`, created on first use, removed at the end of the program.
inline std::filesystem::path scratchDir(const std::string& purpose) {
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() / ("underfoot_" + purpose + "_" + std::to_string(getpid()));
    if (!fs::exists(dir)) {
        fs::create_directories(dir);
        struct Remove : ::testing::Environment {
            explicit Remove(fs::path d) : dir(std::move(d)) {}
            void TearDown() override {
                std::error_code ec;
                fs::remove_all(dir, ec);
            }
            fs::path dir;
        };
        ::testing::AddGlobalTestEnvironment(new Remove(dir));
    }
    return dir;
}

} // namespace underfoot::test
