// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Self-registering subcommands of the `underfoot` program.
///
/// Each cmd_*.cpp defines one static `CommandRegistrar` that adds its subcommand to the CLI11
/// application; main.cpp knows none of them by name. A command's callback returns the process
/// exit code; errors the user can fix are reported as `UserError` with a message naming the
/// file, the place and what was expected.
#include <CLI/CLI.hpp>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::cli {

/// An error caused by the user's input (a file, an argument); printed without a stack of context.
struct UserError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A function that adds one subcommand to the application. The subcommand's callback must set
/// `exitCode` (0 on success) and may throw `UserError`.
using CommandInstaller = std::function<void(CLI::App& app, int& exitCode)>;

struct CommandEntry {
    std::string name;
    CommandInstaller install;
};

/// All registered subcommands, sorted by name.
std::vector<CommandEntry>& commandRegistry();

/// Registers a subcommand at static-initialisation time.
struct CommandRegistrar {
    CommandRegistrar(std::string name, CommandInstaller install);
};

} // namespace underfoot::cli
