// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The whole content of a file as bytes (empty when it cannot be opened): what tests compare
// program output and written reports with.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace underfoot::test {

inline std::string readFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

} // namespace underfoot::test
