// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/cli/CommandRegistry.h"

#include <algorithm>

namespace underfoot::cli {

std::vector<CommandEntry>& commandRegistry() {
    static std::vector<CommandEntry> registry;
    return registry;
}

CommandRegistrar::CommandRegistrar(std::string name, CommandInstaller install) {
    auto& registry = commandRegistry();
    registry.push_back({std::move(name), std::move(install)});
    std::sort(registry.begin(), registry.end(),
              [](const CommandEntry& a, const CommandEntry& b) { return a.name < b.name; });
}

} // namespace underfoot::cli
