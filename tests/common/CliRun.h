// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Runs the built `underfoot` program with arguments (through the shell, stderr merged into the
// output) and returns its exit code and output. UNDERFOOT_BINARY_DIR is set by the test's CMake.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace underfoot::test {

struct CommandResult {
    int exitCode;
    std::string output;
};

inline CommandResult runUnderfootCli(const std::string& args) {
    const std::string cmd =
        std::string(UNDERFOOT_BINARY_DIR) + "/app/cli/underfoot " + args + " 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string out;
    char buf[512];
    while (pipe && fgets(buf, sizeof buf, pipe)) out += buf;
    const int status = pipe ? pclose(pipe) : -1;
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

} // namespace underfoot::test
